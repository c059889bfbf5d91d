// The last stage of the contact solver, for the problems every Newton stage
// left unsolved (badly conditioned hyperstatic sets: W singular, its nonzero
// eigenvalues spread over up to ten decades). With s = mu |U_T| on the normal
// rows held fixed, Coulomb's law with De Saxce's modified velocity is the
// optimality condition of a convex problem,
//   minimise 1/2 P^T W P + (b + s)^T P   over P in the friction cones
// (Acary, Cadoux, Lemarechal, Malick 2011), which an interior-point method
// solves whatever the conditioning (cone_interior_point.cpp). The fixed point
// s <- mu |U_T(P)| from s = 0 converges slowly (linearly), but a few of its
// steps bring P close enough for the global Newton, which then converges where
// it failed from every other start (docs/solver.md). The friction cone
// {|P_T| <= mu P_N} becomes the second-order cone by y_N = mu P_N, y_T = P_T.
#include <algorithm>
#include <cmath>
#include <memory>

#include "cone_interior_point.hpp"
#include "solve_run.hpp"

namespace nscd {

struct ConeFixedPointBuffers {
  int maxRows = 0;
  ConeQpBuffers qp;
  Eigen::MatrixXd Q;                     // D^-1 W D^-1
  Eigen::VectorXd D, q, y, s, Pbest, Pkeep;
  std::vector<ConeBlock> blocks;
};

namespace {

constexpr int kConeMaxRows = 150;   // a dense LU per interior-point iteration
// Fixed-point steps before the Newton: more steps bring the Newton's start
// closer, at the cost of one interior-point solve each (docs/solver.md).
constexpr int kFixedPointSteps = 40;
constexpr NewtonBudget kNewtonFromCone{500, 150, 1e-8};  // as the long last-resort Newton

ConeFixedPointBuffers& coneBuffers(SolverBuffers& buf, int m) {
  if (!buf.cone) buf.cone = std::make_shared<ConeFixedPointBuffers>();
  ConeFixedPointBuffers& cone = *buf.cone;
  if (m > cone.maxRows) {
    cone.maxRows = m;
    cone.Q.resize(m, m);
    for (Eigen::VectorXd* v : {&cone.D, &cone.q, &cone.y, &cone.s, &cone.Pbest, &cone.Pkeep}) v->resize(m);
    cone.blocks.reserve(m);
  }
  return cone;
}

// The cone problem's blocks and its scaled Q = D^-1 W D^-1 (D: mu on the normal rows).
void scaleToCones(const SolveProblem& pr, ConeFixedPointBuffers& cone) {
  const int m = pr.m;
  auto D = cone.D.head(m);
  D.setOnes();
  cone.blocks.clear();
  for (const ProblemBlock& bl : pr.blocks) {
    ConeBlock c;
    c.row = bl.row;
    c.size = bl.size;
    if (bl.kind == BlockKind::Frictional) {
      c.kind = ConeBlock::SecondOrder;
      D(bl.row) = bl.mu;
    } else {
      c.kind = bl.kind == BlockKind::Frictionless ? ConeBlock::HalfLine : ConeBlock::Free;
    }
    cone.blocks.push_back(c);
  }
  auto Q = cone.Q.topLeftCorner(m, m);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) Q(i, j) = pr.Wm(i, j) / (D(i) * D(j));
}

// The fixed point from s = 0: the best iterate into cone.Pbest; its error (INFINITY if none).
double fixedPoint(const SolveProblem& pr, ConeFixedPointBuffers& cone, Iterate& it, SolverReport& rep) {
  const int m = pr.m;
  auto D = cone.D.head(m);
  auto s = cone.s.head(m);
  s.setZero();
  double bestErr = INFINITY;
  for (int k = 0; k < kFixedPointSteps; ++k) {
    cone.q.head(m) = (pr.b.head(m) + s).cwiseQuotient(D);
    const ConeQpReport qr = solveConeQp(cone.Q.topLeftCorner(m, m), cone.q.head(m), cone.blocks, m, cone.qp, cone.y.head(m));
    rep.interior_point_iterations += qr.iterations;
    it.P.head(m) = cone.y.head(m).cwiseQuotient(D);
    it.U.noalias() = pr.Wm * it.P.head(m);
    it.U += pr.b.head(m);
    const double e = errorFromU(pr.blocks, it.P.data(), it.U.data(), pr.bnorm);
    if (!std::isfinite(e)) break;
    if (e < bestErr) {
      bestErr = e;
      cone.Pbest.head(m) = it.P.head(m);
    }
    if (e <= pr.tolerance) break;
    for (const ProblemBlock& bl : pr.blocks)
      if (bl.kind == BlockKind::Frictional) s(bl.row) = bl.mu * std::hypot(it.U(bl.row + 1), it.U(bl.row + 2));
  }
  return bestErr;
}

}  // namespace

bool coneFixedPointApplies(const SolveRun& run) {
  const SolveProblem& pr = run.problem;
  if (pr.m > kConeMaxRows) return false;
  for (int i = 0; i < pr.m; ++i)
    if (pr.buf.zeroRow[i]) return false;
  for (const ProblemBlock& bl : pr.blocks)
    if (bl.kind == BlockKind::Frictional && !(bl.mu > 0)) return false;
  return true;
}

bool runConeFixedPoint(SolveRun& run) {
  const SolveProblem& pr = run.problem;
  const int m = pr.m;
  Iterate& it = run.it;
  ConeFixedPointBuffers& cone = coneBuffers(pr.buf, m);
  cone.Pkeep.head(m) = it.P.head(m);
  const double errBefore = it.err;
  scaleToCones(pr, cone);
  double bestErr = fixedPoint(pr, cone, it, run.rep);
  if (std::isfinite(bestErr)) {
    it.P.head(m) = cone.Pbest.head(m);
    restartIterate(pr, it);
    if (it.err <= pr.tolerance) return true;
    // The Newton from here, on a budget of its own.
    const NewtonResult r = runNewton(pr, it, {std::min(kNewtonFromCone.max_iterations, run.options.max_iterations),
                                              kNewtonFromCone.stall, kNewtonFromCone.delta0});
    run.rep.newton_iterations += r.iterations;
    if (r.converged) return true;
    if (it.err < bestErr) {
      bestErr = it.err;
      cone.Pbest.head(m) = it.P.head(m);
    }
  }
  // Failed: the best answer it found if better than the one it started from.
  it.P.head(m) = bestErr < errBefore ? cone.Pbest.head(m) : cone.Pkeep.head(m);
  restartIterate(pr, it);
  return false;
}

}  // namespace nscd
