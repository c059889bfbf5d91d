// Stage 4b: solve the friction-contact problem (friction_contact_solver.cpp) and
// apply its impulses: v+ = v_free + Ŵ G^T P.
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

SolverReport solveFrictionContact(StepWorkspace& ws, SolverOptions& options) {
  const int r = ws.rows;
  const auto W = ws.W.topLeftCorner(r, r);
  const auto b = ws.b.head(r);
  SolverReport rep = ws.solver.solve(W, b, ws.problem, options, ws.P.head(r));
  if (!ws.P.head(r).allFinite() && W.allFinite() && b.allFinite()) {
    // A non-finite answer from the Newton stage is never applied: solve again
    // cold by plain NSGS.
    ws.P.head(r).setZero();
    options.method = SolverMethod::NSGS;
    rep = ws.solver.solve(W, b, ws.problem, options, ws.P.head(r));
  }
  applyImpulses(ws);
  return rep;
}

}  // namespace nscd
