// The global Newton inside a proximal-point loop, for the sets where the plain
// Newton fails: hyperstatic ones (two rings and the bumps of a clearance joint,
// closed loops, a latch), where W is singular, the solutions are not isolated
// and the Alart-Curnier Jacobian is singular at them; and badly conditioned ones
// (a light link between heavy ones: W's nonzero eigenvalues spread over 1e5 to
// 1e11, jammed joints whose impulses lie along the weakest of them). Outer step k
// solves the shifted problem
//   U = (W + s_k I) P + (b - s_k P_k),   s_k = sigma_k d,
// which is better conditioned, by the global Newton; a fixed point P = P_k solves
// the original problem. An inexact proximal point (Siconos's PROX):
// - the shift is uniform, d the smallest nonzero diagonal of W: it lifts all of
//   W's near-null directions alike. A shift in proportion to each block's
//   diagonal solved 40 of 123 problems the stress suite left unsolved, this one 72.
// - sigma_k = 0.05 x the outer error, so the shift vanishes as the answer converges;
// - the inner Newton only has to reach 0.1 x the outer error, and its last
//   iterate is kept even when it falls short (the next outer step goes on from it);
// - a failed inner solve multiplies sigma by 10; after a success sigma stays at
//   least 3 x the last failed one (a memory that halves at every success), or
//   the loop would drop back to the sigma that just failed and cycle;
// - over-relaxed (Eckstein-Bertsekas): after a solved inner problem the next
//   centre is P_k + 1.3 (P - P_k). On hyperstatic sets the iterates creep along
//   one direction, the impulses growing by a near-constant amount per outer
//   step (stress case 949's plastic re-solve: |P| 3 -> 32 in 40 steps towards
//   40). Of the 110 strictly feasible problems the stress suite left unsolved,
//   at the run's budget of 200, it solves 47 where the plain loop solved 1 (8
//   without its former cap of 40 outer steps; factor 1.2: 42, 1.4: 45; budget
//   1000: 35 -> 65); on the C-60 handle run (dt 1e-5) the most iterations in a
//   step 3455 -> 599. Only the centre moves: the answer and its error are an
//   inner problem's, a fixed point of which is a solution.
// - the outer steps are bounded by the Newton budget, not by a count of their
//   own: the loop may need a hundred (stress case 30's step 888 at h/16: 90).
// Its Newton iterations are counted in the report, against a budget of their own
// (max_iterations): they do not use up the plain Newton's.
#include <algorithm>
#include <cmath>

#include "solve_run.hpp"

namespace nscd {
namespace {

constexpr double kRelaxation = 1.3;       // the next centre: P_k + this x (P - P_k)
constexpr double kSigmaPerError = 0.05;
constexpr double kSigmaGrowth = 10;       // after a failed inner solve
constexpr double kSigmaAfterFailure = 3;  // sigma after a success: at least this x the last failed one
constexpr double kInnerTolRatio = 0.1;    // inner tolerance: this x the outer error

// The smallest diagonal of W that is not a zero row.
double smallestDiagonal(const SolveRun& run) {
  double d = INFINITY;
  for (int i = 0; i < run.m; ++i)
    if (run.Wm(i, i) > run.zeroDiag) d = std::min(d, run.Wm(i, i));
  return std::isfinite(d) ? d : run.maxDiag;
}

}  // namespace

bool runProximalNewton(SolveRun& run) {
  const int m = run.m;
  SolveRun::Workspace& ws = run.ws;
  SolverReport& rep = run.rep;
  const SolverOptions& options = run.options;
  Eigen::Ref<Eigen::VectorXd>& P = run.P;
  const double d = smallestDiagonal(run);
  const double maxDiag = run.maxDiag;

  SolverOptions inner = options;
  inner.method = SolverMethod::Newton;
  double sigma = kSigmaPerError * run.err;
  double failedSigma = 0;
  double bestErr = run.err;
  ws.Pbest.head(m) = P.head(m);
  bool converged = false;
  int used = 0;  // this loop's Newton iterations
  while (used < options.max_iterations) {  // each outer step costs at least one
    ws.Pcentre.head(m) = P.head(m);
    const double shift = sigma * d;
    auto Wp = ws.Wprox.topLeftCorner(m, m);
    Wp = run.Wm;
    for (int i = 0; i < m; ++i) {
      Wp(i, i) += shift;
      ws.bprox(i) = run.b(i) - shift * P(i);
    }
    const Eigen::Ref<const Eigen::MatrixXd> Wref(Wp);
    const Eigen::Ref<const Eigen::VectorXd> bref(ws.bprox.head(m));
    // The inner error is normalised by |b - shift P_k|, not |b|: with large
    // impulses the same velocity error reads smaller there, and the start P_k
    // (where both problems have the same U) passed as solved without a step.
    const double innerScale = std::max(1.0, run.bnorm) / std::max(1.0, ws.bprox.head(m).norm());
    inner.tolerance = std::max(1e-16, kInnerTolRatio * run.err * innerScale);
    inner.max_iterations = options.max_iterations - used;
    SolveRun in(Wref, bref, run.blocks, inner, P, ws, m);
    setUpRun(in, maxDiag + shift);
    const bool ok = in.err <= inner.tolerance || runNewton(in);
    rep.newton_iterations += in.rep.newton_iterations;
    run.ownBudgetNewtonIterations += in.rep.newton_iterations;
    used += std::max(1, in.rep.newton_iterations);
    run.refreshU();
    run.err = errorFromU(run.blocks, P.data(), run.U.data(), run.bnorm);
    if (!std::isfinite(run.err)) break;
    if (run.err < bestErr) {
      bestErr = run.err;
      ws.Pbest.head(m) = P.head(m);
    }
    if (run.err <= options.tolerance) {
      converged = true;
      break;
    }
    // The next centre (and the next inner Newton's start), over-relaxed; the
    // inner answer itself is what the error and the best iterate are of.
    if (ok) P.head(m) = ws.Pcentre.head(m) + kRelaxation * (P.head(m) - ws.Pcentre.head(m));
    if (!ok) {
      failedSigma = sigma;
      sigma *= kSigmaGrowth;
    } else {
      sigma = std::max(kSigmaPerError * run.err, kSigmaAfterFailure * failedSigma);
      failedSigma *= 0.5;
    }
  }
  if (!converged) P.head(m) = ws.Pbest.head(m);
  run.bestAll = bestErr;  // ws.Pbest is now this loop's best
  // The run's buffers (equality factor, scaling, U, error) back to the original problem.
  setUpRun(run, maxDiag);
  rep.converged = converged && run.err <= options.tolerance;
  return rep.converged;
}

}  // namespace nscd
