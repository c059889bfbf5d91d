// The last stage of the contact solver, for the problems every Newton stage
// left unsolved (badly conditioned hyperstatic sets: W singular, its nonzero
// eigenvalues spread over up to ten decades). With s = mu |U_T| on the normal
// rows held fixed, Coulomb's law with De Saxce's modified velocity is the
// optimality condition of a convex problem,
//   minimise 1/2 P^T W P + (b + s)^T P   over P in the friction cones
// (Acary, Cadoux, Lemarechal, Malick 2011), which an interior-point method
// solves whatever the conditioning (cone_interior_point.cpp). The fixed point
// s <- mu |U_T(P)| from s = 0 converges slowly (linearly), but a few of its
// steps bring P close enough for the global Newton: on the stress suite's
// problems that every Newton stage fails even at a budget of 2000, ten steps and
// a long Newton from the best of them solved 36 of 47 (a strictly feasible
// sample; docs/performance.md), forty 39. The friction cone {|P_T| <= mu P_N} becomes the
// second-order cone by y_N = mu P_N, y_T = P_T.
#include <algorithm>
#include <cmath>
#include <memory>

#include "cone_interior_point.hpp"
#include "solve_run.hpp"

namespace nscd {

struct ConeFixedPointWorkspace {
  int maxRows = 0;
  ConeQpWorkspace qp;
  Eigen::MatrixXd Q;                     // D^-1 W D^-1
  Eigen::VectorXd D, q, y, s, Pbest, Pkeep;
  std::vector<ConeBlock> blocks;
};

namespace {

constexpr int kConeMaxRows = 150;   // a dense LU per interior-point iteration
// Fixed-point steps before the Newton. Stress suite (unconverged steps, before
// the interior point's Tikhonov term): 10 steps 972, 20 922, 40 703, at 1.28x
// the CPU of 10; with the term, 40 steps: 1 310 (docs/performance.md).
constexpr int kFixedPointSteps = 40;
constexpr NewtonBudget kNewtonFromCone{500, 150, 1e-8};  // as the long last-resort Newton

ConeFixedPointWorkspace& workspace(SolveRun::Workspace& ws, int m) {
  if (!ws.cone) ws.cone = std::make_shared<ConeFixedPointWorkspace>();
  ConeFixedPointWorkspace& cw = *ws.cone;
  if (m > cw.maxRows) {
    cw.maxRows = m;
    cw.Q.resize(m, m);
    for (Eigen::VectorXd* v : {&cw.D, &cw.q, &cw.y, &cw.s, &cw.Pbest, &cw.Pkeep}) v->resize(m);
    cw.blocks.reserve(m);
  }
  return cw;
}

}  // namespace

bool runConeFixedPoint(SolveRun& run) {
  const int m = run.m;
  if (m > kConeMaxRows) return false;
  for (int i = 0; i < m; ++i)
    if (run.ws.zeroRow[i]) return false;
  for (const ProblemBlock& bl : run.blocks)
    if (bl.kind == BlockKind::Frictional && !(bl.mu > 0)) return false;
  ConeFixedPointWorkspace& cw = workspace(run.ws, m);
  SolverReport& rep = run.rep;
  Eigen::Ref<Eigen::VectorXd>& P = run.P;

  // Start from the best answer so far (what the solve returns if this fails).
  if (run.bestAll < run.err) {
    P.head(m) = run.ws.Pbest.head(m);
    setUpRun(run, run.maxDiag);
  }
  cw.Pkeep.head(m) = P.head(m);
  const double errBefore = run.err;

  auto D = cw.D.head(m);
  D.setOnes();
  cw.blocks.clear();
  for (const ProblemBlock& bl : run.blocks) {
    ConeBlock c;
    c.row = bl.row;
    c.size = bl.size;
    if (bl.kind == BlockKind::Frictional) {
      c.kind = ConeBlock::SecondOrder;
      D(bl.row) = bl.mu;
    } else {
      c.kind = bl.kind == BlockKind::Frictionless ? ConeBlock::HalfLine : ConeBlock::Free;
    }
    cw.blocks.push_back(c);
  }
  auto Q = cw.Q.topLeftCorner(m, m);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) Q(i, j) = run.Wm(i, j) / (D(i) * D(j));
  auto s = cw.s.head(m);
  s.setZero();
  double bestErr = INFINITY;
  for (int k = 0; k < kFixedPointSteps; ++k) {
    cw.q.head(m) = (run.b.head(m) + s).cwiseQuotient(D);
    const ConeQpReport qr = solveConeQp(Q, cw.q.head(m), cw.blocks, m, cw.qp, cw.y.head(m));
    rep.interior_point_iterations += qr.iterations;
    P.head(m) = cw.y.head(m).cwiseQuotient(D);
    run.refreshU();
    const double e = errorFromU(run.blocks, P.data(), run.U.data(), run.bnorm);
    if (!std::isfinite(e)) break;
    if (e < bestErr) {
      bestErr = e;
      cw.Pbest.head(m) = P.head(m);
    }
    if (e <= run.options.tolerance) break;
    for (const ProblemBlock& bl : run.blocks)
      if (bl.kind == BlockKind::Frictional)
        s(bl.row) = bl.mu * std::hypot(run.U(bl.row + 1), run.U(bl.row + 2));
  }
  if (std::isfinite(bestErr)) {
    P.head(m) = cw.Pbest.head(m);
    setUpRun(run, run.maxDiag);
    if (run.err <= run.options.tolerance) {
      rep.converged = true;
      return true;
    }
    // The Newton from here has a budget of its own.
    run.ownBudgetNewtonIterations = rep.newton_iterations;
    if (runNewton(run, kNewtonFromCone)) return true;
    if (run.err < bestErr) {
      bestErr = run.err;
      cw.Pbest.head(m) = P.head(m);
    }
  }
  // Failed: the best answer it found if better than the one it started from.
  P.head(m) = bestErr < errBefore ? cw.Pbest.head(m) : cw.Pkeep.head(m);
  setUpRun(run, run.maxDiag);
  return false;
}

}  // namespace nscd
