// Nonsmooth Gauss-Seidel over the blocks of the one-step contact problem,
// with the running local velocities U = W P + b updated incrementally (O(m)
// per block), an exact local solve per block, and the Siconos-style error.
#include "nscd_sim/friction_contact_solver.hpp"

#include <algorithm>
#include <cmath>

namespace nscd {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

constexpr int kMaxBilateral = 6;
using BVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxBilateral, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

constexpr double kRelZeroDiag = 1e-13;  // a W diagonal below this * max diagonal is a zero row
constexpr int kRefreshEvery = 16;       // recompute U = W P + b exactly this often (round-off)
constexpr int kStallWindow = 100;       // sweeps without halving the error = stalled
constexpr double kProximalSigma = 0.1;  // proximal weight relative to the block diagonal

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

// Pseudo-inverse of a symmetric PSD 6x6 by cyclic Jacobi rotations (exact
// eigenvectors, no allocation); eigenvalues below 1e-12 * max are dropped.
Mat6 pseudoInverseSym(Mat6 A) {
  Mat6 V = Mat6::Identity();
  for (int sweep = 0; sweep < 30; ++sweep) {
    double off = 0;
    for (int p = 0; p < 6; ++p)
      for (int q = p + 1; q < 6; ++q) off += A(p, q) * A(p, q);
    if (!(off > 1e-32 * A.diagonal().squaredNorm())) break;
    for (int p = 0; p < 6; ++p) {
      for (int q = p + 1; q < 6; ++q) {
        if (A(p, q) == 0) continue;
        const double theta = (A(q, q) - A(p, p)) / (2 * A(p, q));
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 6; ++k) {  // A <- A J
          const double akp = A(k, p), akq = A(k, q);
          A(k, p) = c * akp - s * akq;
          A(k, q) = s * akp + c * akq;
        }
        for (int k = 0; k < 6; ++k) {  // A <- J^T A
          const double apk = A(p, k), aqk = A(q, k);
          A(p, k) = c * apk - s * aqk;
          A(q, k) = s * apk + c * aqk;
        }
        for (int k = 0; k < 6; ++k) {
          const double vkp = V(k, p), vkq = V(k, q);
          V(k, p) = c * vkp - s * vkq;
          V(k, q) = s * vkp + c * vkq;
        }
      }
    }
  }
  const double cut = 1e-12 * A.diagonal().cwiseAbs().maxCoeff();
  Mat6 Vs = V;
  for (int c = 0; c < 6; ++c) Vs.col(c) *= A(c, c) > cut ? 1.0 / A(c, c) : 0.0;
  return Vs * V.transpose();
}

// Bilateral blocks: pseudo-inverse of (diagonal block + sigma * mean diagonal * I)
// over its nonzero rows (tiny eigenvalues dropped); zero rows get P = 0.
void bilateralInverses(const Eigen::Ref<const Eigen::MatrixXd>& W,
                       const std::vector<ProblemBlock>& blocks, double zeroDiag, double sigma,
                       Eigen::MatrixXd& blockInv, Eigen::Ref<Eigen::VectorXd> P) {
  int j = 0;
  for (const ProblemBlock& bl : blocks) {
    if (bl.kind != BlockKind::Bilateral) continue;
    const int k = bl.size;
    int idx[kMaxBilateral];
    int nk = 0;
    for (int i = 0; i < k; ++i) {
      if (W(bl.row + i, bl.row + i) > zeroDiag) {
        idx[nk++] = i;
      } else {
        P(bl.row + i) = 0;
      }
    }
    auto inv = blockInv.block(0, kMaxBilateral * j, k, k);
    inv.setZero();
    if (nk > 0) {
      // Fixed 6x6 (padded with decoupled diagonal entries, which leave the
      // pseudo-inverse of the nk x nk part unchanged): no allocation.
      Mat6 Wr = Mat6::Zero();
      double pad = 0, trace = 0;
      for (int r = 0; r < nk; ++r) {
        for (int c = 0; c < nk; ++c) Wr(r, c) = W(bl.row + idx[r], bl.row + idx[c]);
        pad = std::max(pad, Wr(r, r));
        trace += Wr(r, r);
      }
      for (int r = 0; r < nk; ++r) Wr(r, r) += sigma * trace / nk;
      for (int r = nk; r < kMaxBilateral; ++r) Wr(r, r) = pad;
      const Mat6 pinv = pseudoInverseSym(Wr);
      for (int r = 0; r < nk; ++r)
        for (int c = 0; c < nk; ++c) inv(idx[r], idx[c]) = pinv(r, c);
    }
    ++j;
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
  }
  int nBil = 0;
  for (const ProblemBlock& bl : blocks) nBil += bl.kind == BlockKind::Bilateral;
  if (nBil > maxBilateral_) {
    maxBilateral_ = nBil;
    blockInv_.resize(kMaxBilateral, kMaxBilateral * nBil);
  }

  bilateralInverses(W, blocks, zeroDiag, 0.0, blockInv_, P);

  auto U = U_.head(m);
  const auto Wm = W.topLeftCorner(m, m);
  U.noalias() = Wm * P.head(m);
  U += b.head(m);
  const double bnorm = b.head(m).norm();
  const double localTol = std::max(1e-14, 1e-2 * options.tolerance);

  double err = errorFromU(blocks, P.data(), U.data(), bnorm);
  rep.residual = err;
  if (err <= options.tolerance) {
    rep.converged = true;
    return rep;
  }

  // Plain NSGS can stall on hyperstatic sets (W singular). If the error has not
  // halved over kStallWindow sweeps, switch to proximal NSGS: every local
  // problem gets + eps (P - P_previous) (eps = sigma * its mean diagonal), a
  // damping whose fixed points are the same solutions.
  double sigma = 0;
  double bestErr = err;
  int bestIt = 0;

  for (int it = 1; it <= options.max_iterations; ++it) {
    int j = 0;
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
        case BlockKind::Bilateral: {
          const int k = bl.size;
          const BVec dP = -blockInv_.block(0, kMaxBilateral * j, k, k) * U.segment(r, k);
          U.noalias() += Wm.middleCols(r, k) * dP;
          P.segment(r, k) += dP;
          ++j;
          break;
        }
      }
    }
    rep.iterations = it;
    if (it % kRefreshEvery == 0) {
      U.noalias() = Wm * P.head(m);
      U += b.head(m);
    }
    err = errorFromU(blocks, P.data(), U.data(), bnorm);
    if (!std::isfinite(err)) {
      rep.residual = INFINITY;
      return rep;
    }
    if (err < 0.5 * bestErr) {
      bestErr = err;
      bestIt = it;
    } else if (sigma == 0 && it - bestIt >= kStallWindow) {
      sigma = kProximalSigma;
      bilateralInverses(W, blocks, zeroDiag, sigma, blockInv_, P);
    }
    if (err <= options.tolerance) {
      // Confirm on the exact U before declaring convergence.
      U.noalias() = Wm * P.head(m);
      U += b.head(m);
      err = errorFromU(blocks, P.data(), U.data(), bnorm);
      if (err <= options.tolerance) {
        rep.residual = err;
        rep.converged = true;
        return rep;
      }
    }
  }
  rep.residual = err;
  return rep;
}

}  // namespace nscd
