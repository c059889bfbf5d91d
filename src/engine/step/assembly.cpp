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

// Passes of the assembly projection, and how many in a row may leave the
// violation above half of what it was before the assembly gives up: a pose no
// projection can close (a loop whose bars cannot meet) oscillates about its
// least violation, and 200 passes of it took 3 s in Release (a fuzzed four-bar,
// 66 s under the fuzz build). Every scene and test of the repository assembles in
// 0-2 passes; a fuzzed C-60 with garbled origins in 16, 9 in a row not halving it.
constexpr int kAssemblyPasses = 200;
constexpr int kAssemblyStallPasses = 20;

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
  const int passes =
      projectPositions(m, s, ws, kAssemblyPasses, tol, violation, assembly, false, kAssemblyStallPasses);
  if (!(violation <= tol)) {  // a NaN too
    std::string why = std::to_string(passes) + " projection passes";
    if (passes >= kAssemblyStallPasses && passes < kAssemblyPasses)
      why += " (the last " + std::to_string(kAssemblyStallPasses) + " did not halve it)";
    throw std::runtime_error(m.source_file + ": assembly failed: constraint violation " +
                             std::to_string(violation) + " after " + why +
                             ": no pose near the given one satisfies the joints");
  }
  assembleVelocities(m, s, ws);
  trackJointPositions(m, s);  // from the scene's initial positions (whole turns kept)
}

}  // namespace nscd
