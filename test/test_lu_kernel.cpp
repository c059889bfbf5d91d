// The LU kernel of the global Newton and the interior-point solver (luFactor,
// dense_kernels.cpp): two pivots a pass over the trailing columns. It must give
// the bits one pivot a pass gives (the factor as it was before, written out here
// as the reference), on the matrices the solvers hand it: dense, with identity
// rows (an open contact's rows in the Newton's Jacobian), with exact and negative
// zeros, with ties for the pivot, with a NaN, singular; and P A = L U.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "solver/dense_kernels.hpp"

namespace {

// One pivot a pass: the first row of the largest magnitude, rows swapped across
// the matrix, the column scaled, the trailing columns updated column by column
// (an update by a zero U entry skipped).
bool referenceLu(double* A, int ld, int n, int* piv) {
  auto a = [&](int i, int j) -> double& { return A[i + std::size_t(j) * ld]; };
  for (int k = 0; k < n; ++k) {
    int p = k;
    double best = std::abs(a(k, k));
    for (int i = k + 1; i < n; ++i) {
      const double v = std::abs(a(i, k));
      if (v > best) {
        best = v;
        p = i;
      }
    }
    if (!(best > 0) || !std::isfinite(best)) return false;
    piv[k] = p;
    if (p != k)
      for (int j = 0; j < n; ++j) std::swap(a(k, j), a(p, j));
    const double inv = 1 / a(k, k);
    for (int i = k + 1; i < n; ++i) a(i, k) *= inv;
    for (int j = k + 1; j < n; ++j) {
      const double akj = a(k, j);
      if (akj == 0) continue;
      for (int i = k + 1; i < n; ++i) a(i, j) -= a(i, k) * akj;
    }
  }
  return true;
}

struct Case {
  int n = 0, ld = 0;
  std::vector<double> A;
};

enum class Kind { Dense, IdentityRows, Sparse, Ties, NegativeZeros };

Case makeCase(std::mt19937& rng, int n, Kind kind) {
  Case c;
  c.n = n;
  c.ld = n + 3;  // a leading dimension larger than n, as the solvers' buffers have
  c.A.assign(std::size_t(c.ld) * n, 7.0);
  std::normal_distribution<double> g(0, 1);
  std::uniform_int_distribution<int> coin(0, 2);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double v = g(rng);
      if (kind == Kind::Sparse && coin(rng) != 0) v = 0;
      if (kind == Kind::Ties) v = double(coin(rng) - 1);  // -1, 0, 1: many equal magnitudes
      if (kind == Kind::NegativeZeros && coin(rng) == 0) v = -0.0;
      c.A[i + std::size_t(j) * c.ld] = v;
    }
  if (kind == Kind::IdentityRows || kind == Kind::Ties)
    for (int i = 0; i < n; i += 3) {  // every third row e_i
      for (int j = 0; j < n; ++j) c.A[i + std::size_t(j) * c.ld] = 0;
      c.A[i + std::size_t(i) * c.ld] = 1;
    }
  if (kind == Kind::Ties)
    for (int i = 0; i < n; ++i) c.A[i + std::size_t(i) * c.ld] += 2 * (i % 2);  // keep it regular more often
  return c;
}

// luFactor against the reference: the same verdict, the same bits of every
// entry (the padding rows untouched) and the same pivots.
void expectSameAsReference(const Case& c, const char* what) {
  std::vector<double> ours = c.A, ref = c.A;
  std::vector<int> piv_ours(c.n, -1), piv_ref(c.n, -1);
  const bool ok_ours = nscd::luFactor(ours.data(), c.ld, c.n, piv_ours.data());
  const bool ok_ref = referenceLu(ref.data(), c.ld, c.n, piv_ref.data());
  ASSERT_EQ(ok_ours, ok_ref) << what << " n " << c.n;
  if (!ok_ref) return;  // a failed factor is left part-way, and the solvers drop it
  EXPECT_EQ(piv_ours, piv_ref) << what << " n " << c.n;
  EXPECT_EQ(0, std::memcmp(ours.data(), ref.data(), ours.size() * sizeof(double))) << what << " n " << c.n;
}

TEST(LuKernel, SameBitsAsOnePivotAPass) {
  std::mt19937 rng(20261128);
  const int sizes[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 12, 15, 16, 33, 60, 61};
  const std::pair<Kind, const char*> kinds[] = {{Kind::Dense, "dense"},
                                                {Kind::IdentityRows, "identity rows"},
                                                {Kind::Sparse, "sparse"},
                                                {Kind::Ties, "ties"},
                                                {Kind::NegativeZeros, "negative zeros"}};
  int factored = 0, failed = 0;
  for (int n : sizes)
    for (const auto& [kind, name] : kinds)
      for (int rep = 0; rep < 4; ++rep) {
        const Case c = makeCase(rng, n, kind);
        expectSameAsReference(c, name);
        std::vector<double> A = c.A;
        std::vector<int> piv(n);
        (nscd::luFactor(A.data(), c.ld, n, piv.data()) ? factored : failed) += 1;
      }
  // Both verdicts were exercised (the sparse and tied matrices are singular now and then).
  EXPECT_GT(factored, 200);
  EXPECT_GT(failed, 0);
}

TEST(LuKernel, NanAndSingularColumns) {
  std::mt19937 rng(7);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int n : {2, 5, 8, 13}) {
    for (int col = 0; col < n; ++col) {
      Case c = makeCase(rng, n, Kind::Dense);
      c.A[(n - 1) + std::size_t(col) * c.ld] = nan;  // below (or on) the diagonal: passed over or a failure
      expectSameAsReference(c, "NaN");
      Case s = makeCase(rng, n, Kind::Dense);
      for (int i = 0; i < n; ++i) s.A[i + std::size_t(col) * s.ld] = 0;  // a zero column: singular
      std::vector<int> piv(n);
      EXPECT_FALSE(nscd::luFactor(s.A.data(), s.ld, n, piv.data())) << "n " << n << " zero column " << col;
    }
  }
}

// P A = L U to round-off, and luSolve inverts it: a check that does not lean on
// the reference.
TEST(LuKernel, FactorReproducesTheMatrixAndSolves) {
  std::mt19937 rng(3);
  for (int n : {7, 31, 60}) {
    const Case c = makeCase(rng, n, Kind::IdentityRows);
    std::vector<double> A = c.A;
    std::vector<int> piv(n);
    ASSERT_TRUE(nscd::luFactor(A.data(), c.ld, n, piv.data()));
    auto orig = [&](int i, int j) { return c.A[i + std::size_t(j) * c.ld]; };
    auto lu = [&](int i, int j) { return A[i + std::size_t(j) * c.ld]; };
    std::vector<int> row(n);  // row k of P A is row row[k] of A
    for (int i = 0; i < n; ++i) row[i] = i;
    for (int k = 0; k < n; ++k) std::swap(row[k], row[piv[k]]);
    double worst = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        double s = 0;
        for (int k = 0; k <= std::min(i, j); ++k) s += (k == i ? 1.0 : lu(i, k)) * lu(k, j);
        worst = std::max(worst, std::abs(s - orig(row[i], j)));
      }
    EXPECT_LT(worst, 1e-12 * n) << "n " << n;
    // A x = b for a known x.
    std::vector<double> x(n), b(n, 0.0);
    for (int i = 0; i < n; ++i) x[i] = 1 + 0.1 * i;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) b[i] += orig(i, j) * x[j];
    nscd::luSolve(A.data(), c.ld, n, piv.data(), b.data());
    for (int i = 0; i < n; ++i) EXPECT_NEAR(b[i], x[i], 1e-9) << "n " << n << " row " << i;
  }
}

}  // namespace
