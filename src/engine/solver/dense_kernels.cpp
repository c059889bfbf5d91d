// Dense kernels (dense_kernels.hpp): pivoted Cholesky, pivoted LDL^T and LU
// with partial pivoting, in place, no allocation.
#include "dense_kernels.hpp"
#include "row_count_dispatch.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

namespace nscd {

// In-place Cholesky with diagonal pivoting of the n x n symmetric A (full
// storage): A = Pi L L^T Pi^T, L in the lower triangle, perm[k] = original
// index of pivot k. Stops at the first pivot <= dropTol (the rest is dependent);
// returns the rank.
int pivotedCholesky(double* A, int ld, int n, double dropTol, int* perm) {
  for (int i = 0; i < n; ++i) perm[i] = i;
  auto a = [&](int i, int j) -> double& { return A[i + std::size_t(j) * ld]; };
  for (int k = 0; k < n; ++k) {
    int p = k;
    for (int i = k + 1; i < n; ++i)
      if (a(i, i) > a(p, p)) p = i;
    if (!(a(p, p) > dropTol)) return k;
    if (p != k) {  // symmetric swap of rows and columns k, p
      for (int j = 0; j < n; ++j) std::swap(a(k, j), a(p, j));
      for (int i = 0; i < n; ++i) std::swap(a(i, k), a(i, p));
      std::swap(perm[k], perm[p]);
    }
    const double d = std::sqrt(a(k, k));
    a(k, k) = d;
    for (int i = k + 1; i < n; ++i) a(i, k) /= d;
    // Trailing update of the full square (later symmetric swaps move entries
    // across the diagonal, so both triangles must stay current).
    for (int j = k + 1; j < n; ++j) {
      const double ljk = a(j, k);
      if (ljk == 0) continue;
      double* cj = &a(0, j);
      const double* ck = &a(0, k);
      for (int i = k + 1; i < n; ++i) cj[i] -= ck[i] * ljk;
    }
  }
  return n;
}

// x = A^+ rhs (basic solution: dependent pivots get 0) from pivotedCholesky;
// rhs in, x out (both in original order); tmp: n scratch.
void pivotedCholeskySolve(const double* L, int ld, int n, int rank, const int* perm, double* x,
                          double* tmp) {
  auto l = [&](int i, int j) { return L[i + std::size_t(j) * ld]; };
  for (int k = 0; k < n; ++k) tmp[k] = x[perm[k]];
  for (int k = 0; k < rank; ++k) {  // L z = y
    tmp[k] /= l(k, k);
    for (int i = k + 1; i < rank; ++i) tmp[i] -= l(i, k) * tmp[k];
  }
  for (int k = rank; k < n; ++k) tmp[k] = 0;
  for (int k = rank - 1; k >= 0; --k) {  // L^T x = z
    double s = tmp[k];
    for (int i = k + 1; i < rank; ++i) s -= l(i, k) * tmp[i];
    tmp[k] = s / l(k, k);
  }
  for (int k = 0; k < n; ++k) x[perm[k]] = tmp[k];
}

namespace {

// Rows and columns k < p of a symmetric matrix swapped, in its lower triangle.
void swapSymmetricLower(double* A, int ld, int n, int k, int p) {
  auto a = [&](int i, int j) -> double& { return A[i + std::size_t(j) * ld]; };
  for (int c = 0; c < k; ++c) std::swap(a(k, c), a(p, c));
  std::swap(a(k, k), a(p, p));
  for (int i = k + 1; i < p; ++i) std::swap(a(i, k), a(p, i));
  for (int r = p + 1; r < n; ++r) std::swap(a(r, k), a(r, p));
}

}  // namespace

namespace {

// pivotedLdlt (N > 0: n = N, the loops' bounds known).
template <int N = 0>
int pivotedLdltRows(double* A, int ld, int n_, double dropTol, int* perm, int* nonzero) {
  const int n = N > 0 ? N : n_;
  for (int i = 0; i < n; ++i) perm[i] = i;
  auto a = [&](int i, int j) -> double& { return A[i + std::size_t(j) * ld]; };
  // Threshold pivoting: the next row in order is the pivot while its diagonal is
  // at least kPivotThreshold of the largest initial diagonal, which bounds every
  // remaining one (A is semidefinite: eliminating lowers the diagonals), so it
  // is then at least that fraction of the largest remaining, and |L_ik| <=
  // sqrt(A_ii / D_k) <= 1 / sqrt(kPivotThreshold) on a unit diagonal. Only
  // below it the largest remaining diagonal is searched for and swapped in.
  constexpr double kPivotThreshold = 0.25;
  double max_diag = 0;
  for (int i = 0; i < n; ++i) max_diag = std::max(max_diag, a(i, i));
  const double accept = std::max(kPivotThreshold * max_diag, dropTol);
  for (int k = 0; k < n; ++k) {
    int p = k;
    double big = a(k, k);
    if (!(big > accept))
      for (int i = k + 1; i < n; ++i)
        if (a(i, i) > big) {
          big = a(i, i);
          p = i;
        }
    if (!(big > dropTol)) {  // the rows left depend on those before: out of the factor
      for (int j = k; j < n; ++j)
        for (int i = j; i < n; ++i) a(i, j) = 0;
      return k;
    }
    if (p != k) {
      swapSymmetricLower(A, ld, n, k, p);
      std::swap(perm[k], perm[p]);
    }
    // Trailing update A22 -= v v^T / d (v: column k below the pivot), lower
    // part, over v's nonzero entries only (W of joints is sparse: a joint's rows
    // meet only those of joints on its bodies). A skipped update would subtract
    // an exact +-0 (s is finite for a finite A), which changes no entry but the
    // sign of a -0; a difference is -0 only for -0 - (+0), so where A holds no
    // -0 (the step's W: its sums start at +0) no entry ever is one and the
    // factor is the dense loop's bit for bit. The columns are distinct, hence
    // __restrict.
    double* __restrict ck = &a(0, k);
    int nnz = 0;
    for (int i = k + 1; i < n; ++i)
      if (ck[i] != 0) nonzero[nnz++] = i;
    // Column k scaled (L = v / d) as it goes: entry j once the updates that read it
    // unscaled (those of columns j' <= j) are done; s is its scaled value.
    const double inv = 1 / ck[k];
    for (int t = 0; t < nnz; ++t) {
      const int j = nonzero[t];
      const double s = ck[j] * inv;
      if (s != 0) {
        double* __restrict cj = &a(0, j);
        for (int u = t; u < nnz; ++u) {
          const int i = nonzero[u];
          cj[i] -= ck[i] * s;
        }
      }
      ck[j] = s;
    }
  }
  return n;
}

}  // namespace

int pivotedLdlt(double* A, int ld, int n, double dropTol, int* perm, int* nonzero) {
  // 5, 6, 10, 11 and 12 rows by a switch, not withRowCount: the kernel inlined under it
  // costs a double pendulum's or four-bar's factor ~55 instructions less (callgrind,
  // nscd_mujoco_compare --single double_pendulum; the same code otherwise).
  switch (n) {
    case 5: return pivotedLdltRows<5>(A, ld, n, dropTol, perm, nonzero);
    case 6: return pivotedLdltRows<6>(A, ld, n, dropTol, perm, nonzero);
    case 10: return pivotedLdltRows<10>(A, ld, n, dropTol, perm, nonzero);
    case 11: return pivotedLdltRows<11>(A, ld, n, dropTol, perm, nonzero);
    case 12: return pivotedLdltRows<12>(A, ld, n, dropTol, perm, nonzero);
    default: return pivotedLdltRows(A, ld, n, dropTol, perm, nonzero);
  }
}

namespace {

// ldltSolve on the right-hand side in the pivoting order, in place (N > 0: n = N,
// the loops unrolled).
template <int N = 0>
void ldltSolveRows(const double* L, int ld, int n_, double* tmp) {
  const int n = N > 0 ? N : n_;
  for (int k = 0; k < n; ++k) {  // L z = y (a dependent row's column is 0)
    const double zk = tmp[k];
    if (zk == 0) continue;
    const double* ck = L + std::size_t(k) * ld;
    for (int i = k + 1; i < n; ++i) tmp[i] -= ck[i] * zk;
  }
  for (int k = n - 1; k >= 0; --k) {  // D L^T x = z; a dependent row's x is 0
    const double* ck = L + std::size_t(k) * ld;
    if (ck[k] == 0) {
      tmp[k] = 0;
      continue;
    }
    double s = tmp[k] / ck[k];
    for (int i = k + 1; i < n; ++i) s -= ck[i] * tmp[i];
    tmp[k] = s;
  }
}

// The same arithmetic for every n, the joints' common sizes with the loops' bounds known.
void ldltSolveInOrder(const double* L, int ld, int n, double* tmp) {
  withRowCount(JointRowCounts{}, n, [&](auto rows) { ldltSolveRows<decltype(rows)::value>(L, ld, n, tmp); });
}

}  // namespace

void ldltSolve(const double* L, int ld, int n, const int* perm, double* x, double* tmp) {
  for (int k = 0; k < n; ++k) tmp[k] = x[perm[k]];
  ldltSolveInOrder(L, ld, n, tmp);
  for (int k = 0; k < n; ++k) x[perm[k]] = tmp[k];
}

// In-place LU with partial pivoting (row k swapped with piv[k]). False if a
// pivot is zero or not finite (the matrix is then left part-way). Built for AVX
// too, taken where the machine has it (target_clones; no FMA: the same products
// and sums, the same bits).
// Two pivots a pass over the trailing columns: column k + 1 is brought up to date
// by pivot k first (pivot k found, its rows swapped, its column scaled), then
// every later column takes pivot k's update and pivot k + 1's in that order: each
// entry sees the same operations in the same order as with one pivot a pass (a
// row swap commutes with the updates of the rows it swaps), at half the loads and
// stores of the trailing matrix. An update by a zero U entry is skipped, as
// before (it could only turn a -0 into +0).
namespace {

// Pivot k: the first row from k on of the largest magnitude in column k (a NaN
// below the diagonal is passed over; one on it fails), found as the largest
// (max_pd keeps its second operand when the first is NaN: v > best ? v : best,
// lane by lane, and a largest is the same in any order) and then the first row
// that has it; rows k and piv[k] swapped across the matrix, column k scaled.
// False: no usable pivot.
__attribute__((always_inline)) inline bool takePivot(double* A, int ld, int n, int k, int* piv) {
  double* ck = A + std::size_t(k) * ld;
  double best = std::abs(ck[k]);  // a NaN here stays the largest, refused below
  int i = k + 1;
#ifdef __SSE2__
  const __m128d sign = _mm_set1_pd(-0.0);
  __m128d best2 = _mm_set1_pd(best);
  for (; i + 1 < n; i += 2) best2 = _mm_max_pd(_mm_andnot_pd(sign, _mm_loadu_pd(ck + i)), best2);
  double lanes[2];
  _mm_storeu_pd(lanes, best2);
  best = lanes[1] > lanes[0] ? lanes[1] : lanes[0];
#endif
  for (; i < n; ++i)
    if (std::abs(ck[i]) > best) best = std::abs(ck[i]);
  if (!(best > 0) || !std::isfinite(best)) return false;
  int p = k;
  while (!(std::abs(ck[p]) == best)) ++p;
  piv[k] = p;
  if (p != k)
    for (int j = 0; j < n; ++j) std::swap(A[k + std::size_t(j) * ld], A[p + std::size_t(j) * ld]);
  const double inv = 1 / ck[k];
  for (i = k + 1; i < n; ++i) ck[i] *= inv;
  return true;
}

}  // namespace

__attribute__((target_clones("avx", "default"))) bool luFactor(double* A, int ld, int n, int* piv) {
  auto col = [&](int j) { return A + std::size_t(j) * ld; };
  int k = 0;
  for (; k + 1 < n; k += 2) {
    const int k1 = k + 1;
    if (!takePivot(A, ld, n, k, piv)) return false;
    const double* ck = col(k);
    double* c1 = col(k1);
    const double akk1 = c1[k];
    if (akk1 != 0)
      for (int i = k1; i < n; ++i) c1[i] -= ck[i] * akk1;
    if (!takePivot(A, ld, n, k1, piv)) return false;
    const double l1 = ck[k1];  // row k + 1's multiplier of pivot k, after its swap
    for (int j = k1 + 1; j < n; ++j) {
      double* cj = col(j);
      const double akj = cj[k];
      if (akj != 0) cj[k1] -= l1 * akj;
      const double ak1j = cj[k1];
      if (akj != 0 && ak1j != 0) {
        for (int i = k1 + 1; i < n; ++i) cj[i] = (cj[i] - ck[i] * akj) - c1[i] * ak1j;
      } else if (akj != 0) {
        for (int i = k1 + 1; i < n; ++i) cj[i] -= ck[i] * akj;
      } else if (ak1j != 0) {
        for (int i = k1 + 1; i < n; ++i) cj[i] -= c1[i] * ak1j;
      }
    }
  }
  return k == n || takePivot(A, ld, n, k, piv);  // the last column alone, n odd
}

__attribute__((target_clones("avx", "default"))) void luSolve(const double* A, int ld, int n, const int* piv,
                                                               double* x) {
  auto a = [&](int i, int j) { return A[i + std::size_t(j) * ld]; };
  for (int k = 0; k < n; ++k) std::swap(x[k], x[piv[k]]);
  for (int k = 0; k < n; ++k) {
    const double xk = x[k];
    if (xk != 0)
      for (int i = k + 1; i < n; ++i) x[i] -= a(i, k) * xk;
  }
  for (int k = n - 1; k >= 0; --k) {
    x[k] /= a(k, k);
    const double xk = x[k];
    if (xk != 0)
      for (int i = 0; i < k; ++i) x[i] -= a(i, k) * xk;
  }
}

void factorScaledRows(const double* W, int ldw, int m, const int* rows, int ne, const double* s, double* L,
                      int ldl, double dropTol, int* perm) {
  for (int c = 0; c < ne; ++c) {
    const double* wc = W + std::ptrdiff_t(rows[c]) * ldw;
    double* lc = L + std::ptrdiff_t(c) * ldl;
    const double sc = s[c];
    if (ne == m) {  // no zero rows: the rows are 0 .. m-1
      for (int r = c; r < ne; ++r) lc[r] = wc[r] * (s[r] * sc);
    } else {
      for (int r = c; r < ne; ++r) lc[r] = wc[rows[r]] * (s[r] * sc);
    }
  }
  pivotedLdlt(L, ldl, ne, dropTol, perm, perm + ne);
}

namespace {

// solveScaledRows (N > 0: ne = N, as ldltSolveRows).
template <int N = 0>
void solveScaledRowsOf(const double* L, int ldl, int ne_, const int* perm, const int* rows, const double* s, int m,
                       const double* rhs, double* x, double* P) {
  const int ne = N > 0 ? N : ne_;
  // ldltSolve's permutations folded into the scaling (x: its scratch, in the
  // pivoting order).
  for (int k = 0; k < ne; ++k) {
    const int a = perm[k];
    x[k] = -s[a] * rhs[rows[a]];
  }
  ldltSolveRows<N>(L, ldl, ne, x);
  if (ne < m)
    for (int i = 0; i < m; ++i) P[i] = 0;
  for (int k = 0; k < ne; ++k) {
    const int a = perm[k];
    P[rows[a]] = s[a] * x[k];
  }
}

}  // namespace

void solveScaledRows(const double* L, int ldl, int ne, const int* perm, const int* rows, const double* s, int m,
                     const double* rhs, double* x, double* P) {
  withRowCount(JointRowCounts{}, ne, [&](auto count) {
    solveScaledRowsOf<decltype(count)::value>(L, ldl, ne, perm, rows, s, m, rhs, x, P);
  });
}

}  // namespace nscd
