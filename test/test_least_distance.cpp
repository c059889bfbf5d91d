// The least-distance solver behind the projection's fallback, against answers
// known in closed form and the optimality conditions of random problems.
#include <gtest/gtest.h>

#include <random>

#include "../src/engine/geometry/least_distance.hpp"

using nscd::leastDistance;
using nscd::nonNegativeLeastSquares;

TEST(LeastDistance, ClosedFormAnswers) {
  Eigen::VectorXd y;
  // One half-plane y1 + y2 >= 2: the foot of the perpendicular, (1, 1).
  Eigen::MatrixXd A(1, 2);
  A << 1, 1;
  ASSERT_TRUE(leastDistance(A, Eigen::VectorXd::Constant(1, 2.0), y));
  EXPECT_NEAR(y(0), 1, 1e-14);
  EXPECT_NEAR(y(1), 1, 1e-14);
  // A corner (y1 >= 1, y2 >= 2) and a redundant constraint y1 + y2 >= 1.
  Eigen::MatrixXd B(3, 2);
  B << 1, 0, 0, 1, 1, 1;
  Eigen::VectorXd c(3);
  c << 1, 2, 1;
  ASSERT_TRUE(leastDistance(B, c, y));
  EXPECT_NEAR(y(0), 1, 1e-14);
  EXPECT_NEAR(y(1), 2, 1e-14);
  // Already feasible at the origin: y = 0.
  c << -1, -2, -3;
  ASSERT_TRUE(leastDistance(B, c, y));
  EXPECT_EQ(y.norm(), 0.0);
  // An equality as two inequalities: y1 = 3.
  Eigen::MatrixXd C(2, 2);
  C << 1, 0, -1, 0;
  Eigen::VectorXd d(2);
  d << 3, -3;
  ASSERT_TRUE(leastDistance(C, d, y));
  EXPECT_NEAR(y(0), 3, 1e-13);
  EXPECT_NEAR(y(1), 0, 1e-13);
  // Infeasible: y1 >= 1 and -y1 >= 0.
  d << 1, 0;
  EXPECT_FALSE(leastDistance(C, d, y));
}

TEST(LeastDistance, NonNegativeLeastSquaresKnownAnswer) {
  // min |E x - f|, x >= 0, with the unconstrained minimiser (2, -1): the answer
  // keeps x2 = 0 and fits x1 alone, x1 = (e1.f)/(e1.e1) = 1.5.
  Eigen::MatrixXd E(2, 2);
  E << 1, 0, 1, 1;
  Eigen::VectorXd f(2), x;
  f << 2, 1;
  ASSERT_TRUE(nonNegativeLeastSquares(E, f, x));
  EXPECT_NEAR(x(0), 1.5, 1e-14);
  EXPECT_EQ(x(1), 0.0);
}

// Random problems shaped like the projection's: many rows (duplicated, so the
// dual is degenerate) on few unknowns, scales 1e3 apart. The answer must be
// feasible and optimal: y in the cone of the active rows' normals.
TEST(LeastDistance, RandomProblemsMeetTheOptimalityConditions) {
  std::mt19937 rng(7);
  std::normal_distribution<double> N(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 3 + trial % 10, base = 2 + trial % 7, rows = 3 * base;
    Eigen::MatrixXd A(rows, n);
    Eigen::VectorXd c(rows), y0(n);
    for (int j = 0; j < n; ++j) y0(j) = N(rng);  // a feasible point
    for (int i = 0; i < base; ++i) {
      for (int j = 0; j < n; ++j) A(i, j) = N(rng) * (j % 2 ? 1e3 : 1.0);
      c(i) = A.row(i).dot(y0) - std::abs(N(rng));
    }
    for (int i = base; i < rows; ++i) {  // near-copies of the first rows
      A.row(i) = A.row(i % base) * (1 + 1e-9 * N(rng));
      c(i) = c(i % base) - std::abs(N(rng)) * 1e-3;
    }
    Eigen::VectorXd y;
    if (!leastDistance(A, c, y)) {
      ADD_FAILURE() << "trial " << trial << ": reported infeasible (y0 is feasible)";
      continue;
    }
    const Eigen::VectorXd slack = A * y - c;
    const double scale = 1 + A.cwiseAbs().maxCoeff() * y.norm();
    EXPECT_GE(slack.minCoeff(), -1e-9 * scale) << "trial " << trial;
    // Optimality: y = A_act^T u, u >= 0, over the active rows.
    std::vector<int> act;
    for (int i = 0; i < rows; ++i)
      if (slack(i) <= 1e-7 * scale) act.push_back(i);
    Eigen::MatrixXd At(n, static_cast<int>(act.size()));
    for (size_t k = 0; k < act.size(); ++k) At.col(static_cast<int>(k)) = A.row(act[k]).transpose();
    Eigen::VectorXd u;
    ASSERT_TRUE(nonNegativeLeastSquares(At, y, u));
    EXPECT_LE((At * u - y).norm(), 1e-7 * (1 + y.norm())) << "trial " << trial;
  }
}
