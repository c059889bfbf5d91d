// One call of FrictionContactSolver::solve as data: the problem, the solver's
// buffers, and the state the NSGS sweeps (nsgs.cpp) and the global Newton
// (global_newton.cpp) share and hand to each other. Internal to the engine.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "nscd_sim/friction_contact_solver.hpp"

namespace nscd {

struct SolveRun {
  using Workspace = FrictionContactSolver::Workspace;

  SolveRun(const Eigen::Ref<const Eigen::MatrixXd>& W_, const Eigen::Ref<const Eigen::VectorXd>& b_,
           const std::vector<ProblemBlock>& blocks_, const SolverOptions& options_,
           Eigen::Ref<Eigen::VectorXd>& P_, Workspace& ws_, int m_)
      : W(W_), b(b_), blocks(blocks_), options(options_), P(P_), ws(ws_), m(m_),
        Wm(W_.topLeftCorner(m_, m_)), U(ws_.U.head(m_)) {}

  // The problem (the top-left m x m of W is read) and the answer being built.
  const Eigen::Ref<const Eigen::MatrixXd>& W;
  const Eigen::Ref<const Eigen::VectorXd>& b;
  const std::vector<ProblemBlock>& blocks;
  const SolverOptions& options;
  Eigen::Ref<Eigen::VectorXd>& P;
  Workspace& ws;
  const int m;
  const Eigen::Block<const Eigen::Ref<const Eigen::MatrixXd>> Wm;
  Eigen::VectorBlock<Eigen::VectorXd> U;  // running local velocities W P + b

  double maxDiag = 0;    // the largest W(i, i) (setUpRun keeps it for later set-ups)
  double zeroDiag = 0;   // W(i, i) at most this: a zero row
  double bnorm = 0;      // |b|, the error's normalisation
  double localTol = 0;   // the local solver's tolerance
  int ne = 0;            // equality rows (ws.eqRows)
  SolverReport rep;
  double err = 0;        // error of P
  double bestAll = 0;    // error of ws.Pbest, the best NSGS iterate
  // Of rep.newton_iterations, those not charged to the plain Newton's budget:
  // the proximal loop's (proximal_newton.cpp) and those before the Newton from
  // the cone fixed point's answer (cone_fixed_point.cpp), which have budgets of
  // their own.
  int ownBudgetNewtonIterations = 0;
  // Proximal NSGS (see nsgs.cpp): weight, and the error and sweep it last halved at.
  double sigma = 0;
  double stallErr = 0;
  int stallIt = 0;

  // U = W P + b exactly (the sweeps update it incrementally).
  void refreshU() {
    U.noalias() = Wm * P.head(m);
    U += b.head(m);
  }
  void offerBest() {
    if (err < bestAll) {
      bestAll = err;
      ws.Pbest.head(m) = P.head(m);
    }
  }
};

// Sets a run up at its current P (friction_contact_solver.cpp): zero rows, the
// Newton scaling, the factored equality block, U, the error. maxDiag: the largest W(i, i).
void setUpRun(SolveRun& run, double maxDiag);

// Siconos-style error of P given U (see solverError).
double errorFromU(const std::vector<ProblemBlock>& blocks, const double* P, const double* U,
                  double bnorm);

// nsgs.cpp: NSGS sweeps until converged or `until` sweeps in all; false on a
// non-finite iterate.
bool runNsgs(SolveRun& run, int until);
// NSGS starts again from P = ws.Pstart (after a failed Newton).
void resumeNsgs(SolveRun& run);

// cone_fixed_point.cpp: the fixed point on s = mu |U_T| of convex cone
// problems (each solved by the interior-point method), then a long Newton from
// its best answer; true if that converged. Runs on problems without zero rows
// whose frictional blocks all have mu > 0, up to kConeMaxRows rows (false
// otherwise, nothing changed). If it fails, P and the run are as they were.
bool runConeFixedPoint(SolveRun& run);

// global_newton.cpp: the global semismooth Newton from the current P; false if
// it gives up (P is then left at its last iterate: see resumeNsgs). The budget:
// at most max_iterations, and give up after `stall` iterations that did not
// halve the error; without one, a short attempt (60, 25).
struct NewtonBudget {
  int max_iterations;
  int stall;
  double delta0;  // the Jacobian regularisation (relative to diag(W)) to start from and relax to
};
bool runNewton(SolveRun& run);
bool runNewton(SolveRun& run, const NewtonBudget& budget);

// proximal_newton.cpp: the global Newton inside a proximal-point loop, for
// hyperstatic and badly conditioned sets where the plain Newton failed; false if
// it gives up (P is then its best iterate, and the run is set up again for the
// original problem).
bool runProximalNewton(SolveRun& run);

}  // namespace nscd
