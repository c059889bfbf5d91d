// Assembly before the first step: the positions are projected onto the
// constraints (a loop-closing joint's mismatch, initial penetrations), then the
// velocities onto the ideal joints' velocity constraints G v = 0 (the closest
// consistent velocities in the mass metric: an inelastic assembly). A scene's
// initial velocities then need not be consistent, and joints whose rows act on
// the average velocity (Settings::joint_work) never carry an inconsistency.
#include <stdexcept>
#include <string>

#include "step_stages.hpp"

namespace nscd {
namespace {

// Passes of the assembly projection.
constexpr int kAssemblyPasses = 200;

void assembleVelocities(const Model& m, State& s, StepWorkspace& ws) {
  clearConstraintRows(ws);
  appendBilateralRows(m, s, ws.zero_rates, ws);
  const int r = ws.rows;
  if (r == 0) return;
  stateVelocities(s, ws.vk);
  assembleDelassus(ws.mass_inverse, true, ws, 0, r);
  ws.b.head(r).noalias() = ws.G.topRows(r) * ws.vk;
  ws.problem.clear();
  for (const ConstraintBlock& blk : ws.blocks) {
    ProblemBlock pb;
    pb.kind = BlockKind::Bilateral;
    pb.row = blk.row;
    pb.size = blk.size;
    ws.problem.push_back(pb);
  }
  ws.P.head(r).setZero();
  SolverOptions options = solverOptions(m.settings);
  ws.solver.solve(ws.W.topLeftCorner(r, r), ws.b.head(r), ws.problem, options, ws.P.head(r));
  if (!ws.P.head(r).allFinite()) return;  // left as given: the first step enforces them
  ws.vnew = ws.vk;
  ws.vnew.noalias() += ws.Y.leftCols(r) * ws.P.head(r);
  setStateVelocities(s, ws.vnew);
  clearConstraintRows(ws);
}

}  // namespace

void assembleState(const Model& m, State& s, StepWorkspace& ws) {
  double violation = 0;
  const double tol = m.settings.projection_tolerance;
  StepStats assembly;
  projectPositions(m, s, ws, kAssemblyPasses, tol, violation, assembly);
  if (violation > tol)
    throw std::runtime_error(m.source_file + ": assembly failed: constraint violation " +
                             std::to_string(violation) + " after " +
                             std::to_string(kAssemblyPasses) + " projection passes");
  assembleVelocities(m, s, ws);
  trackJointPositions(m, s);  // from the scene's initial positions (whole turns kept)
}

}  // namespace nscd
