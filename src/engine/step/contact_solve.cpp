// Stage 4b: the solver's options for a step, and the impulses applied:
// v+ = v_free + Ŵ G^T P. (The solve itself and its rescues: rescue_policy.cpp.)
#include <cstdint>

#include "step_stages.hpp"

namespace nscd {

SolverOptions solverOptions(const Settings& set) {
  SolverOptions o;
  o.tolerance = set.tolerance;
  o.max_iterations = set.max_iterations;
  return o;
}

void applyImpulses(StepWorkspace& ws) {
  const int r = ws.rows;
  ws.vnew = ws.vfree;
  if (ws.nbodies > 64) {  // no support masks (assembleDelassus)
    ws.vnew.noalias() += ws.Y.leftCols(r) * ws.P.head(r);
    return;
  }
  // Column j of Y is nonzero only on the bodies of its support. A body at a time
  // (its velocity kept in registers), each entry's sum over the rows in their order.
  std::uint64_t touched = 0;
  for (int j = 0; j < r; ++j) touched |= ws.row_support[j];
  for (; touched != 0; touched &= touched - 1) {
    const int c = __builtin_ctzll(touched);
    const std::uint64_t bit = std::uint64_t{1} << c;
    Vec6 v = ws.vnew.segment<6>(6 * c);
    for (int j = 0; j < r; ++j)
      if (ws.row_support[j] & bit) v += ws.P[j] * ws.Y.block<6, 1>(6 * c, j);
    ws.vnew.segment<6>(6 * c) = v;
  }
}

}  // namespace nscd
