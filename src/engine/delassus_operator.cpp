// Stage 3: the Delassus operator W = G Ŵ Gᵀ (and Y = Ŵ Gᵀ, which maps impulses
// to velocity changes). Every row of G touches at most two bodies, i.e. 12 of
// its 6N columns, so both products are formed from those 6-column pieces only:
// O(r·12·6N) and O(r²·12) instead of O(r·(6N)²) and O(r²·6N) for dense products.
// W is filled symmetrically. Ŵ itself is block-diagonal over the bodies, or over
// the groups of bodies springs and PD actuators join (ModelFacts::coupled).
#include "step_stages.hpp"

namespace nscd {

void assembleDelassus(const Eigen::MatrixXd& iteration_inverse, bool block_diagonal,
                      StepWorkspace& ws, int from, int r) {
  // Bodies of each row (kGround = none).
  for (const ConstraintBlock& blk : ws.blocks) {
    const int b = blk.body_b == blk.body_a ? kGround : blk.body_b;
    for (int k = 0; k < blk.size; ++k) ws.row_bodies[blk.row + k] = {blk.body_a, b};
  }
  const int n = ws.n;
  for (int i = from; i < r; ++i) {
    auto y = ws.Y.col(i).head(n);
    y.setZero();
    for (int body : ws.row_bodies[i]) {
      if (body == kGround) continue;
      const Vec6 g = ws.G.row(i).segment<6>(6 * body).transpose();
      if (block_diagonal) {  // no coupling between bodies: only this body's 6 x 6 block
        y.segment<6>(6 * body).noalias() += iteration_inverse.block<6, 6>(6 * body, 6 * body) * g;
        continue;
      }
      // Ŵ couples a body only with those of its stiff group (iteration_matrix.cpp).
      for (int c : ws.facts.coupled[body])
        y.segment<6>(6 * c).noalias() += iteration_inverse.block<6, 6>(6 * c, 6 * body) * g;
    }
  }
  for (int i = from; i < r; ++i) {
    const std::array<int, 2>& bi = ws.row_bodies[i];
    for (int j = 0; j <= i; ++j) {
      double w = 0;
      for (int body : bi)
        if (body != kGround)
          w += ws.G.row(i).segment<6>(6 * body).dot(ws.Y.col(j).segment<6>(6 * body));
      ws.W(i, j) = w;
      ws.W(j, i) = w;
    }
  }
}

}  // namespace nscd
