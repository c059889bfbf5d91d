// What every stage of a solve relies on: the problem prepared once (zero rows,
// the Newton's row scaling, the equality rows assembled into one block and
// factored), and an iterate (re)started on it; for a problem of equality rows
// only, their factor, which is the solve.
#include <algorithm>
#include <cmath>

#include "dense_kernels.hpp"
#include "solve_run.hpp"

namespace nscd {
namespace {

constexpr double kRelZeroDiag = 1e-13;  // a W diagonal below this * max diagonal is a zero row
constexpr double kEqDrop = 1e-11;       // equality pivots below this * max diagonal: dependent rows
// Equality-only problems: W scaled to a unit diagonal and factored with
// diagonal pivoting, a pivot below this is a row dependent on those before it
// (its component off their span, in W's metric, below 3e-7 of its length).
// Redundant loop rows (a four-bar closed in 3D: 3 of its 20 rows) come out at
// round-off, 1e-16, the others' smallest at 4e-3. (In the rows' own order,
// without pivoting, the four-bar's redundant rows came out at up to 2e-12,
// after pivots of 7e-4: too close to a threshold.) A row kept that nearly
// depends on the others (pivot d) errs by about 1e-16 / sqrt(d) relative in the
// velocities its impulse makes: 3e-10 at this threshold.
constexpr double kEqScaledDrop = 1e-13;

// buf's equality buffers hold ne rows.
void growEqualityBuffers(SolverBuffers& buf, int ne) {
  if (ne <= buf.maxEq) return;
  buf.maxEq = ne;
  buf.eqL.resize(ne, ne);
  buf.eqRhs.resize(2 * ne);
  buf.eqPerm.resize(2 * ne);  // the pivoting order, then pivotedLdlt's scratch
  buf.eqScale.resize(ne);
}

// Zero rows keep P = 0. The Newton's per-row scaling rho.
void scaleRows(SolveProblem& pr) {
  const auto& W = pr.W;
  char* zeroRow = pr.buf.zeroRow.data();
  double* rho = pr.buf.rho.data();
  for (int i = 0; i < pr.m; ++i) zeroRow[i] = !(W(i, i) > pr.zeroDiag);
  for (const ProblemBlock& bl : pr.blocks) {
    const int r = bl.row;
    // A bilateral row's Newton function is its velocity U itself (rho 1), the
    // quantity the error measures: the direction does not depend on a row's
    // scale, but the line search's merit 0.5 |phi|^2 does, and 1 / W_ii (up to
    // 4e9 on the rotation rows of the ideal C-60's light links) let it trade the
    // joints' error for the contacts'.
    for (int i = r; i < r + bl.size; ++i)
      rho[i] = zeroRow[i] || bl.kind == BlockKind::Bilateral ? 1.0 : 1.0 / W(i, i);
    // One scale for the normal and the tangents of a contact (1 / its normal
    // diagonal): the Alart-Curnier disc P_T - rho U_T then lives in the same
    // metric as P_N - rho U_N; separate tangent scales made the Newton stall on
    // the C-60's hyperstatic sets.
    if (bl.kind == BlockKind::Frictional) rho[r + 1] = rho[r + 2] = rho[r];
  }
}

// The equality rows (bilateral, not zero) as one block, factored once.
void factorEqualities(SolveProblem& pr) {
  const auto& W = pr.W;
  SolverBuffers& buf = pr.buf;
  const char* zeroRow = buf.zeroRow.data();
  buf.eqRows.clear();
  double maxEqDiag = 0;
  for (const ProblemBlock& bl : pr.blocks) {
    if (bl.kind != BlockKind::Bilateral) continue;
    for (int i = bl.row; i < bl.row + bl.size; ++i) {
      if (zeroRow[i]) continue;
      buf.eqRows.push_back(i);
      maxEqDiag = std::max(maxEqDiag, W(i, i));
    }
  }
  const int ne = int(buf.eqRows.size());
  pr.ne = ne;
  growEqualityBuffers(buf, ne);
  if (ne > 0) {
    for (int c = 0; c < ne; ++c)
      for (int r = 0; r < ne; ++r) buf.eqL(r, c) = W(buf.eqRows[r], buf.eqRows[c]);
    buf.eqRank = pivotedCholesky(buf.eqL.data(), int(buf.eqL.rows()), ne, kEqDrop * maxEqDiag, buf.eqPerm.data());
  }
}

}  // namespace

void prepareEqualityProblem(SolveProblem& pr, double maxDiag) {
  const auto& W = pr.W;
  SolverBuffers& buf = pr.buf;
  pr.maxDiag = maxDiag;
  pr.zeroDiag = kRelZeroDiag * maxDiag;
  buf.eqRows.clear();
  for (int i = 0; i < pr.m; ++i) {
    buf.zeroRow[i] = !(W(i, i) > pr.zeroDiag);
    if (!buf.zeroRow[i]) buf.eqRows.push_back(i);
  }
  const int ne = int(buf.eqRows.size());
  pr.ne = ne;
  growEqualityBuffers(buf, ne);
  // The unit-diagonal scaling makes the pivoting and the rank test independent of
  // the rows' units (a light link's rotation rows are 1e9 times its neighbours').
  double* s = buf.eqScale.data();
  for (int a = 0; a < ne; ++a) s[a] = 1 / std::sqrt(W(buf.eqRows[a], buf.eqRows[a]));
  factorScaledRows(W.data(), int(W.outerStride()), pr.m, buf.eqRows.data(), ne, s, buf.eqL.data(),
                   int(buf.eqL.outerStride()), kEqScaledDrop, buf.eqPerm.data());
  pr.bnorm = pr.b.head(pr.m).norm();
  pr.localTol = std::max(1e-14, 1e-2 * pr.tolerance);
}

void solveByEqualityFactor(SolverBuffers& buf, int m, const double* rhs, double* P) {
  solveScaledRows(buf.eqL.data(), int(buf.eqL.outerStride()), int(buf.eqRows.size()), buf.eqPerm.data(),
                  buf.eqRows.data(), buf.eqScale.data(), m, rhs, buf.eqRhs.data(), P);
}

void prepareProblem(SolveProblem& pr, double maxDiag) {
  pr.maxDiag = maxDiag;
  pr.zeroDiag = kRelZeroDiag * maxDiag;
  scaleRows(pr);
  factorEqualities(pr);
  pr.bnorm = pr.b.head(pr.m).norm();
  pr.localTol = std::max(1e-14, 1e-2 * pr.tolerance);
}

void refreshIterate(const SolveProblem& pr, Iterate& it) {
  it.U.noalias() = pr.Wm * it.P.head(pr.m);
  it.U += pr.b.head(pr.m);
  it.err = errorFromU(pr.blocks, it.P.data(), it.U.data(), pr.bnorm);
}

void restartIterate(const SolveProblem& pr, Iterate& it) {
  const char* zeroRow = pr.buf.zeroRow.data();
  for (const ProblemBlock& bl : pr.blocks) {
    if (bl.kind == BlockKind::Frictionless) continue;
    for (int i = bl.row; i < bl.row + bl.size; ++i)
      if (zeroRow[i] && (bl.kind == BlockKind::Bilateral || i > bl.row)) it.P(i) = 0;
  }
  refreshIterate(pr, it);
}

}  // namespace nscd
