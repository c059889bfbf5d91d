// The global Newton inside a proximal-point loop: the last resort on hyperstatic
// sets (two rings and the bumps of a clearance joint, closed loops, a latch),
// where W is singular, the solutions are not isolated and the Alart-Curnier
// Jacobian is singular at them. Each outer step k solves the shifted problem
//   U = (W + sigma_k D) P + (b - sigma_k D P_k)
// (D: each block's mean diagonal of W, so a contact's cone is kept), which is
// strongly monotone, by the global Newton; a fixed point P = P_k solves the
// original problem. sigma_k = 5 x the current error, so the shift vanishes as the
// answer converges; an inner solve that fails is retried with 10 x sigma.
#include <algorithm>
#include <cmath>

#include "solve_run.hpp"

namespace nscd {
namespace {

constexpr int kMaxOuter = 40;
constexpr double kSigmaPerError = 5;
constexpr double kSigmaGrowth = 10;   // after a failed inner solve
constexpr double kInnerTolRatio = 0.1;  // inner tolerance: this x the outer error

void blockScales(const Eigen::Ref<const Eigen::MatrixXd>& W, const std::vector<ProblemBlock>& blocks,
                 double* D) {
  for (const ProblemBlock& bl : blocks) {
    double s = 0;
    for (int i = bl.row; i < bl.row + bl.size; ++i) s += W(i, i);
    s /= bl.size;
    for (int i = bl.row; i < bl.row + bl.size; ++i) D[i] = s;
  }
}

}  // namespace

bool runProximalNewton(SolveRun& run) {
  const int m = run.m;
  SolveRun::Workspace& ws = run.ws;
  SolverReport& rep = run.rep;
  const SolverOptions& options = run.options;
  Eigen::Ref<Eigen::VectorXd>& P = run.P;
  double* D = ws.Pouter.data() + m;  // Pouter holds 2m: the outer iterate, then D
  blockScales(run.Wm, run.blocks, D);
  const double maxDiag = run.maxDiag;

  SolverOptions inner = options;
  inner.method = SolverMethod::Newton;
  double sigma = kSigmaPerError * run.err;
  double bestErr = run.err;
  ws.Pbest.head(m) = P.head(m);
  bool converged = false;
  for (int outer = 0; outer < kMaxOuter && rep.newton_iterations < options.max_iterations; ++outer) {
    ws.Pouter.head(m) = P.head(m);
    auto Wp = ws.Wprox.topLeftCorner(m, m);
    Wp = run.Wm;
    for (int i = 0; i < m; ++i) {
      Wp(i, i) += sigma * D[i];
      ws.bprox(i) = run.b(i) - sigma * D[i] * P(i);
    }
    const Eigen::Ref<const Eigen::MatrixXd> Wref(Wp);
    const Eigen::Ref<const Eigen::VectorXd> bref(ws.bprox.head(m));
    inner.tolerance = std::max(1e-16, std::min(options.tolerance, kInnerTolRatio * run.err));
    inner.max_iterations = options.max_iterations - rep.newton_iterations;
    SolveRun in(Wref, bref, run.blocks, inner, P, ws, m);
    setUpRun(in, maxDiag * (1 + sigma));
    const bool ok = in.err <= inner.tolerance || runNewton(in);
    rep.newton_iterations += in.rep.newton_iterations;
    if (!ok) P.head(m) = ws.Pouter.head(m);
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
    sigma = ok ? kSigmaPerError * run.err : kSigmaGrowth * sigma;
  }
  if (!converged) P.head(m) = ws.Pbest.head(m);
  // The run's buffers (equality factor, scaling, U, error) back to the original problem.
  setUpRun(run, maxDiag);
  rep.converged = converged && run.err <= options.tolerance;
  return rep.converged;
}

}  // namespace nscd
