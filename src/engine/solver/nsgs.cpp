// Nonsmooth Gauss-Seidel over the blocks of the problem, with the running local
// velocities U = W P + b updated incrementally (O(m) per block), an exact local
// solve per frictional block (local_contact_solver.cpp), and all equality rows
// solved together. Plain NSGS can stall on hyperstatic sets (W singular): if the
// error has not halved over kStallWindow sweeps, it turns proximal: every
// contact problem gets + eps (P - P_previous) (eps = sigma * its mean diagonal),
// a damping whose fixed points are the same solutions.
#include <Eigen/Core>

#include "dense_kernels.hpp"
#include "solve_run.hpp"

namespace nscd {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr int kRefreshEvery = 16;       // recompute U = W P + b exactly this often (round-off)
constexpr int kStallWindow = 100;       // sweeps without halving the error = stalled
constexpr double kProximalSigma = 0.1;  // proximal weight relative to the block diagonal

// The equality block solved exactly for the current U (all bilateral rows at
// once, from the factor made by the driver).
void solveEqualities(SolveRun& run) {
  const int ne = run.ne;
  SolveRun::Workspace& ws = run.ws;
  auto& U = run.U;
  const auto& Wm = run.Wm;
  Eigen::Ref<Eigen::VectorXd>& P = run.P;

  if (ne == 0) return;
  double* x = ws.eqRhs.data();
  for (int a = 0; a < ne; ++a) x[a] = -U(ws.eqRows[a]);
  pivotedCholeskySolve(ws.eqL.data(), int(ws.eqL.rows()), ne, ws.eqRank, ws.eqPerm.data(), x, x + ne);
  for (int a = 0; a < ne; ++a) {
    if (x[a] == 0) continue;
    U += x[a] * Wm.col(ws.eqRows[a]);
    P(ws.eqRows[a]) += x[a];
  }
}

}  // namespace

bool runNsgs(SolveRun& run, int until) {
  const auto& W = run.W;
  const std::vector<ProblemBlock>& blocks = run.blocks;
  const SolverOptions& options = run.options;
  Eigen::Ref<Eigen::VectorXd>& P = run.P;
  const auto& Wm = run.Wm;
  auto& U = run.U;
  SolverReport& rep = run.rep;
  double& err = run.err;
  const double zeroDiag = run.zeroDiag;
  const double localTol = run.localTol;
  const double bnorm = run.bnorm;
  double& sigma = run.sigma;
  double& stallErr = run.stallErr;
  int& stallIt = run.stallIt;

  while (rep.sweeps < until) {
    bool eqDone = false;
    for (const ProblemBlock& bl : blocks) {
      const int r = bl.row;
      switch (bl.kind) {
        case BlockKind::Frictional: {
          Matrix3d Wl = W.block<3, 3>(r, r);
          const Vector3d Pold = P.segment<3>(r);
          Vector3d bl3 = U.segment<3>(r) - Wl * Pold;
          if (sigma > 0) {  // proximal term eps |P - Pold|^2 / 2
            const double eps = sigma * Wl.trace() / 3;
            Wl.diagonal().array() += eps;
            bl3 -= eps * Pold;
          }
          Vector3d Pnew = Pold;
          solveLocalFrictional(Wl, bl3, bl.mu, localTol, Pnew, nullptr, &run.ws.localFactor[r]);
          const Vector3d dP = Pnew - Pold;
          if (!dP.isZero(0)) {
            U.noalias() += Wm.middleCols<3>(r) * dP;
            P.segment<3>(r) = Pnew;
          }
          break;
        }
        case BlockKind::Frictionless: {
          const double w = W(r, r);
          const double pn = w > zeroDiag ? std::max(0.0, P(r) - U(r) / ((1 + sigma) * w)) : 0.0;
          const double dP = pn - P(r);
          if (dP != 0) {
            U += dP * Wm.col(r);
            P(r) = pn;
          }
          break;
        }
        case BlockKind::Bilateral:
          if (!eqDone) solveEqualities(run);  // all equalities at the first one
          eqDone = true;
          break;
      }
    }
    const int it = ++rep.sweeps;
    if (it % kRefreshEvery == 0) run.refreshU();
    err = errorFromU(blocks, P.data(), U.data(), bnorm);
    if (!std::isfinite(err)) return false;
    if (err < 0.5 * stallErr) {
      stallErr = err;
      stallIt = it;
    } else if (sigma == 0 && it - stallIt >= kStallWindow) {
      sigma = kProximalSigma;
    }
    if (err <= options.tolerance) {
      run.refreshU();  // confirm on the exact U before declaring convergence
      err = errorFromU(blocks, P.data(), U.data(), bnorm);
      if (err <= options.tolerance) {
        rep.converged = true;
        break;
      }
    }
    run.offerBest();
  }
  run.offerBest();
  return true;
}

void resumeNsgs(SolveRun& run) {
  Eigen::Ref<Eigen::VectorXd>& P = run.P;
  const int m = run.m;
  SolveRun::Workspace& ws = run.ws;

  P.head(m) = ws.Pstart.head(m);
  run.refreshU();
  run.err = errorFromU(run.blocks, P.data(), run.U.data(), run.bnorm);
  run.stallErr = run.err;
  run.stallIt = run.rep.sweeps;
}

}  // namespace nscd
