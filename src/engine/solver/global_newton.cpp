// The global semismooth Newton on the Alart-Curnier function of the whole
// problem (alart_curnier.cpp), for strongly coupled problems where the sweeps
// converge slowly: a non-monotone Armijo line search on 0.5 |phi|^2, the
// Jacobian of the problem with W + delta diag(W), delta growing when a step
// fails (Levenberg-like). It gives up (false) when it stops making progress;
// the stage that ran it decides where the solve goes on.
#include <algorithm>
#include <cmath>

#include "alart_curnier.hpp"
#include "dense_kernels.hpp"
#include "solve_run.hpp"

namespace nscd {
namespace {

constexpr int kNonMonotone = 5;          // merit history of the line search
constexpr int kLineSearchSteps = 30;
constexpr double kNewtonDeltaMax = 1e-1;
constexpr double kNewtonShortStep = 0.25;  // accepted step length below this: more delta
constexpr double kNewtonMaxImpulse = 1e3;  // iterates bounded by this * impulse scale

// y = W x over the m rows: each entry summed over the columns in order from +0,
// as Eigen's matrix-vector product sums it (the same bits), in AVX where the
// machine has it (no FMA: the same products and sums).
__attribute__((target_clones("avx", "default"))) void timesW(const double* W, long ld, int m,
                                                             const double* __restrict x,
                                                             double* __restrict y) {
  for (int i = 0; i < m; ++i) y[i] = 0;
  for (int j = 0; j < m; ++j) {
    const double xj = x[j];
    const double* wc = W + j * ld;
    for (int i = 0; i < m; ++i) y[i] += wc[i] * xj;
  }
}

// Iterates are kept within kNewtonMaxImpulse times the impulse scale of the
// problem (what stops each row alone, or the start): on problems without a
// solution (jamming, b outside range(W) in position projection) the
// Alart-Curnier residual decreases towards infinity along near-null directions
// of W, with impulses that change nothing but round-off.
double impulseCap(const SolveProblem& pr, const Iterate& it) {
  const char* zeroRow = pr.buf.zeroRow.data();
  double impulseScale = it.P.head(pr.m).cwiseAbs().maxCoeff();
  for (int i = 0; i < pr.m; ++i)
    if (!zeroRow[i]) impulseScale = std::max(impulseScale, std::abs(pr.b(i)) / pr.W(i, i));
  return kNewtonMaxImpulse * impulseScale;
}

// The Newton direction d (J d = -phi, J factored in place) and the
// non-monotone Armijo search along it: true with buf.Pt, buf.Ut at step t if a
// step was accepted. f: the merit at P; fref: the largest of the history.
bool newtonStep(const SolveProblem& pr, const Iterate& it, double delta, double f, double fref,
                double cap, double& t) {
  SolverBuffers& buf = pr.buf;
  const int m = pr.m;
  const int ld = int(buf.J.rows());
  acJacobian(pr.W, pr.blocks, it.P.data(), it.U.data(), buf.rho.data(), buf.zeroRow.data(), delta,
             buf.J.topLeftCorner(m, m));
  t = 1;
  if (!luFactor(buf.J.data(), ld, m, buf.piv.data())) return false;
  buf.d.head(m) = -buf.phi.head(m);
  luSolve(buf.J.data(), ld, m, buf.piv.data(), buf.d.data());
  if (!buf.d.head(m).allFinite()) return false;
  timesW(pr.W.data(), pr.W.outerStride(), m, buf.d.data(), buf.Wd.data());
  for (int ls = 0; ls < kLineSearchSteps; ++ls, t *= 0.5) {
    buf.Pt.head(m) = it.P.head(m) + t * buf.d.head(m);
    if (buf.Pt.head(m).cwiseAbs().maxCoeff() > cap) continue;
    buf.Ut.head(m) = it.U + t * buf.Wd.head(m);
    const double ft = acResidual(pr.blocks, buf.Pt.data(), buf.Ut.data(), buf.rho.data(), buf.zeroRow.data(),
                                 buf.phiT.data());
    if (ft <= fref - 2e-4 * t * f) return true;
  }
  return false;
}

}  // namespace

NewtonResult runNewton(const SolveProblem& pr, Iterate& it, const NewtonBudget& budget) {
  SolverBuffers& buf = pr.buf;
  const int m = pr.m;
  NewtonResult res;
  timesW(pr.W.data(), pr.W.outerStride(), m, it.P.data(), it.U.data());
  it.U += pr.b.head(m);
  double f = acResidual(pr.blocks, it.P.data(), it.U.data(), buf.rho.data(), buf.zeroRow.data(), buf.phi.data());
  double hist[kNonMonotone];
  for (double& h : hist) h = f;
  double delta = budget.delta0;
  const double cap = impulseCap(pr, it);
  double progressErr = it.err;
  int noProgress = 0;
  for (int k = 0; k < budget.max_iterations; ++k) {
    ++res.iterations;
    double fref = 0;
    for (double h : hist) fref = std::max(fref, h);
    double t = 1;
    if (!newtonStep(pr, it, delta, f, fref, cap, t)) {
      if (delta >= kNewtonDeltaMax) return res;
      delta *= 1e3;
      continue;
    }
    // A short step means a poor model (kink, near-singular J): regularise
    // more (Levenberg-like); a full step lets delta relax back.
    delta = t < kNewtonShortStep ? std::min(kNewtonDeltaMax, 1e3 * delta) : std::max(budget.delta0, 1e-2 * delta);
    it.P.head(m) = buf.Pt.head(m);
    timesW(pr.W.data(), pr.W.outerStride(), m, it.P.data(), it.U.data());
    it.U += pr.b.head(m);
    f = acResidual(pr.blocks, it.P.data(), it.U.data(), buf.rho.data(), buf.zeroRow.data(), buf.phi.data());
    for (int h = kNonMonotone - 1; h > 0; --h) hist[h] = hist[h - 1];
    hist[0] = f;
    it.err = errorFromU(pr.blocks, it.P.data(), it.U.data(), pr.bnorm);
    if (!std::isfinite(it.err)) return res;
    if (it.err <= pr.tolerance) {
      res.converged = true;
      return res;
    }
    if (it.err < 0.5 * progressErr) {
      progressErr = it.err;
      noProgress = 0;
    } else if (++noProgress >= budget.stall) {
      return res;
    }
  }
  return res;
}

}  // namespace nscd
