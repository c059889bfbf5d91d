// Stage 3: the Delassus operator W = G Ŵ Gᵀ (and Y = Ŵ Gᵀ, which maps impulses
// to velocity changes). Every row of G touches at most two bodies, i.e. 12 of
// its 6N columns, so both products are formed from those 6-column pieces only:
// O(r·12·6N) and O(r²·12) instead of O(r·(6N)²) and O(r²·6N) for dense products.
// W is filled symmetrically. Ŵ itself is block-diagonal over the bodies, or over
// the groups of bodies springs and PD actuators join (ModelFacts::coupled), so
// W_ij needs only the pieces of row i on bodies where column j of Y is nonzero
// (none, for rows on bodies Ŵ does not couple).
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "step_stages.hpp"

namespace nscd {
namespace {

// The dot product of two 6-vectors, summed as Eigen sums a non-vectorised
// fixed-size 6 (G's row pieces are strided): (0 + (1 + 2)) + (3 + (4 + 5)).
inline double dot6(const double* a, const double* b) {
  return (a[0] * b[0] + (a[1] * b[1] + a[2] * b[2])) + (a[3] * b[3] + (a[4] * b[4] + a[5] * b[5]));
}

#if defined(__SSE2__)
// dot6 of two rows at once, one per lane (a01[k] = {row 0, row 1} at k): the same
// products and sums in the same order in each lane, so each lane is dot6's bits.
inline __m128d dot6x2(const __m128d* a01, const double* b) {
  const __m128d p12 = _mm_add_pd(_mm_mul_pd(a01[1], _mm_set1_pd(b[1])),
                                 _mm_mul_pd(a01[2], _mm_set1_pd(b[2])));
  const __m128d p45 = _mm_add_pd(_mm_mul_pd(a01[4], _mm_set1_pd(b[4])),
                                 _mm_mul_pd(a01[5], _mm_set1_pd(b[5])));
  return _mm_add_pd(_mm_add_pd(_mm_mul_pd(a01[0], _mm_set1_pd(b[0])), p12),
                    _mm_add_pd(_mm_mul_pd(a01[3], _mm_set1_pd(b[3])), p45));
}
#endif

}  // namespace

void assembleDelassus(const Eigen::MatrixXd& iteration_inverse, bool block_diagonal,
                      StepWorkspace& ws, int from, int r) {
  // Bodies of each row (kGround = none), and the bodies where its column of Y
  // can be nonzero (its bodies' coupled groups; all of them past 64 bodies).
  const bool masks = ws.nbodies <= 64;
  for (const ConstraintBlock& blk : ws.blocks) {
    const int b = blk.body_b == blk.body_a ? kGround : blk.body_b;
    std::uint64_t support = masks ? 0 : ~std::uint64_t{0};
    for (int body : {blk.body_a, b})
      if (masks && body != kGround)
        support |= block_diagonal ? std::uint64_t{1} << body : ws.facts.coupled_mask[body];
    for (int k = 0; k < blk.size; ++k) {
      ws.row_bodies[blk.row + k] = {blk.body_a, b};
      ws.row_support[blk.row + k] = support;
    }
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
  const double* Y = ws.Y.data();
  const Eigen::Index ldy = ws.Y.outerStride();
  // Block by block: a block's rows share their bodies, so each piece of Y's
  // column j is loaded and tested once for all of them.
  for (const ConstraintBlock& blk : ws.blocks) {
    if (blk.row < from || blk.row >= r) continue;
    const int i0 = blk.row, size = blk.size;
    // The block's pieces of G (one per body it touches), copied out of G's strided rows.
    int off[2];
    std::uint64_t bit[2];
    double g[6][2][6];
    int np = 0;
    for (int body : ws.row_bodies[i0]) {
      if (body == kGround) continue;
      off[np] = 6 * body;
      bit[np] = masks ? std::uint64_t{1} << body : ~std::uint64_t{0};
      for (int a = 0; a < size; ++a)
        for (int k = 0; k < 6; ++k) g[a][np][k] = ws.G(i0 + a, 6 * body + k);
      ++np;
    }
    int j0 = 0;
    if (size == 3) {  // frictional contacts, most rows: fixed-size loops below the block
#if defined(__SSE2__)
      // Rows 0 and 1 of the block in the two lanes of one vector (bit for bit the
      // scalar sums: lanes do not mix), row 2 alone.
      __m128d g01[2][6];
      for (int q = 0; q < np; ++q)
        for (int k = 0; k < 6; ++k) g01[q][k] = _mm_set_pd(g[1][q][k], g[0][q][k]);
#endif
      const std::uint64_t touched = np == 2 ? bit[0] | bit[1] : np == 1 ? bit[0] : 0;
      for (; j0 < i0; ++j0) {
        const std::uint64_t support = ws.row_support[j0];
        double* wc = &ws.W(0, j0);  // column j0: W_ij0 (= W_j0i)
        if (!(support & touched)) {
          // Column j0 of Y is zero on this block's bodies (most pairs of rows):
          // the sums below would be +0 (they start at +0 and add nothing).
          wc[i0] = wc[i0 + 1] = wc[i0 + 2] = 0.0;
          ws.W(j0, i0) = ws.W(j0, i0 + 1) = ws.W(j0, i0 + 2) = 0.0;
          continue;
        }
        const double* yj = Y + j0 * ldy;
#if defined(__SSE2__)
        __m128d w01 = _mm_setzero_pd();
        double w2 = 0;
        for (int q = 0; q < np; ++q) {
          if (!(support & bit[q])) continue;
          const double* y = yj + off[q];
          w01 = _mm_add_pd(w01, dot6x2(g01[q], y));
          w2 += dot6(g[2][q], y);
        }
        double w01s[2];
        _mm_storeu_pd(w01s, w01);
        const double w0 = w01s[0], w1 = w01s[1];
#else
        double w0 = 0, w1 = 0, w2 = 0;
        for (int q = 0; q < np; ++q) {
          if (!(support & bit[q])) continue;
          const double* y = yj + off[q];
          w0 += dot6(g[0][q], y);
          w1 += dot6(g[1][q], y);
          w2 += dot6(g[2][q], y);
        }
#endif
        wc[i0] = w0;
        wc[i0 + 1] = w1;
        wc[i0 + 2] = w2;
        ws.W(j0, i0) = w0;
        ws.W(j0, i0 + 1) = w1;
        ws.W(j0, i0 + 2) = w2;
      }
    }
    for (int j = j0; j < i0 + size; ++j) {
      // A piece against a body where column j of Y is zero adds +-0 to a sum that
      // starts at +0: skipping it leaves W bit for bit the same.
      const std::uint64_t support = ws.row_support[j];
      const double* yj = Y + j * ldy;
      const int first = j > i0 ? j - i0 : 0;  // W_ij for i >= j only
      double w[6] = {0, 0, 0, 0, 0, 0};
      for (int q = 0; q < np; ++q) {
        if (!(support & bit[q])) continue;
        const double* y = yj + off[q];
        for (int a = first; a < size; ++a) w[a] += dot6(g[a][q], y);
      }
      for (int a = first; a < size; ++a) {
        ws.W(i0 + a, j) = w[a];
        ws.W(j, i0 + a) = w[a];
      }
    }
  }
}

}  // namespace nscd
