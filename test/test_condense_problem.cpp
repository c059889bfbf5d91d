// The FCLib condenser (tools/fclib/condense_problem.cpp, nscd_fclib --from-nscd): an
// nscd problem's bilateral rows condensed out by the Schur complement, a frictionless
// contact made a 3-row contact with mu = 0; a problem it cannot take refused with a
// reason, never read outside W (the fclib_from_nscd fuzz target's finding: a
// frictional block of 2 rows at the last rows made it read row 15 of a 15-row W).
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "condense_problem.hpp"

using nscd::BlockKind;
using nscd::ProblemBlock;

namespace {

ProblemBlock block(BlockKind kind, int row, int size, double mu = 0) {
  ProblemBlock b;
  b.kind = kind;
  b.row = row;
  b.size = size;
  b.mu = mu;
  return b;
}

// A symmetric positive definite W of m rows with every entry nonzero, b = 1 .. m.
nscd::ProblemFile problem(int m, std::vector<ProblemBlock> blocks) {
  nscd::ProblemFile p;
  Eigen::MatrixXd A(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) A(i, j) = 1.0 / (1 + i + 2 * j) + (i == j ? 1.0 : 0.0);
  p.W = A * A.transpose();
  p.b = Eigen::VectorXd::LinSpaced(m, 1, m);
  p.P_start = p.P = Eigen::VectorXd::Zero(m);
  p.blocks = std::move(blocks);
  return p;
}

}  // namespace

// A frictional contact (rows 0-2), a bilateral pair (3-4) and a frictionless contact
// (5): the local problem is W_cc - W_ce W_ee^-1 W_ec over rows 0, 1, 2, 5 (and two
// inert tangent rows of identity), q likewise, to round-off.
TEST(CondenseProblem, BilateralRowsCondensedOutAndFrictionlessPadded) {
  const nscd::ProblemFile p = problem(6, {block(BlockKind::Frictional, 0, 3, 0.3),
                                          block(BlockKind::Bilateral, 3, 2),
                                          block(BlockKind::Frictionless, 5, 1)});
  nscd_fclib::CondensedProblem c;
  std::string why;
  ASSERT_TRUE(nscd_fclib::condenseProblem(p, c, why)) << why;
  EXPECT_EQ(c.bilateral_rows, 2);
  ASSERT_EQ(c.mu, (std::vector<double>{0.3, 0.0}));
  ASSERT_EQ(c.W.rows(), 6);
  ASSERT_EQ(c.q.size(), 6);
  const std::vector<int> rows = {0, 1, 2, 5};  // local 0, 1, 2, 3
  const std::vector<int> eq = {3, 4};
  Eigen::MatrixXd Wcc(4, 4), Wce(4, 2), Wee(2, 2);
  Eigen::VectorXd qc(4), qe(2);
  for (int a = 0; a < 4; ++a) {
    qc(a) = p.b(rows[a]);
    for (int c2 = 0; c2 < 4; ++c2) Wcc(a, c2) = p.W(rows[a], rows[c2]);
    for (int e = 0; e < 2; ++e) Wce(a, e) = p.W(rows[a], eq[e]);
  }
  for (int e = 0; e < 2; ++e) {
    qe(e) = p.b(eq[e]);
    for (int f = 0; f < 2; ++f) Wee(e, f) = p.W(eq[e], eq[f]);
  }
  const Eigen::MatrixXd S = Wcc - Wce * Wee.inverse() * Wce.transpose();
  const Eigen::VectorXd s = qc - Wce * Wee.inverse() * qe;
  const double scale = p.W.cwiseAbs().maxCoeff();
  for (int a = 0; a < 4; ++a) {
    EXPECT_NEAR(c.q(a), s(a), 1e-12 * scale) << a;
    for (int c2 = 0; c2 < 4; ++c2) EXPECT_NEAR(c.W(a, c2), S(a, c2), 1e-12 * scale) << a << " " << c2;
  }
  // The frictionless contact's inert tangents (local rows 4, 5): U_T = P_T, apart from the rest.
  for (int t = 4; t < 6; ++t) {
    EXPECT_EQ(c.q(t), 0.0);
    for (int k = 0; k < 6; ++k) EXPECT_EQ(c.W(t, k), t == k ? 1.0 : 0.0) << t << " " << k;
  }
}

// Blocks whose size is not their kind's are refused with a reason naming the block,
// before any row of W is read; a problem of bilateral rows alone, with its reason.
TEST(CondenseProblem, BlocksOfTheWrongSizeAndNoContactAreRefusedWithAReason) {
  struct Case {
    std::vector<ProblemBlock> blocks;
    const char* reason;
  };
  const std::vector<Case> cases = {
      {{block(BlockKind::Frictional, 0, 3, 1), block(BlockKind::Frictional, 4, 2, 1)},
       "a frictional block of 2 rows at row 4 (3 expected)"},
      {{block(BlockKind::Frictionless, 0, 3)}, "a frictionless block of 3 rows at row 0 (1 expected)"},
      {{block(BlockKind::Bilateral, 0, 6)}, "no contact (bilateral rows only): not an FCLib problem"}};
  for (const Case& k : cases) {
    nscd_fclib::CondensedProblem c;
    std::string why;
    EXPECT_FALSE(nscd_fclib::condenseProblem(problem(6, k.blocks), c, why)) << k.reason;
    EXPECT_EQ(why, k.reason);
  }
}
