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
//   W's near-null directions alike, where a shift in proportion to each block's
//   diagonal left the weakest directions as ill-conditioned as before
//   (docs/solver.md);
// - sigma_k = 0.05 x the outer error, so the shift vanishes as the answer converges;
// - the inner Newton only has to reach 0.1 x the outer error, and its last
//   iterate is kept even when it falls short (the next outer step goes on from it);
// - a failed inner solve multiplies sigma by 10; after a success sigma stays at
//   least 3 x the last failed one (a memory that halves at every success), or
//   the loop would drop back to the sigma that just failed and cycle;
// - over-relaxed (Eckstein-Bertsekas): after a solved inner problem the next
//   centre is P_k + 1.3 (P - P_k). On hyperstatic sets the iterates creep along
//   one direction, the impulses growing by a near-constant amount per outer
//   step; the over-relaxation covers that distance in fewer steps. Only the
//   centre moves: the answer and its error are an inner problem's, a fixed
//   point of which is a solution.
// - the outer steps are bounded by the Newton budget, not by a count of their
//   own: a creeping set may need a hundred of them.
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
constexpr NewtonBudget kInnerNewton{60, 25, 1e-10};  // as a short Newton attempt

// The smallest diagonal of W that is not a zero row.
double smallestDiagonal(const SolveProblem& pr) {
  double d = INFINITY;
  for (int i = 0; i < pr.m; ++i)
    if (pr.Wm(i, i) > pr.zeroDiag) d = std::min(d, pr.Wm(i, i));
  return std::isfinite(d) ? d : pr.maxDiag;
}

// One outer step: the problem shifted by `shift` about the centre it.P, solved
// by the Newton to kInnerTolRatio x the outer error with at most `budget`
// iterations; it.P is left at the inner answer. True if the inner solve
// converged; `iterations`: the Newton iterations it took; `start`: the centre
// as the shifted problem started from it (P = 0 on its zero rows).
bool solveShifted(const SolveProblem& pr, double shift, double outerErr, int budget, Iterate& it,
                  int& iterations, Eigen::Ref<Eigen::VectorXd> start) {
  SolverBuffers& buf = pr.buf;
  const int m = pr.m;
  auto Wp = buf.Wprox.topLeftCorner(m, m);
  Wp = pr.Wm;
  for (int i = 0; i < m; ++i) {
    Wp(i, i) += shift;
    buf.bprox(i) = pr.b(i) - shift * it.P(i);
  }
  const Eigen::Ref<const Eigen::MatrixXd> Wref(Wp);
  const Eigen::Ref<const Eigen::VectorXd> bref(buf.bprox.head(m));
  // The inner error is normalised by |b - shift P_k|, not |b|: with large
  // impulses the same velocity error reads smaller there, and the start P_k
  // (where both problems have the same U) passed as solved without a step.
  const double innerScale = std::max(1.0, pr.bnorm) / std::max(1.0, buf.bprox.head(m).norm());
  SolveProblem inner(Wref, bref, pr.blocks, std::max(1e-16, kInnerTolRatio * outerErr * innerScale), m, buf);
  prepareProblem(inner, pr.maxDiag + shift);
  Iterate innerIt(it.P, buf.U, m);
  restartIterate(inner, innerIt);
  start = it.P.head(m);
  iterations = 0;
  if (innerIt.err <= inner.tolerance) return true;
  const NewtonResult r = runNewton(inner, innerIt, {std::min(kInnerNewton.max_iterations, budget),
                                                    kInnerNewton.stall, kInnerNewton.delta0});
  iterations = r.iterations;
  return r.converged;
}

}  // namespace

bool runProximalNewton(SolveRun& run, Iterate& it) {
  const SolveProblem& pr = run.problem;
  const int m = pr.m;
  SolverBuffers& buf = pr.buf;
  const int budget = run.options.max_iterations;
  const double d = smallestDiagonal(pr);
  double sigma = kSigmaPerError * it.err;
  double failedSigma = 0;
  double bestErr = it.err;
  auto Pbest = buf.proxBest.head(m);
  Pbest = it.P.head(m);
  bool converged = false;
  int used = 0;  // this loop's Newton iterations
  while (used < budget) {  // each outer step costs at least one
    buf.Pcentre.head(m) = it.P.head(m);
    int iterations = 0;
    // The best so far restarts at each outer step's centre (the answer the loop
    // returns when it fails is the last step's, or the centre it started from).
    const bool ok = solveShifted(pr, sigma * d, it.err, budget - used, it, iterations, Pbest);
    run.rep.newton_iterations += iterations;
    used += std::max(1, iterations);
    refreshIterate(pr, it);
    if (!std::isfinite(it.err)) break;
    if (it.err < bestErr) {
      bestErr = it.err;
      Pbest = it.P.head(m);
    }
    if (it.err <= pr.tolerance) {
      converged = true;
      break;
    }
    // The next centre (and the next inner Newton's start), over-relaxed; the
    // inner answer itself is what the error and the best iterate are of.
    if (ok) it.P.head(m) = buf.Pcentre.head(m) + kRelaxation * (it.P.head(m) - buf.Pcentre.head(m));
    if (!ok) {
      failedSigma = sigma;
      sigma *= kSigmaGrowth;
    } else {
      sigma = std::max(kSigmaPerError * it.err, kSigmaAfterFailure * failedSigma);
      failedSigma *= 0.5;
    }
  }
  if (!converged) it.P.head(m) = Pbest;
  // The prepared data in the buffers back to the original problem.
  prepareProblem(run.problem, pr.maxDiag);
  restartIterate(pr, it);
  return converged && it.err <= pr.tolerance;
}

}  // namespace nscd
