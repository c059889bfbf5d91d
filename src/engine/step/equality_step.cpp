// Stages 3-4 for a step whose rows are all bilateral (a model without contact
// pairs and clearance joints: ideal joints and prescribed motions): W P = -b,
// one LDLᵀ solve, without the friction-contact problem's set-up and solver.
// The same arithmetic as the solver's equality-only path (problem_setup.cpp's
// prepareEqualityProblem, solver_stages.cpp's equalityStage) bit for bit, so the
// answer is the one the general path gives; a problem it does not solve (rows
// so nearly dependent that the basic solution leaves a residual above the
// tolerance, an inconsistent system, a non-finite entry) is left to that path.
// The factor stays in ws.equality for the projection's first pass
// (velocityFactorReusable).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "solver/dense_kernels.hpp"
#include "solver/row_count_dispatch.hpp"
#include "step_stages.hpp"

namespace nscd {
namespace {

// As problem_setup.cpp: a W diagonal at most this * the largest is a zero row
// (P = 0); a scaled pivot at most kScaledDrop ends the factor (dependent rows).
constexpr double kRelZeroDiag = 1e-13;
constexpr double kScaledDrop = 1e-13;
// As solver_schedule.cpp: solves with the factor after the first, while the
// residual is above the tolerance.
constexpr int kRefinements = 2;

// b = G v_free minus the targets, plus an ideal joint's workless average: the
// sums friction_contact_problem.cpp forms (each row over its bodies' columns in
// column order, from the first product). False if v_free is not finite (the
// general path takes the dense product then).
bool bilateralFreeVelocities(double joint_average, StepWorkspace& ws) {
  if ((ws.vfree.array() * 0.0).sum() != 0) return false;
  rowFreeVelocities(joint_average, ws);  // every block bilateral here
  return true;
}

// Every entry of W's lower triangle finite: x * 0 is +-0 for a finite x and NaN
// for any other, so the products' sum is 0, in whatever order, exactly then;
// summed two at a time (GCC's vector extension: SSE2 on x86-64).
bool lowerTriangleFinite(const double* W, Eigen::Index ldw, int r) {
  typedef double Pair __attribute__((vector_size(16)));
  Pair acc = {0.0, 0.0};
  double single = 0;
  for (int j = 0; j < r; ++j) {
    const double* w = W + j * ldw + j;
    const double* end = W + j * ldw + r;
    for (; end - w >= 2; w += 2) {
      Pair x;
      std::memcpy(&x, w, sizeof x);
      acc += x * 0.0;
    }
    if (w < end) single += *w * 0.0;
  }
  return acc[0] + acc[1] + single == 0;
}

// factorScaledRows's copy L = S W S where no row is zero (rows 0 .. r-1), W's
// finiteness checked on the way (as lowerTriangleFinite): the copy two entries at
// a time, each entry's product the same. False (L not factored) if W is not finite.
// N > 0: r = N, the loops' bounds known (scaledCopyIfFinite).
template <int N = 0>
bool scaledCopyRows(const double* W, Eigen::Index ldw, int r_, const double* s, double* L, Eigen::Index ldl) {
  const int r = N > 0 ? N : r_;
  typedef double Pair __attribute__((vector_size(16)));
  Pair acc = {0.0, 0.0};
  double single = 0;
  for (int c = 0; c < r; ++c) {
    const double* wc = W + c * ldw;
    double* lc = L + c * ldl;
    const double sc = s[c];
    int i = c;
    for (; i + 2 <= r; i += 2) {
      Pair w, si;
      std::memcpy(&w, wc + i, sizeof w);
      std::memcpy(&si, s + i, sizeof si);
      const Pair l = w * (si * sc);
      std::memcpy(lc + i, &l, sizeof l);
      acc += w * 0.0;
    }
    if (i < r) {
      lc[i] = wc[i] * (s[i] * sc);
      single += wc[i] * 0.0;
    }
  }
  return acc[0] + acc[1] + single == 0;
}

bool scaledCopyIfFinite(const double* W, Eigen::Index ldw, int r, const double* s, double* L, Eigen::Index ldl) {
  return withRowCount(JointRowCounts{}, r,
                      [&](auto rows) { return scaledCopyRows<decltype(rows)::value>(W, ldw, r, s, L, ldl); });
}

// The rows not zero, scaled to a unit diagonal, factored. False if W is not finite.
bool factorRows(StepWorkspace& ws, int r) {
  EqualityFactor& f = ws.equality;
  const double* W = ws.W.data();
  const Eigen::Index ldw = ws.W.outerStride();
  double maxDiag = 0;
  for (int i = 0; i < r; ++i) {
    if (!std::isfinite(W[i * ldw + i])) return false;
    maxDiag = std::max(maxDiag, W[i * ldw + i]);
  }
  const double zeroDiag = kRelZeroDiag * maxDiag;
  int ne = 0;
  for (int i = 0; i < r; ++i)
    if (W[i * ldw + i] > zeroDiag) f.rows[ne++] = i;
  f.ne = ne;
  double* s = f.scale.data();
  for (int a = 0; a < ne; ++a) s[a] = 1 / std::sqrt(W[f.rows[a] * ldw + f.rows[a]]);
  if (ne == r) {  // the copy covers W's lower triangle (the one assembled) and checks it
    if (!scaledCopyIfFinite(W, ldw, r, s, f.L.data(), f.L.outerStride())) return false;
    pivotedLdlt(f.L.data(), int(f.L.outerStride()), ne, kScaledDrop, f.perm.data(), f.perm.data() + ne);
    return true;
  }
  if (!lowerTriangleFinite(W, ldw, r)) return false;
  factorScaledRows(W, int(ldw), r, f.rows.data(), ne, s, f.L.data(), int(f.L.outerStride()), kScaledDrop,
                   f.perm.data());
  return true;
}

// U = W P + b over the nonzero P_j, and the solver's error sqrt(|U|^2) / max(1, |b|)
// summed block by block (errorFromU).
template <int N = 0>
double residualRows(StepWorkspace& ws, int r_, double bnorm) {
  const int r = N > 0 ? N : r_;
  double* U = ws.equality.U.data();
  const double* W = ws.W.data();
  const Eigen::Index ldw = ws.W.outerStride();
  for (int i = 0; i < r; ++i) U[i] = ws.b[i];
  for (int j = 0; j < r; ++j) {  // W_ij = W_ji above the diagonal (the lower triangle holds W)
    const double pj = ws.P[j];
    if (pj == 0) continue;
    const double* wj = W + j * ldw;
    for (int i = 0; i < j; ++i) U[i] += W[i * ldw + j] * pj;
    for (int i = j; i < r; ++i) U[i] += wj[i] * pj;
  }
  double sum = 0;
  for (const ConstraintBlock& blk : ws.blocks) {
    double s = 0;
    for (int k = blk.row; k < blk.row + blk.size; ++k) s += U[k] * U[k];
    sum += s;
  }
  return std::sqrt(sum) / std::max(1.0, bnorm);
}

// The same sums for every r; the joints' common sizes with the loops' bounds known.
double residualOf(StepWorkspace& ws, int r, double bnorm) {
  return withRowCount(JointRowCounts{}, r,
                      [&](auto rows) { return residualRows<decltype(rows)::value>(ws, r, bnorm); });
}

}  // namespace

void solveWithEqualityFactor(StepWorkspace& ws, int r, const double* rhs, double* P) {
  EqualityFactor& f = ws.equality;
  solveScaledRows(f.L.data(), int(f.L.outerStride()), f.ne, f.perm.data(), f.rows.data(), f.scale.data(), r, rhs,
                  f.x.data(), P);
}

bool solveEqualityStep(const Model& m, StepWorkspace& ws, StepStats& st) {
  const int r = ws.rows;
  ws.equality.factor_rows = 0;
  const double theta = m.settings.theta;
  const double joint_average = m.settings.joint_work == JointWork::None ? (1 - theta) / theta : 0.0;
  if (!bilateralFreeVelocities(joint_average, ws)) return false;
  if (!ws.facts.stiff && ws.mass_inverse_by_body && ws.nbodies <= 64)
    assembleEqualityDelassus(ws, r);  // the lower triangle: all the factor and residual read
  else
    assembleDelassus(ws.iteration_inverse, !ws.facts.stiff, ws, 0, r);
  if (!factorRows(ws, r)) return false;
  const double bnorm = ws.b.head(r).norm();
  if (!std::isfinite(bnorm)) return false;
  const double tol = m.settings.tolerance;
  double* P = ws.P.data();
  solveWithEqualityFactor(ws, r, ws.b.data(), P);
  double err = residualOf(ws, r, bnorm);
  int solves = 1;
  // Refinement: the correction of the residual U (U = 0 is the answer).
  for (int k = 0; k < kRefinements && !(err <= tol); ++k) {
    double* correction = ws.equality.correction.data();
    solveWithEqualityFactor(ws, r, ws.equality.U.data(), correction);
    for (int i = 0; i < r; ++i) P[i] += correction[i];
    err = residualOf(ws, r, bnorm);
    ++solves;
  }
  if (!(err <= tol) || !ws.P.head(r).allFinite()) return false;  // the general path's
  ws.equality.factor_rows = r;
  st.active_contacts = 0;
  st.iterations = solves;
  st.residual = err;
  st.converged = true;
  st.rows = r;
  ++st.solves_by_stage[static_cast<int>(SolverStage::Equalities)];
  ++st.direct_equality_solves;
  applyImpulses(ws);
  return true;
}

}  // namespace nscd
