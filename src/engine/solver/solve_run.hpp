// One call of FrictionContactSolver::solve as data, internal to the engine: the
// problem as the algorithms see it (SolveProblem), the iterate they improve
// (Iterate), the keeper of the best iterate (BestIterate), the NSGS sweeps' own
// state (NsgsState), and the run that holds them with the report
// (SolveRun). The stages of the schedule (solver_schedule.cpp) are functions
// of a SolveRun; the algorithms under them (nsgs.cpp, global_newton.cpp,
// proximal_newton.cpp, cone_fixed_point.cpp) take the parts they use.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "nscd_sim/friction_contact_solver.hpp"

namespace nscd {

using SolverBuffers = FrictionContactSolver::Buffers;

// The problem U = W P + b (the top-left m x m of W is read) with what
// prepareProblem derives from it: the zero rows, the Newton's row scaling and
// the factored equality block live in the buffers (buf.zeroRow, buf.rho,
// buf.eqL ...), the scalars here.
struct SolveProblem {
  SolveProblem(const Eigen::Ref<const Eigen::MatrixXd>& W_, const Eigen::Ref<const Eigen::VectorXd>& b_,
               const std::vector<ProblemBlock>& blocks_, double tolerance_, int m_, SolverBuffers& buffers_)
      : W(W_), b(b_), blocks(blocks_), tolerance(tolerance_), m(m_), Wm(W_.topLeftCorner(m_, m_)),
        buf(buffers_) {}

  const Eigen::Ref<const Eigen::MatrixXd>& W;
  const Eigen::Ref<const Eigen::VectorXd>& b;
  const std::vector<ProblemBlock>& blocks;
  double tolerance;  // on the normalised error (see solverError)
  const int m;
  const Eigen::Block<const Eigen::Ref<const Eigen::MatrixXd>> Wm;
  SolverBuffers& buf;

  double maxDiag = 0;   // the largest W(i, i)
  double zeroDiag = 0;  // W(i, i) at most this: a zero row
  double bnorm = 0;     // |b|, the error's normalisation
  double localTol = 0;  // the local solver's tolerance
  int ne = 0;           // equality rows (buf.eqRows)
  // Every block bilateral (and the Equalities stage not skipped): the
  // schedule is the direct solve (solver_schedule.cpp), set up by
  // prepareEqualityProblem instead of prepareProblem.
  bool equalityOnly = false;
};

// An iterate P with U = W P + b (the sweeps update U incrementally and refresh
// it now and then) and the error of (P, U).
struct Iterate {
  Iterate(Eigen::Ref<Eigen::VectorXd> P_, Eigen::VectorXd& Ubuffer, int m)
      : P(P_), U(Ubuffer.head(m)) {}
  Eigen::Ref<Eigen::VectorXd> P;
  Eigen::VectorBlock<Eigen::VectorXd> U;
  double err = 0;
};

// The best iterate a run has seen: every start and every NSGS sweep is offered;
// a stage whose answer is at least as good as the best by construction (a
// restart at the best, the proximal Newton, the cone fixed point) makes it the
// best (adopt).
struct BestIterate {
  explicit BestIterate(Eigen::VectorXd& buffer, int m) : P(buffer.head(m)) {}
  Eigen::VectorBlock<Eigen::VectorXd> P;
  double err = 0;
  void offer(const Iterate& it) {
    if (it.err < err) adopt(it);
  }
  void adopt(const Iterate& it) {
    err = it.err;
    P = it.P;
  }
};

// The sweeps turn proximal (sigma > 0) when the error has not halved over a
// window of sweeps (nsgs.cpp): the error and the sweep it last halved at.
struct NsgsState {
  double sigma = 0;
  double stallErr = 0;
  int stallIt = 0;
  // A fresh start at error err (stallIt 0: the sweep count is the run's).
  static NsgsState fresh(double err) { return NsgsState{0, err, 0}; }
};

// A solve in progress: the problem, the iterate (the caller's P), the best
// iterate, the sweeps' state, the report, and what the schedule's stages tell
// the later ones.
struct SolveRun {
  SolveRun(const Eigen::Ref<const Eigen::MatrixXd>& W, const Eigen::Ref<const Eigen::VectorXd>& b,
           const std::vector<ProblemBlock>& blocks, const SolverOptions& options_,
           Eigen::Ref<Eigen::VectorXd> P, SolverBuffers& buf, int m)
      : problem(W, b, blocks, options_.tolerance, m, buf), options(options_), it(P, buf.U, m),
        best(buf.Pbest, m) {}

  SolveProblem problem;
  const SolverOptions& options;
  Iterate it;
  BestIterate best;
  NsgsState nsgs;
  SolverReport rep;
  // Newton iterations charged to the run's Newton budget (max_iterations): the
  // short attempts' and the long Newton's; the proximal Newton and the cone
  // fixed point have budgets of their own.
  int newtonBudgetUsed = 0;
  // The sweeps handed over to the Newton (solver_schedule.cpp), after this many.
  bool newtonDue = false;
  int sweepsAtHandover = 0;
  // The best error before the Newton's restarts from zero and the warm start:
  // where the sweeps go on after them depends on whether they improved on it.
  double bestBeforeRestarts = 0;
  // The last of the short Newton attempts ran and failed (its iterate is kept).
  bool lastAttemptFailed = false;
};

// ---- set-up (problem_setup.cpp)
// The zero rows (planar scenes), the Newton's row scaling, the factored
// equality block, |b| and the local tolerance. maxDiag: the largest W(i, i).
void prepareProblem(SolveProblem& pr, double maxDiag);
// An equality-only problem: the zero rows, the LDLᵀ of the other rows
// of W scaled to a unit diagonal (in buf.eqL, buf.eqScale), |b|.
void prepareEqualityProblem(SolveProblem& pr, double maxDiag);
// P = -W⁺ rhs (m rows) from the factor prepareEqualityProblem made: the basic
// solution, zero and dependent rows 0.
void solveByEqualityFactor(SolverBuffers& buf, int m, const double* rhs, double* P);
// The iterate made admissible (P = 0 on the zero rows), U = W P + b exactly, its error.
void restartIterate(const SolveProblem& pr, Iterate& it);
// U = W P + b exactly and the error, P as it is.
void refreshIterate(const SolveProblem& pr, Iterate& it);

// Siconos-style error of P given U (see solverError).
double errorFromU(const std::vector<ProblemBlock>& blocks, const double* P, const double* U,
                  double bnorm);

// ---- the algorithms the stages run
// nsgs.cpp: NSGS sweeps until converged or `until` sweeps in all (rep.sweeps),
// each iterate offered to run.best; false on a non-finite iterate.
bool runNsgs(SolveRun& run, int until);

// global_newton.cpp: the global semismooth Newton on the Alart-Curnier function
// from it.P, at most max_iterations iterations, giving up after `stall`
// iterations that did not halve the error; delta0: the Jacobian regularisation
// (relative to diag(W)) to start from and relax to.
struct NewtonBudget {
  int max_iterations;
  int stall;
  double delta0;
};
struct NewtonResult {
  bool converged = false;  // it.err <= pr.tolerance
  int iterations = 0;
};
// it is left at the last iterate (a failure: the caller decides where to go on).
NewtonResult runNewton(const SolveProblem& pr, Iterate& it, const NewtonBudget& budget);

// proximal_newton.cpp: the global Newton inside a proximal-point loop, from
// it.P, at most options.max_iterations Newton iterations (counted in
// run.rep.newton_iterations). Leaves `it` at its answer or, if it fails, its
// best iterate (restarted: P = 0 on the zero rows, U exact), and run.problem
// prepared again. True if converged.
bool runProximalNewton(SolveRun& run, Iterate& it);

// cone_fixed_point.cpp: for the problems it applies to (no zero rows, every
// frictional block mu > 0, at most kConeMaxRows rows), the fixed point on
// s = mu |U_T| of convex cone problems (each solved by the interior-point
// method), then a long Newton from its best answer. Leaves run.it at the
// answer or the best iterate it found (if better than its start, else the start).
bool coneFixedPointApplies(const SolveRun& run);
bool runConeFixedPoint(SolveRun& run);

}  // namespace nscd
