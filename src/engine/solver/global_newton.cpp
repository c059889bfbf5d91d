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

// Iterates are kept within kNewtonMaxImpulse times the impulse scale of the
// problem (what stops each row alone, or the start): on problems without a
// solution (jamming, b outside range(W) in position projection) the
// Alart-Curnier residual decreases towards infinity along near-null directions
// of W, with impulses that change nothing but round-off.
double impulseCap(const SolveProblem& pr, const Iterate& it) {
  const char* zeroRow = pr.ws.zeroRow.data();
  double impulseScale = it.P.head(pr.m).cwiseAbs().maxCoeff();
  for (int i = 0; i < pr.m; ++i)
    if (!zeroRow[i]) impulseScale = std::max(impulseScale, std::abs(pr.b(i)) / pr.W(i, i));
  return kNewtonMaxImpulse * impulseScale;
}

// The Newton direction d (J d = -phi, J factored in place) and the
// non-monotone Armijo search along it: true with ws.Pt, ws.Ut at step t if a
// step was accepted. f: the merit at P; fref: the largest of the history.
bool newtonStep(const SolveProblem& pr, const Iterate& it, double delta, double f, double fref,
                double cap, double& t) {
  SolverWorkspace& ws = pr.ws;
  const int m = pr.m;
  const int ld = int(ws.J.rows());
  acJacobian(pr.W, pr.blocks, it.P.data(), it.U.data(), ws.rho.data(), ws.zeroRow.data(), delta,
             ws.J.topLeftCorner(m, m));
  t = 1;
  if (!luFactor(ws.J.data(), ld, m, ws.piv.data())) return false;
  ws.d.head(m) = -ws.phi.head(m);
  luSolve(ws.J.data(), ld, m, ws.piv.data(), ws.d.data());
  if (!ws.d.head(m).allFinite()) return false;
  ws.Wd.head(m).noalias() = pr.Wm * ws.d.head(m);
  for (int ls = 0; ls < kLineSearchSteps; ++ls, t *= 0.5) {
    ws.Pt.head(m) = it.P.head(m) + t * ws.d.head(m);
    if (ws.Pt.head(m).cwiseAbs().maxCoeff() > cap) continue;
    ws.Ut.head(m) = it.U + t * ws.Wd.head(m);
    const double ft = acResidual(pr.blocks, ws.Pt.data(), ws.Ut.data(), ws.rho.data(), ws.zeroRow.data(),
                                 ws.phiT.data());
    if (ft <= fref - 2e-4 * t * f) return true;
  }
  return false;
}

}  // namespace

NewtonResult runNewton(const SolveProblem& pr, Iterate& it, const NewtonBudget& budget) {
  SolverWorkspace& ws = pr.ws;
  const int m = pr.m;
  NewtonResult res;
  it.U.noalias() = pr.Wm * it.P.head(m);
  it.U += pr.b.head(m);
  double f = acResidual(pr.blocks, it.P.data(), it.U.data(), ws.rho.data(), ws.zeroRow.data(), ws.phi.data());
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
    it.P.head(m) = ws.Pt.head(m);
    it.U.noalias() = pr.Wm * it.P.head(m);
    it.U += pr.b.head(m);
    f = acResidual(pr.blocks, it.P.data(), it.U.data(), ws.rho.data(), ws.zeroRow.data(), ws.phi.data());
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
