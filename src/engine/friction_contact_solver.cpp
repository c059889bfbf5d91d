// Nonsmooth Gauss-Seidel over the blocks of the one-step contact problem,
// with the running local velocities U = W P + b updated incrementally (O(m)
// per block), an exact local solve per block, all equality rows solved
// together (one dense factorisation per call), a global semismooth Newton
// on the Alart-Curnier function for slow (strongly coupled) cases, and the
// Siconos-style error.
#include "nscd_sim/friction_contact_solver.hpp"

#include <algorithm>
#include <cmath>

namespace nscd {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

constexpr int kMaxBilateral = 6;
using BVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxBilateral, 1>;

constexpr double kRelZeroDiag = 1e-13;  // a W diagonal below this * max diagonal is a zero row
constexpr int kRefreshEvery = 16;       // recompute U = W P + b exactly this often (round-off)
constexpr int kStallWindow = 100;       // sweeps without halving the error = stalled
constexpr double kProximalSigma = 0.1;  // proximal weight relative to the block diagonal
constexpr double kEqDrop = 1e-11;       // equality pivots below this * max diagonal: dependent rows

// Global Newton (see solve()).
constexpr int kNewtonMaxRows = 400;      // dense m x m LU beyond this costs more than sweeps
constexpr int kNewtonSmallRows = 24;     // Auto: Newton after one sweep up to this size
constexpr int kSwitchSweeps = 1;         // Auto: looks at the NSGS rate after 1, 2, 4, 8, ... sweeps
constexpr double kNewtonCostIterations = 6;  // Auto: expected Newton iterations...
constexpr double kLuRowsPerSweep = 20;   // ...each costing (1 + m / this) sweeps
constexpr int kNewtonMaxIterations = 60;  // per attempt
constexpr int kNewtonAttempts = 4;       // Newton runs per solve, NSGS sweeps in between
constexpr int kNewtonStall = 25;         // iterations without halving the error: give up
constexpr int kNonMonotone = 5;          // merit history of the line search
constexpr int kLineSearchSteps = 30;
constexpr double kNewtonDelta0 = 1e-10;  // Jacobian regularisation, relative to diag(W)
constexpr double kNewtonDeltaMax = 1e-1;
constexpr double kNewtonShortStep = 0.25;  // accepted step length below this: more delta
constexpr double kNewtonMaxImpulse = 1e3;  // iterates bounded by this * impulse scale

int problemRows(const std::vector<ProblemBlock>& blocks) {
  int m = 0;
  for (const ProblemBlock& bl : blocks) m = std::max(m, bl.row + bl.size);
  return m;
}

// Squared error of one block given its U (see solverError).
double blockError2(const ProblemBlock& bl, const double* P, const double* U) {
  switch (bl.kind) {
    case BlockKind::Frictional: {
      const Vector3d p(P[0], P[1], P[2]);
      const Vector3d u(U[0], U[1], U[2]);
      const double e = localCoulombError(p, u, bl.mu);
      return e * e;
    }
    case BlockKind::Frictionless: {
      const double e = P[0] - std::max(0.0, P[0] - U[0]);
      return e * e;
    }
    case BlockKind::Bilateral: {
      double s = 0;
      for (int i = 0; i < bl.size; ++i) s += U[i] * U[i];
      return s;
    }
  }
  return 0;
}

double errorFromU(const std::vector<ProblemBlock>& blocks, const double* P, const double* U,
                  double bnorm) {
  double s = 0;
  for (const ProblemBlock& bl : blocks) s += blockError2(bl, P + bl.row, U + bl.row);
  return std::sqrt(s) / std::max(1.0, bnorm);
}

bool validBlocks(const std::vector<ProblemBlock>& blocks, Eigen::Index rows) {
  for (const ProblemBlock& bl : blocks) {
    const int want = bl.kind == BlockKind::Frictional ? 3 : bl.kind == BlockKind::Frictionless ? 1 : -1;
    if (bl.row < 0 || bl.size < 1 || bl.row + bl.size > rows) return false;
    if (want > 0 ? bl.size != want : bl.size > kMaxBilateral) return false;
  }
  return true;
}

// ---- dense kernels on column-major storage with leading dimension ld (no allocation)

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

// In-place LU with partial pivoting (row k swapped with piv[k]). False if a
// pivot is zero or not finite.
bool luFactor(double* A, int ld, int n, int* piv) {
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
    double* ck = &a(0, k);
    for (int i = k + 1; i < n; ++i) ck[i] *= inv;
    for (int j = k + 1; j < n; ++j) {
      const double akj = a(k, j);
      if (akj == 0) continue;
      double* cj = &a(0, j);
      for (int i = k + 1; i < n; ++i) cj[i] -= ck[i] * akj;
    }
  }
  return true;
}

void luSolve(const double* A, int ld, int n, const int* piv, double* x) {
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

// ---- Alart-Curnier function of the whole problem

// Rows of one frictional block: phi (3) and, if A3/B3 are given, dPhi/dP and
// dPhi/dU (same formulation as the local solver). zt[i]: tangent row i is a
// zero row (its P and U are taken as 0).
void acFrictional(const double* P, const double* U, double mu, double rhoN, double rhoT,
                  const bool zt[2], double* phi, Matrix3d* A3, Matrix3d* B3) {
  const Vector3d p(P[0], zt[0] ? 0.0 : P[1], zt[1] ? 0.0 : P[2]);
  const Vector3d u(U[0], zt[0] ? 0.0 : U[1], zt[1] ? 0.0 : U[2]);
  Matrix3d A = Matrix3d::Zero(), B = Matrix3d::Zero();
  const double tN = p(0) - rhoN * u(0);
  if (tN > 0) {
    phi[0] = rhoN * u(0);
    B(0, 0) = rhoN;
  } else {
    phi[0] = p(0);
    A(0, 0) = 1;
  }
  const double r = mu * std::max(0.0, tN);
  const Eigen::Vector2d z = p.tail<2>() - rhoT * u.tail<2>();
  const double nz = z.norm();
  if (nz <= r) {
    phi[1] = rhoT * u(1);
    phi[2] = rhoT * u(2);
    B(1, 1) = B(2, 2) = rhoT;
  } else {
    const Eigen::Vector2d zh = z / nz;
    phi[1] = p(1) - r * zh(0);
    phi[2] = p(2) - r * zh(1);
    const Eigen::Matrix2d G = (r / nz) * (Eigen::Matrix2d::Identity() - zh * zh.transpose());
    A.block<2, 2>(1, 1) = Eigen::Matrix2d::Identity() - G;
    B.block<2, 2>(1, 1) = rhoT * G;
    if (tN > 0) {
      A.block<2, 1>(1, 0) = -mu * zh;
      B.block<2, 1>(1, 0) = mu * rhoN * zh;
    }
  }
  for (int i = 0; i < 2; ++i) {  // zero tangent row: equation P_T = 0
    if (!zt[i]) continue;
    phi[1 + i] = P[1 + i];
    A.row(1 + i).setZero();
    A.col(1 + i).setZero();
    B.row(1 + i).setZero();
    B.col(1 + i).setZero();
    A(1 + i, 1 + i) = 1;
  }
  if (A3) *A3 = A;
  if (B3) *B3 = B;
}

// phi(P) for all blocks (U = W P + b given); returns 0.5 |phi|^2. rho: per-row
// scaling 1/W(i, i) (frictional tangents: 1/mean of the two). zeroRow: P_i = 0.
double acResidual(const std::vector<ProblemBlock>& blocks, const double* P, const double* U,
                  const double* rho, const char* zeroRow, double* phi) {
  double s = 0;
  for (const ProblemBlock& bl : blocks) {
    const int r = bl.row;
    switch (bl.kind) {
      case BlockKind::Frictional:
        if (zeroRow[r]) {
          for (int i = 0; i < 3; ++i) phi[r + i] = P[r + i];
        } else {
          const bool zt[2] = {zeroRow[r + 1] != 0, zeroRow[r + 2] != 0};
          acFrictional(P + r, U + r, bl.mu, rho[r], rho[r + 1], zt, phi + r, nullptr, nullptr);
        }
        break;
      case BlockKind::Frictionless:
        phi[r] = zeroRow[r] || P[r] - rho[r] * U[r] <= 0 ? P[r] : rho[r] * U[r];
        break;
      case BlockKind::Bilateral:
        for (int i = r; i < r + bl.size; ++i) phi[i] = zeroRow[i] ? P[i] : rho[i] * U[i];
        break;
    }
    for (int i = r; i < r + bl.size; ++i) s += phi[i] * phi[i];
  }
  return 0.5 * s;
}

// J = A + B (W + delta diag(W)) for the current P, U (one element of the
// generalised Jacobian of the problem with W regularised: nonsingular on
// hyperstatic sets, and the same roots).
template <class MatJ>
void acJacobian(const Eigen::Ref<const Eigen::MatrixXd>& W, const std::vector<ProblemBlock>& blocks,
                const double* P, const double* U, const double* rho, const char* zeroRow,
                double delta, MatJ& J) {
  const int m = int(J.rows());
  J.setZero();
  double phi3[3];
  for (const ProblemBlock& bl : blocks) {
    const int r = bl.row;
    if (bl.kind == BlockKind::Frictional && !zeroRow[r]) {
      const bool zt[2] = {zeroRow[r + 1] != 0, zeroRow[r + 2] != 0};
      Matrix3d A, B;
      acFrictional(P + r, U + r, bl.mu, rho[r], rho[r + 1], zt, phi3, &A, &B);
      J.template middleRows<3>(r).noalias() = B * W.block(r, 0, 3, m);
      J.template block<3, 3>(r, r) += A;
      for (int c = 0; c < 3; ++c) J.col(r + c).template segment<3>(r) += (delta * W(r + c, r + c)) * B.col(c);
      continue;
    }
    for (int i = r; i < r + bl.size; ++i) {
      bool active = !zeroRow[i];
      if (bl.kind == BlockKind::Frictionless) active = active && P[i] - rho[i] * U[i] > 0;
      if (bl.kind == BlockKind::Frictional) active = false;  // zero normal row: P = 0
      if (active) {
        J.row(i) = rho[i] * W.row(i).head(m);
        J(i, i) += delta * rho[i] * W(i, i);
      } else {
        J(i, i) = 1;
      }
    }
  }
}

}  // namespace

double solverError(const Eigen::Ref<const Eigen::MatrixXd>& W,
                   const Eigen::Ref<const Eigen::VectorXd>& b,
                   const Eigen::Ref<const Eigen::VectorXd>& P,
                   const std::vector<ProblemBlock>& blocks) {
  const int m = problemRows(blocks);
  if (m == 0) return 0;
  if (!validBlocks(blocks, std::min({W.rows(), W.cols(), b.size(), P.size()}))) return INFINITY;
  double s = 0;
  for (const ProblemBlock& bl : blocks) {
    // Row block of U = W P + b, fixed-capacity result: no allocation.
    BVec u = b.segment(bl.row, bl.size);
    u.noalias() += W.block(bl.row, 0, bl.size, m) * P.head(m);
    s += blockError2(bl, P.data() + bl.row, u.data());
  }
  const double bnorm = b.head(m).norm();
  if (!std::isfinite(bnorm)) return INFINITY;
  const double e = std::sqrt(s) / std::max(1.0, bnorm);
  return std::isfinite(e) ? e : INFINITY;
}

SolverReport FrictionContactSolver::solve(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                          const Eigen::Ref<const Eigen::VectorXd>& b,
                                          const std::vector<ProblemBlock>& blocks,
                                          const SolverOptions& options,
                                          Eigen::Ref<Eigen::VectorXd> P) {
  SolverReport rep;
  rep.residual = INFINITY;
  const int m = problemRows(blocks);
  if (m == 0) {
    rep.residual = 0;
    rep.converged = true;
    return rep;
  }
  if (!validBlocks(blocks, std::min({W.rows(), W.cols(), b.size(), P.size()}))) return rep;

  // One frictional contact (a pin in its hole, a body on a plane): the local
  // solver's answer is the problem's. Checked on the problem's own error; the
  // general path below takes over (from this answer) if it falls short.
  if (blocks.size() == 1 && blocks[0].kind == BlockKind::Frictional && blocks[0].row == 0 &&
      W.topLeftCorner<3, 3>().allFinite() && b.head<3>().allFinite()) {
    const Matrix3d Wl = W.topLeftCorner<3, 3>();
    const Vector3d bl = b.head<3>();
    if (Wl.diagonal().minCoeff() > kRelZeroDiag * Wl.diagonal().maxCoeff()) {
      Vector3d Pl = P.head<3>().allFinite() ? Vector3d(P.head<3>()) : Vector3d::Zero();
      solveLocalFrictional(Wl, bl, blocks[0].mu, std::max(1e-14, 1e-2 * options.tolerance), Pl);
      const Vector3d Ul = Wl * Pl + bl;
      const double err = errorFromU(blocks, Pl.data(), Ul.data(), bl.norm());
      if (err <= options.tolerance) {
        P.head<3>() = Pl;
        rep.residual = err;
        rep.converged = true;
        rep.sweeps = 1;
        rep.iterations = 1;
        return rep;
      }
    }
  }

  // Non-finite input: report, never loop.
  double maxDiag = 0;
  for (int i = 0; i < m; ++i) {
    if (!std::isfinite(W(i, i)) || !std::isfinite(b(i))) return rep;
    maxDiag = std::max(maxDiag, W(i, i));
  }
  if (!W.topLeftCorner(m, m).allFinite()) return rep;
  if (!P.head(m).allFinite()) P.head(m).setZero();  // a poisoned warm start is dropped
  const double zeroDiag = kRelZeroDiag * maxDiag;

  // Workspace: grows to the largest problem seen, never shrinks.
  if (m > maxRows_) {
    maxRows_ = m;
    U_.resize(m);
    Pbest_.resize(m);
    Pstart_.resize(m);
    phi_.resize(m);
    d_.resize(m);
    Wd_.resize(m);
    Pt_.resize(m);
    Ut_.resize(m);
    phiT_.resize(m);
    rho_.resize(m);
    piv_.resize(m);
    zeroRow_.resize(m);
    eqRows_.reserve(m);
  }
  const bool newtonAllowed = options.method != SolverMethod::NSGS && m <= kNewtonMaxRows;
  if (newtonAllowed && J_.rows() < m) {  // not for NSGS only; capped at the Newton size
    const int cap = std::min(maxRows_, kNewtonMaxRows);
    J_.resize(cap, cap);
  }

  // Zero rows (planar scenes) keep P = 0; per-row scaling of the Newton function.
  char* zeroRow = zeroRow_.data();
  double* rho = rho_.data();
  for (int i = 0; i < m; ++i) zeroRow[i] = !(W(i, i) > zeroDiag);
  for (const ProblemBlock& bl : blocks) {
    const int r = bl.row;
    for (int i = r; i < r + bl.size; ++i) {
      rho[i] = zeroRow[i] ? 1.0 : 1.0 / W(i, i);
      if (zeroRow[i] && bl.kind != BlockKind::Frictionless && (bl.kind == BlockKind::Bilateral || i > r))
        P(i) = 0;
    }
    if (bl.kind == BlockKind::Frictional) {
      const double wT = 0.5 * (W(r + 1, r + 1) + W(r + 2, r + 2));
      rho[r + 1] = rho[r + 2] = wT > zeroDiag ? 1.0 / wT : rho[r];
    }
  }

  // Equalities assembled: all bilateral rows in one block, factored once here.
  eqRows_.clear();
  double maxEqDiag = 0;
  for (const ProblemBlock& bl : blocks) {
    if (bl.kind != BlockKind::Bilateral) continue;
    for (int i = bl.row; i < bl.row + bl.size; ++i) {
      if (zeroRow[i]) continue;
      eqRows_.push_back(i);
      maxEqDiag = std::max(maxEqDiag, W(i, i));
    }
  }
  const int ne = int(eqRows_.size());
  if (ne > maxEq_) {
    maxEq_ = ne;
    eqL_.resize(ne, ne);
    eqRhs_.resize(2 * ne);
    eqPerm_.resize(ne);
  }
  if (ne > 0) {
    for (int c = 0; c < ne; ++c)
      for (int r = 0; r < ne; ++r) eqL_(r, c) = W(eqRows_[r], eqRows_[c]);
    eqRank_ = pivotedCholesky(eqL_.data(), int(eqL_.rows()), ne, kEqDrop * maxEqDiag, eqPerm_.data());
  }

  auto U = U_.head(m);
  const auto Wm = W.topLeftCorner(m, m);
  const auto refreshU = [&] {
    U.noalias() = Wm * P.head(m);
    U += b.head(m);
  };
  refreshU();
  const double bnorm = b.head(m).norm();
  const double localTol = std::max(1e-14, 1e-2 * options.tolerance);

  double err = errorFromU(blocks, P.data(), U.data(), bnorm);
  rep.residual = err;
  if (err <= options.tolerance) {
    rep.converged = true;
    return rep;
  }
  double bestAll = err;  // best NSGS iterate (returned if not converged)
  Pbest_.head(m) = P.head(m);
  const auto offerBest = [&] {
    if (err < bestAll) {
      bestAll = err;
      Pbest_.head(m) = P.head(m);
    }
  };

  // Exact solve of the equality block for the current U.
  const auto solveEqualities = [&] {
    if (ne == 0) return;
    double* x = eqRhs_.data();
    for (int a = 0; a < ne; ++a) x[a] = -U(eqRows_[a]);
    pivotedCholeskySolve(eqL_.data(), int(eqL_.rows()), ne, eqRank_, eqPerm_.data(), x, x + ne);
    for (int a = 0; a < ne; ++a) {
      if (x[a] == 0) continue;
      U += x[a] * Wm.col(eqRows_[a]);
      P(eqRows_[a]) += x[a];
    }
  };

  // Plain NSGS can stall on hyperstatic sets (W singular). If the error has not
  // halved over kStallWindow sweeps, switch to proximal NSGS: every contact
  // problem gets + eps (P - P_previous) (eps = sigma * its mean diagonal), a
  // damping whose fixed points are the same solutions.
  double sigma = 0;
  double stallErr = err;
  int stallIt = 0;

  // NSGS sweeps until converged or `until` sweeps in all. False on non-finite.
  const auto nsgs = [&](int until) {
    while (rep.sweeps < until) {
      bool eqDone = false;
      for (const ProblemBlock& bl : blocks) {
        const int r = bl.row;
        switch (bl.kind) {
          case BlockKind::Frictional: {
            Matrix3d Wl = W.block<3, 3>(r, r);
            const Vector3d Pold = P.segment<3>(r);
            Vector3d bl3 = U.segment<3>(r) - Wl * Pold;
            if (sigma > 0) {  // proximal term eps |P - Pold|^2 / 2
              const double eps = sigma * Wl.trace() / 3;
              Wl.diagonal().array() += eps;
              bl3 -= eps * Pold;
            }
            Vector3d Pnew = Pold;
            solveLocalFrictional(Wl, bl3, bl.mu, localTol, Pnew);
            const Vector3d dP = Pnew - Pold;
            if (!dP.isZero(0)) {
              U.noalias() += Wm.middleCols<3>(r) * dP;
              P.segment<3>(r) = Pnew;
            }
            break;
          }
          case BlockKind::Frictionless: {
            const double w = W(r, r);
            const double pn = w > zeroDiag ? std::max(0.0, P(r) - U(r) / ((1 + sigma) * w)) : 0.0;
            const double dP = pn - P(r);
            if (dP != 0) {
              U += dP * Wm.col(r);
              P(r) = pn;
            }
            break;
          }
          case BlockKind::Bilateral:
            if (!eqDone) solveEqualities();  // all equalities at the first one
            eqDone = true;
            break;
        }
      }
      const int it = ++rep.sweeps;
      if (it % kRefreshEvery == 0) refreshU();
      err = errorFromU(blocks, P.data(), U.data(), bnorm);
      if (!std::isfinite(err)) return false;
      if (err < 0.5 * stallErr) {
        stallErr = err;
        stallIt = it;
      } else if (sigma == 0 && it - stallIt >= kStallWindow) {
        sigma = kProximalSigma;
      }
      if (err <= options.tolerance) {
        refreshU();  // confirm on the exact U before declaring convergence
        err = errorFromU(blocks, P.data(), U.data(), bnorm);
        if (err <= options.tolerance) {
          rep.converged = true;
          break;
        }
      }
      offerBest();
    }
    offerBest();
    return true;
  };

  // Global semismooth Newton on the Alart-Curnier function, non-monotone Armijo
  // line search on 0.5|phi|^2. The Jacobian is that of the problem with
  // W + delta diag(W); delta grows when the step fails (Levenberg-like). False
  // if it gives up (the caller then continues NSGS from the best iterate).
  const auto newton = [&] {
    auto J = J_.topLeftCorner(m, m);
    const int ld = int(J_.rows());
    const int maxIt =
        std::min(kNewtonMaxIterations, options.max_iterations - rep.newton_iterations);
    Pstart_.head(m) = P.head(m);
    refreshU();
    double f = acResidual(blocks, P.data(), U.data(), rho, zeroRow, phi_.data());
    double hist[kNonMonotone];
    for (double& h : hist) h = f;
    double delta = kNewtonDelta0;
    // Iterates are kept within kNewtonMaxImpulse times the impulse scale of
    // the problem (what stops each row alone, or the start): on problems
    // without a solution (jamming, b outside range(W) in position projection)
    // the Alart-Curnier residual decreases towards infinity along near-null
    // directions of W, with impulses that change nothing but round-off.
    double impulseScale = P.head(m).cwiseAbs().maxCoeff();
    for (int i = 0; i < m; ++i)
      if (!zeroRow[i]) impulseScale = std::max(impulseScale, std::abs(b(i)) / W(i, i));
    const double impulseCap = kNewtonMaxImpulse * impulseScale;
    double progressErr = err;
    int noProgress = 0;
    for (int it = 0; it < maxIt; ++it) {
      ++rep.newton_iterations;
      acJacobian(W, blocks, P.data(), U.data(), rho, zeroRow, delta, J);
      bool stepped = false;
      double t = 1;
      if (luFactor(J_.data(), ld, m, piv_.data())) {
        d_.head(m) = -phi_.head(m);
        luSolve(J_.data(), ld, m, piv_.data(), d_.data());
        if (d_.head(m).allFinite()) {
          Wd_.head(m).noalias() = Wm * d_.head(m);
          double fref = 0;
          for (double h : hist) fref = std::max(fref, h);
          for (int ls = 0; ls < kLineSearchSteps; ++ls, t *= 0.5) {
            Pt_.head(m) = P.head(m) + t * d_.head(m);
            if (Pt_.head(m).cwiseAbs().maxCoeff() > impulseCap) continue;
            Ut_.head(m) = U + t * Wd_.head(m);
            const double ft = acResidual(blocks, Pt_.data(), Ut_.data(), rho, zeroRow, phiT_.data());
            if (ft <= fref - 2e-4 * t * f) {
              stepped = true;
              break;
            }
          }
        }
      }
      if (!stepped) {
        if (delta >= kNewtonDeltaMax) return false;
        delta *= 1e3;
        continue;
      }
      // A short step means a poor model (kink, near-singular J): regularise
      // more (Levenberg-like); a full step lets delta relax back.
      delta = t < kNewtonShortStep ? std::min(kNewtonDeltaMax, 1e3 * delta)
                                   : std::max(kNewtonDelta0, 1e-2 * delta);
      P.head(m) = Pt_.head(m);
      refreshU();
      f = acResidual(blocks, P.data(), U.data(), rho, zeroRow, phi_.data());
      for (int h = kNonMonotone - 1; h > 0; --h) hist[h] = hist[h - 1];
      hist[0] = f;
      err = errorFromU(blocks, P.data(), U.data(), bnorm);
      if (!std::isfinite(err)) return false;
      if (err <= options.tolerance) {
        rep.converged = true;
        return true;
      }
      if (err < 0.5 * progressErr) {
        progressErr = err;
        noProgress = 0;
      } else if (++noProgress >= kNewtonStall) {
        return false;
      }
    }
    return false;
  };

  // Back to NSGS where Newton started after a failed Newton: its iterates may
  // have a lower error yet huge impulses along near-null directions of W
  // (problems without a solution), so a failure leaves the NSGS path as is.
  const auto resumeNsgs = [&] {
    P.head(m) = Pstart_.head(m);
    refreshU();
    err = errorFromU(blocks, P.data(), U.data(), bnorm);
    stallErr = err;
    stallIt = rep.sweeps;
  };

  int attempts = 0;
  const auto tryNewton = [&] {
    ++attempts;
    if (!newton()) resumeNsgs();
  };
  bool ok = true;
  if (newtonAllowed && (options.method == SolverMethod::Newton || m <= kNewtonSmallRows)) {
    ok = nsgs(1);
    if (ok && !rep.converged) tryNewton();
  } else if (newtonAllowed) {
    // Switch when the observed NSGS rate predicts more sweeps than Newton costs
    // (checked after kSwitchSweeps, then at doubling sweep counts).
    const double newtonCost = kNewtonCostIterations * (1 + m / kLuRowsPerSweep);
    int check = kSwitchSweeps;
    double errRef = err;
    int itRef = 0;
    while (ok && !rep.converged && attempts == 0 && rep.sweeps < options.max_iterations) {
      ok = nsgs(std::min(check, options.max_iterations));
      if (!ok || rep.converged || rep.sweeps >= options.max_iterations) break;
      const double rate = std::pow(err / errRef, 1.0 / (rep.sweeps - itRef));
      const double remaining =
          rate < 1 ? std::log(options.tolerance / err) / std::log(rate) : INFINITY;
      if (remaining > newtonCost) tryNewton();
      errRef = err;
      itRef = rep.sweeps;
      check *= 2;
    }
  }
  // NSGS to the end; after a failed Newton, a few sweeps move the iterate to
  // another start for a new Newton attempt.
  while (ok && !rep.converged && rep.sweeps < options.max_iterations) {
    const bool retry = attempts > 0 && attempts < kNewtonAttempts;
    ok = nsgs(retry ? std::min(rep.sweeps + kSwitchSweeps, options.max_iterations)
                    : options.max_iterations);
    if (ok && !rep.converged && retry && rep.sweeps < options.max_iterations) tryNewton();
  }

  rep.iterations = rep.sweeps + rep.newton_iterations;
  if (!ok) {
    rep.residual = INFINITY;
    return rep;
  }
  if (!rep.converged) {  // the best iterate, its error on the exact U
    if (bestAll < err) P.head(m) = Pbest_.head(m);
    refreshU();
    err = errorFromU(blocks, P.data(), U.data(), bnorm);
  }
  rep.residual = err;
  return rep;
}

}  // namespace nscd
