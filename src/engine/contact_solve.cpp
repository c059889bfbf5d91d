// Stage 4b: solve the friction-contact problem (friction_contact_solver.cpp) and
// apply its impulses: v+ = v_free + Ŵ G^T P.
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
  ws.vnew.noalias() += ws.Y.leftCols(r) * ws.P.head(r);
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
