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
  // Column j of Y is nonzero only on the bodies of its support.
  for (int j = 0; j < r; ++j)
    for (std::uint64_t m = ws.row_support[j]; m != 0; m &= m - 1) {
      const int c = __builtin_ctzll(m);
      ws.vnew.segment<6>(6 * c) += ws.P[j] * ws.Y.block<6, 1>(6 * c, j);
    }
}

}  // namespace nscd
