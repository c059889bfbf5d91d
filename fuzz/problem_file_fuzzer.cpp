// Fuzz target: a friction-contact problem file (nscd::readProblemFile, what
// nscd_solve_problems and the solver tests read), then solved as
// nscd_solve_problems solves it, from the file's warm start and from zero, with a
// budget of 30 iterations. A bad file is refused with one line naming it; a file
// read is consistent (fuzz_support's readProblemInput).
//
// The solver is the input's own, so a finding reproduces from its input alone (a
// solver kept across inputs made a crash depend on the inputs before it, whose
// order follows the file system's). Reuse is checked within the input: the
// problem of the first half of its blocks is solved on the fresh solver, then the
// whole problem, then the half again, which must give the same bits (a kept
// solver answers as a fresh one; test_solver_reuse checks the same on the
// repository's problems in many orders).
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "fuzz_support.hpp"
#include "nscd_sim/friction_contact_solver.hpp"

namespace {

struct Answer {
  Eigen::VectorXd P;
  nscd::SolverReport report;
};

bool identical(const Answer& x, const Answer& y) {
  const nscd::SolverReport &r = x.report, &s = y.report;
  return x.P.size() == y.P.size() && std::memcmp(x.P.data(), y.P.data(), sizeof(double) * x.P.size()) == 0 &&
         std::memcmp(&r.residual, &s.residual, sizeof(double)) == 0 && r.converged == s.converged &&
         r.iteration_sum == s.iteration_sum && r.sweeps == s.sweeps && r.newton_iterations == s.newton_iterations &&
         r.interior_point_iterations == s.interior_point_iterations && r.stage == s.stage;
}

Answer solveChecked(nscd::FrictionContactSolver& solver, const Eigen::MatrixXd& W, const Eigen::VectorXd& b,
                    const std::vector<nscd::ProblemBlock>& blocks, const nscd::SolverOptions& options,
                    const Eigen::VectorXd& P_start) {
  Answer a{P_start, {}};
  a.report = solver.solve(W, b, blocks, options, a.P);
  if (a.report.converged && !a.P.allFinite()) nscd_fuzz::fail("a converged answer that is not finite");
  return a;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nscd::ProblemFile p;
  if (!nscd_fuzz::readProblemInput(data, size, p)) return 0;
  nscd::FrictionContactSolver solver;
  nscd::SolverOptions options;
  options.max_iterations = 30;
  const Eigen::Index m = p.b.size();
  // The first half of the blocks (rounded up), on the rows up to the last of them.
  const std::vector<nscd::ProblemBlock> half(p.blocks.begin(), p.blocks.begin() + (p.blocks.size() + 1) / 2);
  int mh = 0;
  for (const nscd::ProblemBlock& bl : half) mh = std::max(mh, bl.row + bl.size);
  const Eigen::MatrixXd Wh = p.W.topLeftCorner(mh, mh);
  const Eigen::VectorXd bh = p.b.head(mh), Ph = p.P_start.head(mh);
  const Answer first = solveChecked(solver, Wh, bh, half, options, Ph);
  solveChecked(solver, p.W, p.b, p.blocks, options, p.P_start);
  solveChecked(solver, p.W, p.b, p.blocks, options, Eigen::VectorXd::Zero(m));
  const Answer again = solveChecked(solver, Wh, bh, half, options, Ph);
  if (!identical(first, again))
    nscd_fuzz::fail("the first half of the blocks solved again after the whole problem: another answer (stage " +
                    std::string(nscd::solverStageName(again.report.stage)) + ", fresh " +
                    nscd::solverStageName(first.report.stage) + ")");
  return 0;
}
