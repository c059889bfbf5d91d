// The equality-only solve (SolverStage::Equalities, docs/solver.md): its LDLᵀ
// kernels, the solve of bilateral problems with full rank, redundant rows (a
// four-bar closed in 3D), nearly dependent rows, rows of very different scales
// and inconsistent right-hand sides; the factor applied again
// (solveEqualitiesAgain); and in the step, the projection's first pass on the
// velocity stage's factor and the rows kept for the next step.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "nscd_sim/friction_contact_solver.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "solver/dense_kernels.hpp"
#include "solver/row_count_dispatch.hpp"
#include "step/step_stages.hpp"
#include "test_support.hpp"

using namespace nscd;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

// W = G M^-1 G^T of m random rows on ndof DOF (M^-1 diagonal, positive), and
// b = G v (consistent) for a random v.
void randomMechanism(std::mt19937& rng, int m, int ndof, MatrixXd& W, VectorXd& b, MatrixXd* Gout = nullptr) {
  std::normal_distribution<double> g(0, 1);
  std::uniform_real_distribution<double> u(0.5, 2);
  MatrixXd G(m, ndof);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < ndof; ++j) G(i, j) = g(rng);
  VectorXd minv(ndof), v(ndof);
  for (int j = 0; j < ndof; ++j) {
    minv(j) = u(rng);
    v(j) = g(rng);
  }
  W = G * minv.asDiagonal() * G.transpose();
  b = G * v;
  if (Gout) *Gout = G;
}

// W = G G^T (unit masses) of rows G edited after randomMechanism, and b = G v
// (consistent) for a new random v.
void problemOfRows(std::mt19937& rng, const MatrixXd& G, MatrixXd& W, VectorXd& b) {
  W = G * G.transpose();
  std::normal_distribution<double> g(0, 1);
  VectorXd v(G.cols());
  for (int i = 0; i < G.cols(); ++i) v(i) = g(rng);
  b = G * v;
}

std::vector<ProblemBlock> bilateralBlocks(int m, int size) {
  std::vector<ProblemBlock> blocks;
  for (int r = 0; r < m; r += size) blocks.push_back({BlockKind::Bilateral, r, std::min(size, m - r), 0});
  return blocks;
}

int zeros(const VectorXd& P) {
  int n = 0;
  for (int i = 0; i < P.size(); ++i) n += P(i) == 0.0;
  return n;
}

// L D L^T (unit lower L below the diagonal of F, D on it) of an n x n factor.
MatrixXd reconstruct(const MatrixXd& F) {
  const int n = int(F.rows());
  MatrixXd L = MatrixXd::Identity(n, n);
  VectorXd d(n);
  for (int j = 0; j < n; ++j) {
    d(j) = F(j, j);
    for (int i = j + 1; i < n; ++i) L(i, j) = F(i, j);
  }
  return L * d.asDiagonal() * L.transpose();
}

// A workspace and state of a scene, assembled as the simulator assembles it.
struct StepHarness {
  Model m;
  StepWorkspace ws;
  StepOutputs out;
  State s;
  explicit StepHarness(const std::string& scene) : m(loadScene(nscd_test::scenePath(scene))) {
    initStepWorkspace(m, ws);
    initStepOutputs(m, out);
    s = initialState(m, ws);
    placeJournals(m, s);
    assembleState(m, s, ws);
  }
  // W = G M^-1 G^T of the ideal joints' rows at the state (rows in ws).
  MatrixXd jointOperator() {
    clearConstraintRows(ws);
    appendBilateralRows(m, s, ws.zero_rates, ws);
    assembleDelassus(ws.mass_inverse, true, ws, 0, ws.rows);
    return ws.W.topLeftCorner(ws.rows, ws.rows);
  }
  // The velocity stage of a step of length h, as Simulator::advance runs it.
  SolverReport velocityStage(double h) {
    clearStepOutputs(out);
    clearConstraintRows(ws);
    computeForces(m, s, ws, out, ws.facts.stiff);
    stateVelocities(s, ws.vk);
    buildIterationMatrix(m, h, ws, out.stats);
    computeFreeVelocity(m, h, ws);
    appendBilateralRows(m, s, ws.rates, ws);
    assembleDelassus(ws.iteration_inverse, !ws.facts.stiff, ws, 0, ws.rows);
    buildFrictionContactProblem(m, s, h, 0, ws, out.stats);
    const SolverReport rep = solveWithRescues(m, ws, solverOptions(m.settings), false, ResolveObserver{}, out.stats);
    storeImpulses(m, h, s, ws, out);
    return rep;
  }
};

}  // namespace

// The kernel: Pi^T A Pi = L D L^T; a rank-deficient A (rank 8 of 12) stops at
// rank 8 and gives the basic solution of a consistent system (4 zeros);
// nearly dependent rows (1e-7 apart: pivot 1e-14 of the diagonal) are kept
// above the threshold and dropped below it.
TEST(LdltKernel, FactorsSolvesAndDropsDependentRows) {
  std::mt19937 rng(5);
  for (int rank : {12, 8}) {
    MatrixXd A, G;
    VectorXd rhs;
    randomMechanism(rng, 12, rank, A, rhs, &G);
    std::vector<int> perm(12), scratch(12);
    MatrixXd F = A;
    EXPECT_EQ(pivotedLdlt(F.data(), 12, 12, 1e-13 * A.diagonal().maxCoeff(), perm.data(), scratch.data()), rank);
    MatrixXd Ap(12, 12);
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < 12; ++j) Ap(i, j) = A(perm[i], perm[j]);
    EXPECT_LT((reconstruct(F) - Ap).cwiseAbs().maxCoeff(), 1e-10 * A.cwiseAbs().maxCoeff()) << "rank " << rank;
    VectorXd x = rhs, tmp(12);
    ldltSolve(F.data(), 12, 12, perm.data(), x.data(), tmp.data());
    EXPECT_LT((A * x - rhs).norm(), 1e-10 * rhs.norm()) << "rank " << rank;
    EXPECT_EQ(zeros(x), 12 - rank);
  }
  MatrixXd A, G;
  VectorXd rhs;
  randomMechanism(rng, 6, 10, A, rhs, &G);
  G.row(3) = G.row(1);
  G(3, 0) += 1e-7 * G.row(1).norm();
  A = G * G.transpose();
  std::vector<int> perm(6), scratch(6);
  MatrixXd F = A;
  EXPECT_EQ(pivotedLdlt(F.data(), 6, 6, 1e-16 * A.diagonal().maxCoeff(), perm.data(), scratch.data()), 6);
  F = A;
  EXPECT_EQ(pivotedLdlt(F.data(), 6, 6, 1e-12 * A.diagonal().maxCoeff(), perm.data(), scratch.data()), 5);
}

// withRowCount: the kernel instance of a listed count, the generic one (0) for
// any other, called once either way; a void kernel alike.
TEST(RowCountDispatch, ListedCountsAndTheRest) {
  for (int n = 0; n <= 24; ++n) {
    const bool listed = n == 5 || n == 6 || n == 10 || n == 11 || n == 12 || n == 15 || n == 20;
    EXPECT_EQ(withRowCount(JointRowCounts{}, n, [](auto count) { return decltype(count)::value; }), listed ? n : 0)
        << n;
    int calls = 0, seen = -1;
    withRowCount(RowCounts<5, 6, 10, 11, 12>{}, n, [&](auto count) {
      ++calls;
      seen = decltype(count)::value;
    });
    EXPECT_EQ(calls, 1) << n;
    EXPECT_EQ(seen, listed && n <= 12 ? n : 0) << n;
  }
}

// Every size, listed or not, through the factor, the in-order solve and the
// scaled solve: A x = rhs to 1e-12 relative (A = G G^T + I, well conditioned).
TEST(LdltKernel, EverySizeFactorsAndSolves) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int n = 1; n <= 22; ++n) {
    MatrixXd G(n, n + 2);
    for (int i = 0; i < G.size(); ++i) G.data()[i] = u(rng);
    const MatrixXd A = G * G.transpose() + MatrixXd::Identity(n, n);
    VectorXd rhs(n);
    for (int i = 0; i < n; ++i) rhs[i] = u(rng);
    std::vector<int> perm(2 * n);
    MatrixXd F = A;
    ASSERT_EQ(pivotedLdlt(F.data(), n, n, 1e-13, perm.data(), perm.data() + n), n) << n;
    VectorXd x = rhs, tmp(n);
    ldltSolve(F.data(), n, n, perm.data(), x.data(), tmp.data());
    EXPECT_LT((A * x - rhs).norm(), 1e-12 * rhs.norm()) << n;
    // The scaled solve: every row kept, unit scales, P = -A^-1 rhs.
    std::vector<int> rows(n);
    for (int i = 0; i < n; ++i) rows[i] = i;
    const VectorXd s = VectorXd::Ones(n);
    MatrixXd L(n, n);
    factorScaledRows(A.data(), n, n, rows.data(), n, s.data(), L.data(), n, 1e-13, perm.data());
    VectorXd P(n), scratch(2 * n);
    solveScaledRows(L.data(), n, n, perm.data(), rows.data(), s.data(), n, rhs.data(), scratch.data(), P.data());
    EXPECT_LT((A * P + rhs).norm(), 1e-12 * rhs.norm()) << n;
  }
}

// Threshold pivoting: a pivot in order is kept while its diagonal is at least a
// quarter of the largest (a diagonally dominant A keeps its order); where the
// diagonals fall below that, the largest is swapped in, and on a unit diagonal
// every |L_ik| stays <= 2 (= 1 / sqrt(1/4)).
TEST(LdltKernel, ThresholdPivotingKeepsTheOrderAndBoundsL) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  MatrixXd A = MatrixXd::Identity(10, 10);
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < i; ++j) A(i, j) = A(j, i) = u(rng);
  std::vector<int> perm(10), scratch(10);
  MatrixXd F = A;
  EXPECT_EQ(pivotedLdlt(F.data(), 10, 10, 1e-13, perm.data(), scratch.data()), 10);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(perm[i], i);
  EXPECT_LT((reconstruct(F) - A).cwiseAbs().maxCoeff(), 1e-14);
  int swapped = 0;
  for (int trial = 0; trial < 20; ++trial) {
    MatrixXd W, G;
    VectorXd rhs;
    randomMechanism(rng, 12, 14, W, rhs, &G);  // rows nearly dependent in pairs: small Schur diagonals
    const VectorXd s = W.diagonal().cwiseSqrt().cwiseInverse();
    W = s.asDiagonal() * W * s.asDiagonal();
    F = W;
    perm.assign(12, 0);
    scratch.assign(12, 0);
    ASSERT_EQ(pivotedLdlt(F.data(), 12, 12, 1e-13, perm.data(), scratch.data()), 12);
    for (int i = 0; i < 12; ++i) swapped += perm[i] != i;
    MatrixXd Wp(12, 12);
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < 12; ++j) Wp(i, j) = W(perm[i], perm[j]);
    EXPECT_LT((reconstruct(F) - Wp).cwiseAbs().maxCoeff(), 1e-10);
    EXPECT_LE(F.triangularView<Eigen::StrictlyLower>().toDenseMatrix().cwiseAbs().maxCoeff(), 2 + 1e-12);
  }
  EXPECT_GT(swapped, 0);  // the search did run
}

// Full rank, rows in blocks of 1 to 6: the direct solve meets the tolerance
// in one solve with the factor, and is the exact answer -W^-1 b.
TEST(EqualitySolve, FullRankExactInOneSolve) {
  std::mt19937 rng(7);
  FrictionContactSolver solver;
  for (int size = 1; size <= 6; ++size) {
    const int m = 4 * size;
    MatrixXd W;
    VectorXd b;
    randomMechanism(rng, m, m + 6, W, b);
    VectorXd P = VectorXd::Constant(m, 3.0);  // a warm start it does not need
    SolverOptions o;
    o.tolerance = 1e-12;
    const SolverReport r = solver.solve(W, b, bilateralBlocks(m, size), o, P);
    EXPECT_EQ(r.stage, SolverStage::Equalities) << solverStageName(r.stage);
    EXPECT_TRUE(r.converged);
    EXPECT_EQ(r.iteration_sum, 1);
    const VectorXd exact = -W.ldlt().solve(b);
    EXPECT_LT((P - exact).norm(), 1e-10 * exact.norm()) << "blocks of " << size;
    EXPECT_LT((W * P + b).norm(), 1e-12 * b.norm());
    EXPECT_LE(r.residual, 1e-12);
  }
}

// The four-bar of urdf/fourbar.urdf closed in 3D: 20 joint rows on 18 DOF,
// rank 17 (the out-of-plane rows of the loop repeat the others'). For any
// consistent b the direct solve leaves 3 rows out (P = 0 there) and meets
// U = 0 to round-off, with the joints in either order.
TEST(EqualitySolve, RedundantLoopRowsOfAFourBar) {
  StepHarness t("urdf/fourbar.urdf");
  const MatrixXd W = t.jointOperator();
  ASSERT_EQ(W.rows(), 20);
  const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(W);
  int null = 0;
  for (int i = 0; i < 20; ++i) null += eig.eigenvalues()(i) < 1e-12 * eig.eigenvalues().maxCoeff();
  ASSERT_EQ(null, 3);
  const MatrixXd G = t.ws.G.topRows(20);
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  FrictionContactSolver solver;
  for (int k = 0; k < 20; ++k) {
    VectorXd v(t.ws.n);
    for (int i = 0; i < t.ws.n; ++i) v(i) = g(rng);
    const VectorXd b = G * t.ws.mass_inverse * v;  // consistent: in the range of G
    // The blocks as the joints come, or the loop joint's first.
    std::vector<ProblemBlock> blocks = bilateralBlocks(20, 5);
    if (k % 2) std::swap(blocks[0], blocks[3]);
    VectorXd P = VectorXd::Zero(20);
    SolverOptions o;
    o.tolerance = 1e-12;
    const SolverReport r = solver.solve(W, b, blocks, o, P);
    EXPECT_EQ(r.stage, SolverStage::Equalities) << solverStageName(r.stage);
    EXPECT_TRUE(r.converged) << r.residual;
    EXPECT_LT((W * P + b).norm(), 1e-12 * b.norm()) << k;
    EXPECT_EQ(zeros(P), 3) << k;
  }
}

// Two rows 1e-6 apart in angle (a mechanism next to a singular
// configuration, W's condition 1e12): leaving one out would leave a residual
// of that order; the direct solve keeps it, and its answer (impulses 1e6 times
// the others along the near-dependent pair) has a round-off floor of about
// 1e-9 in U; the general schedule goes on from there and meets 1e-10. An
// inconsistent system (b off the range of W) cannot be solved: reported
// unsolved, finite.
TEST(EqualitySolve, NearlyDependentAndInconsistentRows) {
  std::mt19937 rng(9);
  MatrixXd W, G;
  VectorXd b;
  randomMechanism(rng, 8, 12, W, b, &G);
  G.row(5) = G.row(2);
  G(5, 4) += 1e-6 * G.row(2).norm();  // pivot about 1e-12 of the row's diagonal
  problemOfRows(rng, G, W, b);
  FrictionContactSolver solver;
  VectorXd P = VectorXd::Zero(8);
  SolverOptions o;
  o.tolerance = 1e-10;
  SolverReport r = solver.solve(W, b, bilateralBlocks(8, 4), o, P);
  EXPECT_TRUE(r.converged) << solverStageName(r.stage) << " " << r.residual;
  EXPECT_LE(r.residual, 1e-10);
  EXPECT_LT((W * P + b).norm(), 1e-9 * b.norm());
  EXPECT_TRUE(P.allFinite());

  MatrixXd Wr;
  VectorXd br;
  randomMechanism(rng, 8, 5, Wr, br);  // rank 5
  const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(Wr);
  const VectorXd off_range = eig.eigenvectors().col(0);  // the smallest eigenvalue's: 0
  const VectorXd bad = br + off_range;
  P.setZero();
  r = solver.solve(Wr, bad, bilateralBlocks(8, 4), o, P);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.stage, SolverStage::Unsolved) << solverStageName(r.stage);
  EXPECT_TRUE(P.allFinite());
  EXPECT_TRUE(std::isfinite(r.residual));
}

// Rows whose scales differ by 1e9 in W's diagonal (a light link's rotation
// rows beside a heavy body's translation rows): the unit-diagonal scaling
// keeps the solve exact to round-off relative to each row.
TEST(EqualitySolve, RowScalesNineDecadesApart) {
  std::mt19937 rng(13);
  MatrixXd W, G;
  VectorXd b;
  randomMechanism(rng, 10, 14, W, b, &G);
  for (int i = 0; i < 10; i += 2) G.row(i) *= 3e4;  // W_ii up to 1e9 times the others
  problemOfRows(rng, G, W, b);
  FrictionContactSolver solver;
  VectorXd P = VectorXd::Zero(10);
  SolverOptions o;
  o.tolerance = 1e-12;
  const SolverReport r = solver.solve(W, b, bilateralBlocks(10, 5), o, P);
  EXPECT_EQ(r.stage, SolverStage::Equalities) << solverStageName(r.stage);
  EXPECT_TRUE(r.converged) << r.residual;
  const VectorXd U = W * P + b;
  for (int i = 0; i < 10; ++i) EXPECT_LT(std::abs(U(i)), 1e-12 * std::abs(b(i)) + 1e-14 * b.norm()) << i;
}

// The factor applied again: the same bits as a fresh solve of the same W; no
// factor after a problem that was not equality-only, or for another size. With
// the stage skipped the general schedule solves it (zero rows kept at 0).
TEST(EqualitySolve, FactorAppliedAgainAndStageSkipped) {
  std::mt19937 rng(17);
  MatrixXd W, G;
  VectorXd b1;
  randomMechanism(rng, 10, 14, W, b1, &G);
  VectorXd b2 = G * VectorXd::LinSpaced(14, -1, 2);
  W.row(4).setZero();  // a zero row (an out-of-plane row in a planar scene)
  W.col(4).setZero();
  b1(4) = b2(4) = 0;
  const std::vector<ProblemBlock> blocks = bilateralBlocks(10, 5);
  FrictionContactSolver solver, fresh;
  VectorXd P1 = VectorXd::Zero(10), P2 = VectorXd::Zero(10), again(10);
  SolverOptions o;
  ASSERT_EQ(solver.solve(W, b1, blocks, o, P1).stage, SolverStage::Equalities);
  ASSERT_TRUE(solver.solveEqualitiesAgain(b2, again));
  ASSERT_EQ(fresh.solve(W, b2, blocks, o, P2).stage, SolverStage::Equalities);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(again(i), P2(i)) << i;
  EXPECT_EQ(again(4), 0.0);
  VectorXd wrong(9);
  EXPECT_FALSE(solver.solveEqualitiesAgain(b2, wrong));

  std::vector<ProblemBlock> mixed = blocks;
  mixed.back() = {BlockKind::Frictionless, 9, 1, 0};
  VectorXd Pm = VectorXd::Zero(10);
  solver.solve(W, b1, mixed, o, Pm);
  EXPECT_FALSE(solver.solveEqualitiesAgain(b2, again));

  SolverOptions skip = o;
  skip.skip_stages = 1u << static_cast<int>(SolverStage::Equalities);
  VectorXd Ps = VectorXd::Zero(10);
  const SolverReport r = solver.solve(W, b2, blocks, skip, Ps);
  EXPECT_NE(r.stage, SolverStage::Equalities);
  EXPECT_TRUE(r.converged) << solverStageName(r.stage);
  EXPECT_LT((Ps - P2).norm(), 1e-6 * P2.norm());
  EXPECT_EQ(Ps(4), 0.0);
}

// In a step of the four-bar: the velocity stage's problem is equality-only,
// its factor may serve the projection (the bodies turn by h |w| << 0.02 rad),
// and the first pass takes it. The positions it leaves meet the tolerance
// and are those of the projection with its own operator at q_{k+1} to within
// 1e-12 m (both project onto the same constraint manifold, along directions
// that differ by the rows' turn in the step); the rows it leaves are a memo
// of its poses, bit for bit a fresh gather's there.
TEST(EqualityPath, ProjectionFirstPassTakesTheVelocityFactor) {
  StepHarness t("urdf/fourbar.urdf");
  const double h = 1e-3;  // drift h^2: passes needed
  const double tol = t.m.settings.projection_tolerance;
  for (int step = 0; step < 5; ++step) {
    const SolverReport rep = t.velocityStage(h);
    ASSERT_EQ(rep.stage, SolverStage::Equalities);
    ASSERT_TRUE(velocityFactorReusable(h, t.ws));
    advanceState(t.m, h, t.ws, t.s);
    State own = t.s;
    StepWorkspace own_ws;
    initStepWorkspace(t.m, own_ws);
    double violation = 0, own_violation = 0;
    StepStats st;
    const int passes = projectPositions(t.m, t.s, t.ws, 20, tol, violation, st, true);
    ASSERT_GE(passes, 1);
    if (passes == 1) EXPECT_TRUE(t.ws.projection_reused_factor);
    projectPositions(t.m, own, own_ws, 20, tol, own_violation, st, false);
    EXPECT_FALSE(own_ws.projection_reused_factor);
    EXPECT_LE(violation, tol);
    EXPECT_LE(own_violation, tol);
    for (size_t b = 0; b < t.s.bodies.size(); ++b) EXPECT_LT((t.s.bodies[b].x - own.bodies[b].x).norm(), 1e-12) << b;
    // The rows kept: those of a fresh gather at these poses, bit for bit.
    ASSERT_TRUE(rowsMatchPoses(t.s, t.ws));
    StepWorkspace fresh;
    initStepWorkspace(t.m, fresh);
    appendBilateralRows(t.m, t.s, fresh.zero_rates, fresh);
    ASSERT_EQ(fresh.rows, t.ws.rows);
    for (int i = 0; i < fresh.rows; ++i)
      for (int j = 0; j < fresh.n; ++j) ASSERT_EQ(fresh.G(i, j), t.ws.G(i, j)) << i << " " << j;
    for (size_t k = 0; k < fresh.blocks.size(); ++k)
      for (int r = 0; r < fresh.blocks[k].size; ++r) ASSERT_EQ(fresh.blocks[k].error[r], t.ws.blocks[k].error[r]);
    trackJointPositions(t.m, t.s);
  }
  // Moved by anything else, the memo no longer matches.
  t.s.bodies[1].x.x() += 1e-15;
  EXPECT_FALSE(rowsMatchPoses(t.s, t.ws));
}

// The rows a step keeps are a full gather's, however they were gathered: a
// gather of the errors alone completed (completeBilateralRows, the projection's
// check that needs no pass), or a gather after a clear that left a revolute
// joint's rows in G (clearStaleJointRows), G and the blocks against a fresh
// workspace's full gather bit for bit (memcmp), on revolute, prismatic and
// same-body joints.
TEST(EqualityPath, CompletedAndStaleGathersAreAFullGathers) {
  for (const char* scene : {"urdf/pendulum.urdf", "test/scenes/double_pendulum.urdf", "urdf/fourbar.urdf",
                            "urdf/slider_crank.urdf", "urdf/c60_ideal.urdf"}) {
    StepHarness t(scene);
    for (int step = 0; step < 3; ++step) {
      t.velocityStage(1e-3);  // rows in G at the step's start
      advanceState(t.m, 1e-3, t.ws, t.s);
      trackJointPositions(t.m, t.s);
      StepWorkspace fresh;
      initStepWorkspace(t.m, fresh);
      appendBilateralRows(t.m, t.s, fresh.zero_rates, fresh);
      const auto same = [&](const StepWorkspace& ws, const char* how) {
        ASSERT_EQ(fresh.rows, ws.rows) << scene << how;
        ASSERT_EQ(fresh.blocks.size(), ws.blocks.size()) << scene << how;
        for (int j = 0; j < fresh.n; ++j)
          for (int i = 0; i < fresh.G.rows(); ++i)
            ASSERT_EQ(std::memcmp(&fresh.G(i, j), &ws.G(i, j), sizeof(double)), 0) << scene << how << " G " << i << " " << j;
        for (size_t k = 0; k < fresh.blocks.size(); ++k) {
          const ConstraintBlock &a = fresh.blocks[k], &b = ws.blocks[k];
          ASSERT_EQ(a.row, b.row);
          ASSERT_EQ(a.size, b.size);
          ASSERT_EQ(a.linear_known, b.linear_known) << scene << how;
          for (int r = 0; r < a.size; ++r) {
            ASSERT_EQ(std::memcmp(&a.error[r], &b.error[r], sizeof(double)), 0) << scene << how;
            if (a.linear_known) ASSERT_EQ(a.linear_axis[r], b.linear_axis[r]) << scene << how;
          }
        }
      };
      // The errors alone, then completed (the rows of the velocity stage, at the
      // step's start, still in G where a clear left them).
      clearConstraintRows(t.ws);
      appendBilateralRows(t.m, t.s, t.ws.zero_rates, t.ws, false);
      completeBilateralRows(t.m, t.s, t.ws);
      same(t.ws, " completed");
      // A full gather after a clear (the rows just gathered left in G).
      clearConstraintRows(t.ws);
      appendBilateralRows(t.m, t.s, t.ws.zero_rates, t.ws);
      same(t.ws, " after a clear");
    }
  }
}

// A scene with stiff elements (Ŵ is not M^-1) or a contact never reuses.
TEST(EqualityPath, NoReuseWithStiffElementsOrContacts) {
  StepHarness spring("urdf/spring_mass.urdf");
  spring.velocityStage(1e-4);
  EXPECT_FALSE(velocityFactorReusable(1e-4, spring.ws));
  StepHarness journal("urdf/journal.urdf");
  EXPECT_FALSE(journal.ws.facts.rows_follow_poses);
}

// The simulator on the double pendulum and the four-bar at dt 1e-4: every
// velocity problem goes to the equality stage (the step's direct path), the loop stays closed (1e-9 m),
// no energy is gained (the projection's energy is taken back), and no step
// allocates once warm.
TEST(EqualityPath, JointsOnlyScenesStepWithTheEqualityStage) {
  for (const char* scene : {"test/scenes/double_pendulum.urdf", "urdf/fourbar.urdf"}) {
    Simulator sim(loadScene(nscd_test::scenePath(scene)));
    const double E0 = sim.energy().total();
    long equalities = 0, solves = 0, direct = 0;
    double worst = 0, gain = -INFINITY;
    long allocations = 0;
    for (int k = 0; k < 5000; ++k) {
      const long before = nscd_test::allocationCount();
      ASSERT_EQ(sim.step(), StepStatus::Ok) << scene << " step " << k;
      if (k >= 10) allocations += nscd_test::allocationCount() - before;
      const StepStats& st = sim.stats();
      equalities += st.solves_by_stage[static_cast<int>(SolverStage::Equalities)];
      for (int s : st.solves_by_stage) solves += s;
      direct += st.direct_equality_solves;
      if (k % 50 == 0) {
        worst = std::max(worst, sim.constraintViolation());
        gain = std::max(gain, sim.energy().total() - E0);
      }
    }
    std::printf("[ figures  ] %s: %ld of %ld solves by the equality stage, loop violation max %.2e m, "
                "energy gain max %.2e J\n", scene, equalities, solves, worst, gain);
    EXPECT_EQ(equalities, solves) << scene;
    EXPECT_EQ(solves, 5000) << scene;
    EXPECT_EQ(direct, 5000) << scene;  // every one by the step's direct path
    EXPECT_LT(worst, 1e-9) << scene;
    EXPECT_LT(gain, 1e-9) << scene;
    EXPECT_EQ(allocations, 0) << scene;
  }
}

// The step's own direct solve (equality_step.cpp) against the friction-contact
// solver's equality path, from the same state and rows, on four mechanisms
// (open chains, a closed loop with redundant rows, a slider-crank): the same
// arithmetic, so the impulses, velocities and reports agree bit for bit
// (tolerance 0), over 50 steps of each.
TEST(EqualityPath, DirectStepAnswerIsTheSolversBitForBit) {
  for (const char* scene : {"urdf/pendulum.urdf", "test/scenes/double_pendulum.urdf", "urdf/fourbar.urdf",
                            "urdf/slider_crank.urdf"}) {
    StepHarness t(scene);
    const double h = 1e-3;
    for (int step = 0; step < 50; ++step) {
      // The general path (the harness's velocity stage) ...
      const SolverReport rep = t.velocityStage(h);
      ASSERT_EQ(rep.stage, SolverStage::Equalities) << scene;
      ASSERT_TRUE(rep.converged) << scene;
      const int r = t.ws.rows;
      const VectorXd P_general = t.ws.P.head(r), v_general = t.ws.vnew;
      // ... and the direct one, on the same rows and free velocity.
      t.ws.P.head(r).setConstant(7.0);  // no warm start is read
      StepStats st;
      ASSERT_TRUE(solveEqualityStep(t.m, t.ws, st)) << scene << " step " << step;
      EXPECT_EQ(st.direct_equality_solves, 1);
      EXPECT_EQ(st.solves_by_stage[static_cast<int>(SolverStage::Equalities)], 1);
      EXPECT_EQ(st.iterations, rep.iteration_sum);
      EXPECT_EQ(st.residual, rep.residual);
      EXPECT_TRUE(st.converged);
      EXPECT_EQ(t.ws.equality.factor_rows, r);
      for (int i = 0; i < r; ++i) ASSERT_EQ(t.ws.P[i], P_general[i]) << scene << " row " << i;
      for (int j = 0; j < t.ws.n; ++j) ASSERT_EQ(t.ws.vnew[j], v_general[j]) << scene << " dof " << j;
      advanceState(t.m, h, t.ws, t.s);
      trackJointPositions(t.m, t.s);
    }
  }
}

// The direct step's operator (assembleEqualityDelassus: W's lower triangle
// from the pairs of blocks that share a body, and Y) against assembleDelassus's
// dense assembly of M^-1's W, on the joints-only scenes and the ideal-joint C-60 model's joint rows, at
// their assembled start and after 20 steps: equal bit for bit (tolerance 0;
// memcmp, so a signed zero counts too).
TEST(EqualityPath, EqualityOperatorIsTheDenseAssemblysLowerTriangle) {
  int diagonal = 0, full = 0;  // bodies whose angular M^-1 is diagonal (Y's short sums) and not
  for (const char* scene : {"urdf/pendulum.urdf", "test/scenes/double_pendulum.urdf", "urdf/fourbar.urdf",
                            "urdf/slider_crank.urdf", "urdf/c60_ideal.urdf"}) {
    StepHarness t(scene);
    ASSERT_TRUE(t.ws.mass_inverse_by_body && t.ws.nbodies <= 64) << scene;  // (Ŵ = M^-1: jointOperator's)
    for (const StepWorkspace::BodyMassInverse& bm : t.ws.body_mass_inverse) ++(bm.ang_diagonal ? diagonal : full);
    for (int step = 0; step < 21; ++step) {
      if (step > 0) {
        t.velocityStage(1e-4);
        advanceState(t.m, 1e-4, t.ws, t.s);
        trackJointPositions(t.m, t.s);
      }
      if (step % 20 != 0) continue;
      const MatrixXd W = t.jointOperator();
      const MatrixXd Y = t.ws.Y.leftCols(t.ws.rows);
      const int r = t.ws.rows;
      ASSERT_GT(r, 0) << scene;
      t.ws.W.setConstant(NAN);  // nothing is read from an earlier assembly
      t.ws.Y.setConstant(NAN);
      assembleEqualityDelassus(t.ws, r);
      for (int j = 0; j < r; ++j) {
        for (int i = j; i < r; ++i)
          ASSERT_EQ(std::memcmp(&W(i, j), &t.ws.W(i, j), sizeof(double)), 0) << scene << " W " << i << " " << j;
        for (int k = 0; k < t.ws.n; ++k)
          ASSERT_EQ(std::memcmp(&Y(k, j), &t.ws.Y(k, j), sizeof(double)), 0) << scene << " Y " << k << " " << j;
      }
    }
  }
  EXPECT_GT(diagonal, 0);  // both kinds of body met
  EXPECT_GT(full, 0);
}

// The direct path is the step's for a model of ideal joints alone (counted in
// StepStats::direct_equality_solves), never where contacts can join, and a
// step an observer watches takes the general path (the observer sees its
// problems) to the same state bit for bit.
TEST(EqualityPath, DirectStepTakenAndItsFallbackAgrees) {
  Simulator direct(loadScene(nscd_test::scenePath("urdf/fourbar.urdf")));
  Simulator watched(loadScene(nscd_test::scenePath("urdf/fourbar.urdf")));
  int seen = 0;
  watched.setProblemObserver([&](const ProblemView&) { ++seen; });
  for (int k = 0; k < 300; ++k) {
    ASSERT_EQ(direct.step(), StepStatus::Ok);
    ASSERT_EQ(watched.step(), StepStatus::Ok);
    EXPECT_EQ(direct.stats().direct_equality_solves, 1);
    EXPECT_EQ(watched.stats().direct_equality_solves, 0);
    EXPECT_EQ(direct.stats().iterations, watched.stats().iterations);
    EXPECT_EQ(direct.stats().residual, watched.stats().residual);
  }
  EXPECT_EQ(seen, 300);
  for (size_t b = 0; b < direct.state().bodies.size(); ++b) {
    EXPECT_EQ(direct.state().bodies[b].x, watched.state().bodies[b].x) << b;
    EXPECT_EQ(direct.state().bodies[b].v, watched.state().bodies[b].v) << b;
    EXPECT_EQ(direct.state().bodies[b].w, watched.state().bodies[b].w) << b;
  }
  Simulator journal(loadScene(nscd_test::scenePath("urdf/journal.urdf")));
  for (int k = 0; k < 100; ++k) {
    journal.step();
    EXPECT_EQ(journal.stats().direct_equality_solves, 0);
  }
}
