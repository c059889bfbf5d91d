// Nonsmooth Gauss-Seidel over the blocks of the problem, with the running local
// velocities U = W P + b updated incrementally (O(m) per block), an exact local
// solve per frictional block (local_contact_solver.cpp), and all equality rows
// solved together. Plain NSGS can stall on hyperstatic sets (W singular): if the
// error has not halved over kStallWindow sweeps, it turns proximal: every
// contact problem gets + eps (P - P_previous) (eps = sigma * its mean diagonal),
// a damping whose fixed points are the same solutions.
#include <algorithm>
#include <cmath>

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
// once, from the factor prepareProblem made).
void solveEqualities(const SolveProblem& pr, Iterate& it) {
  const int ne = pr.ne;
  const SolverBuffers& buf = pr.buf;
  if (ne == 0) return;
  double* x = pr.buf.eqRhs.data();
  for (int a = 0; a < ne; ++a) x[a] = -it.U(buf.eqRows[a]);
  pivotedCholeskySolve(buf.eqL.data(), int(buf.eqL.rows()), ne, buf.eqRank, buf.eqPerm.data(), x, x + ne);
  for (int a = 0; a < ne; ++a) {
    if (x[a] == 0) continue;
    it.U += x[a] * pr.Wm.col(buf.eqRows[a]);
    it.P(buf.eqRows[a]) += x[a];
  }
}

// One frictional block by the local solver, proximal when sigma > 0.
void sweepFrictional(const SolveProblem& pr, const ProblemBlock& bl, double sigma, Iterate& it) {
  const int r = bl.row;
  Matrix3d Wl = pr.W.block<3, 3>(r, r);
  const Vector3d Pold = it.P.segment<3>(r);
  Vector3d bl3 = it.U.segment<3>(r) - Wl * Pold;
  if (sigma > 0) {  // proximal term eps |P - Pold|^2 / 2
    const double eps = sigma * Wl.trace() / 3;
    Wl.diagonal().array() += eps;
    bl3 -= eps * Pold;
  }
  Vector3d Pnew = Pold;
  solveLocalFrictional(Wl, bl3, bl.mu, pr.localTol, Pnew, nullptr, &pr.buf.localFactor[r]);
  const Vector3d dP = Pnew - Pold;
  if (!dP.isZero(0)) {
    it.U.noalias() += pr.Wm.middleCols<3>(r) * dP;
    it.P.segment<3>(r) = Pnew;
  }
}

void sweepFrictionless(const SolveProblem& pr, const ProblemBlock& bl, double sigma, Iterate& it) {
  const int r = bl.row;
  const double w = pr.W(r, r);
  const double pn = w > pr.zeroDiag ? std::max(0.0, it.P(r) - it.U(r) / ((1 + sigma) * w)) : 0.0;
  const double dP = pn - it.P(r);
  if (dP != 0) {
    it.U += dP * pr.Wm.col(r);
    it.P(r) = pn;
  }
}

// One pass over the blocks; the equalities all at the first bilateral block.
void sweep(const SolveProblem& pr, double sigma, Iterate& it) {
  bool eqDone = false;
  for (const ProblemBlock& bl : pr.blocks) {
    switch (bl.kind) {
      case BlockKind::Frictional: sweepFrictional(pr, bl, sigma, it); break;
      case BlockKind::Frictionless: sweepFrictionless(pr, bl, sigma, it); break;
      case BlockKind::Bilateral:
        if (!eqDone) solveEqualities(pr, it);
        eqDone = true;
        break;
    }
  }
}

// After sweep number `sweeps`: the stall watch (the sweeps turn proximal).
void watchStall(double err, int sweeps, NsgsState& st) {
  if (err < 0.5 * st.stallErr) {
    st.stallErr = err;
    st.stallIt = sweeps;
  } else if (st.sigma == 0 && sweeps - st.stallIt >= kStallWindow) {
    st.sigma = kProximalSigma;
  }
}

}  // namespace

bool runNsgs(SolveRun& run, int until) {
  const SolveProblem& pr = run.problem;
  Iterate& it = run.it;
  SolverReport& rep = run.rep;
  while (rep.sweeps < until) {
    sweep(pr, run.nsgs.sigma, it);
    const int sweeps = ++rep.sweeps;
    if (sweeps % kRefreshEvery == 0) {
      it.U.noalias() = pr.Wm * it.P.head(pr.m);
      it.U += pr.b.head(pr.m);
    }
    it.err = errorFromU(pr.blocks, it.P.data(), it.U.data(), pr.bnorm);
    if (!std::isfinite(it.err)) return false;
    watchStall(it.err, sweeps, run.nsgs);
    // Converged: confirmed on the exact U before it is declared.
    if (it.err <= pr.tolerance) {
      refreshIterate(pr, it);
      if (it.err <= pr.tolerance) {
        rep.converged = true;
        break;
      }
    }
    run.best.offer(it);
  }
  run.best.offer(it);
  return true;
}

}  // namespace nscd
