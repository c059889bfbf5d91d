// Dense kernels on column-major storage with leading dimension ld, in place and
// without allocation (the contact solver's equality block and Newton Jacobian).
#pragma once

namespace nscd {

// In-place Cholesky with diagonal pivoting of the n x n symmetric A (full
// storage): A = Pi L L^T Pi^T, L in the lower triangle, perm[k] = original
// index of pivot k. Stops at the first pivot <= dropTol (the rest is dependent);
// returns the rank.
int pivotedCholesky(double* A, int ld, int n, double dropTol, int* perm);

// x = A^+ rhs (basic solution: dependent pivots get 0) from pivotedCholesky;
// rhs in, x out (both in original order); tmp: n scratch.
void pivotedCholeskySolve(const double* L, int ld, int n, int rank, const int* perm, double* x,
                          double* tmp);

// In-place LDL^T with diagonal (complete) pivoting of the n x n symmetric
// positive semidefinite A, its lower triangle only (read and written; the upper
// is not touched): Pi^T A Pi = L D L^T, L unit lower triangular below the
// diagonal, D on it, perm[k] = original index of pivot k. The next row in
// order is the pivot while its diagonal is at least a quarter of A's largest
// diagonal; else the largest remaining diagonal is; the first one at most
// dropTol stops it (the rows left depend on those before them: every entry of
// what is left is at most dropTol), and their D and L are set to 0. Returns the
// rank. nonzero: n scratch.
int pivotedLdlt(double* A, int ld, int n, double dropTol, int* perm, int* nonzero);

// x = A^+ rhs from that factor, the basic solution: dependent rows get 0. rhs
// in, x out (both in original order); tmp: n scratch.
void ldltSolve(const double* L, int ld, int n, const int* perm, double* x, double* tmp);

// The equality rows' factor, as the solver and the direct equality step use it:
// rows[0..ne) of the m x m W (its nonzero rows), scaled by s (1/sqrt of their
// diagonals) to a unit diagonal, into L's lower triangle, then pivotedLdlt.
void factorScaledRows(const double* W, int ldw, int m, const int* rows, int ne, const double* s, double* L,
                      int ldl, double dropTol, int* perm);
// P = -W^+ rhs over those rows from that factor (W = S^-1 Ws S^-1, so W^+ rhs =
// S Ws^+ S rhs), 0 on the others; x: 2 ne scratch.
void solveScaledRows(const double* L, int ldl, int ne, const int* perm, const int* rows, const double* s, int m,
                     const double* rhs, double* x, double* P);

// In-place LU with partial pivoting (row k swapped with piv[k]). False if a
// pivot is zero or not finite.
bool luFactor(double* A, int ld, int n, int* piv);
void luSolve(const double* A, int ld, int n, const int* piv, double* x);

}  // namespace nscd
