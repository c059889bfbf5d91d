// The global semismooth Newton on the Alart-Curnier function of the whole
// problem (alart_curnier.cpp), for strongly coupled problems where the sweeps
// converge slowly: a non-monotone Armijo line search on 0.5 |phi|^2, the
// Jacobian of the problem with W + delta diag(W), delta growing when a step
// fails (Levenberg-like). It gives up (false) when it stops making progress;
// the driver then resumes the sweeps from where it started.
#include <algorithm>
#include <cmath>

#include "alart_curnier.hpp"
#include "dense_kernels.hpp"
#include "solve_run.hpp"

namespace nscd {
namespace {

constexpr NewtonBudget kNewtonAttempt{60, 25, 1e-10};  // per attempt: iterations, without halving the error, delta
constexpr int kNonMonotone = 5;          // merit history of the line search
constexpr int kLineSearchSteps = 30;
constexpr double kNewtonDeltaMax = 1e-1;
constexpr double kNewtonShortStep = 0.25;  // accepted step length below this: more delta
constexpr double kNewtonMaxImpulse = 1e3;  // iterates bounded by this * impulse scale

}  // namespace

bool runNewton(SolveRun& run) { return runNewton(run, kNewtonAttempt); }

bool runNewton(SolveRun& run, const NewtonBudget& budget) {
  const auto& W = run.W;
  const auto& b = run.b;
  const std::vector<ProblemBlock>& blocks = run.blocks;
  const SolverOptions& options = run.options;
  Eigen::Ref<Eigen::VectorXd>& P = run.P;
  SolveRun::Workspace& ws = run.ws;
  const int m = run.m;
  const auto& Wm = run.Wm;
  auto& U = run.U;
  SolverReport& rep = run.rep;
  double& err = run.err;
  const double* rho = ws.rho.data();
  const char* zeroRow = ws.zeroRow.data();
  const double bnorm = run.bnorm;

  auto J = ws.J.topLeftCorner(m, m);
  const int ld = int(ws.J.rows());
  const int maxIt = std::min(budget.max_iterations, options.max_iterations - rep.newton_iterations +
                                                        run.ownBudgetNewtonIterations);
  ws.Pstart.head(m) = P.head(m);
  run.refreshU();
  double f = acResidual(blocks, P.data(), U.data(), rho, zeroRow, ws.phi.data());
  double hist[kNonMonotone];
  for (double& h : hist) h = f;
  double delta = budget.delta0;
  // Iterates are kept within kNewtonMaxImpulse times the impulse scale of
  // the problem (what stops each row alone, or the start): on problems
  // without a solution (jamming, b outside range(W) in position projection)
  // the Alart-Curnier residual decreases towards infinity along near-null
  // directions of W, with impulses that change nothing but round-off.
  double impulseScale = P.head(m).cwiseAbs().maxCoeff();
  for (int i = 0; i < m; ++i)
    if (!zeroRow[i]) impulseScale = std::max(impulseScale, std::abs(b(i)) / W(i, i));
  const double impulseCap = kNewtonMaxImpulse * impulseScale;
  double progressErr = err;
  int noProgress = 0;
  for (int it = 0; it < maxIt; ++it) {
    ++rep.newton_iterations;
    acJacobian(W, blocks, P.data(), U.data(), rho, zeroRow, delta, J);
    bool stepped = false;
    double t = 1;
    if (luFactor(ws.J.data(), ld, m, ws.piv.data())) {
      ws.d.head(m) = -ws.phi.head(m);
      luSolve(ws.J.data(), ld, m, ws.piv.data(), ws.d.data());
      if (ws.d.head(m).allFinite()) {
        ws.Wd.head(m).noalias() = Wm * ws.d.head(m);
        double fref = 0;
        for (double h : hist) fref = std::max(fref, h);
        for (int ls = 0; ls < kLineSearchSteps; ++ls, t *= 0.5) {
          ws.Pt.head(m) = P.head(m) + t * ws.d.head(m);
          if (ws.Pt.head(m).cwiseAbs().maxCoeff() > impulseCap) continue;
          ws.Ut.head(m) = U + t * ws.Wd.head(m);
          const double ft = acResidual(blocks, ws.Pt.data(), ws.Ut.data(), rho, zeroRow, ws.phiT.data());
          if (ft <= fref - 2e-4 * t * f) {
            stepped = true;
            break;
          }
        }
      }
    }
    if (!stepped) {
      if (delta >= kNewtonDeltaMax) return false;
      delta *= 1e3;
      continue;
    }
    // A short step means a poor model (kink, near-singular J): regularise
    // more (Levenberg-like); a full step lets delta relax back.
    delta = t < kNewtonShortStep ? std::min(kNewtonDeltaMax, 1e3 * delta)
                                 : std::max(budget.delta0, 1e-2 * delta);
    P.head(m) = ws.Pt.head(m);
    run.refreshU();
    f = acResidual(blocks, P.data(), U.data(), rho, zeroRow, ws.phi.data());
    for (int h = kNonMonotone - 1; h > 0; --h) hist[h] = hist[h - 1];
    hist[0] = f;
    err = errorFromU(blocks, P.data(), U.data(), bnorm);
    if (!std::isfinite(err)) return false;
    if (err <= options.tolerance) {
      rep.converged = true;
      return true;
    }
    if (err < 0.5 * progressErr) {
      progressErr = err;
      noProgress = 0;
    } else if (++noProgress >= budget.stall) {
      return false;
    }
  }
  return false;
}

}  // namespace nscd
