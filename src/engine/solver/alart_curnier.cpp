// The Alart-Curnier function and its generalised Jacobian (alart_curnier.hpp).
#include "alart_curnier.hpp"

#include <algorithm>
#include <cmath>

namespace nscd {

using Eigen::Matrix3d;
using Eigen::Vector3d;

void alartCurnierContact(const Vector3d& P, const Vector3d& U, double mu, double rhoN,
                         double rhoT, Vector3d& phi, Matrix3d* A3, Matrix3d* B3) {
  Matrix3d A = Matrix3d::Zero(), B = Matrix3d::Zero();
  const double tN = P(0) - rhoN * U(0);
  if (tN > 0) {
    phi(0) = rhoN * U(0);
    B(0, 0) = rhoN;
  } else {
    phi(0) = P(0);
    A(0, 0) = 1;
  }
  const double r = mu * std::max(0.0, tN);
  const Eigen::Vector2d z = P.tail<2>() - rhoT * U.tail<2>();
  const double nz = z.norm();
  if (nz <= r) {
    phi(1) = rhoT * U(1);
    phi(2) = rhoT * U(2);
    B(1, 1) = B(2, 2) = rhoT;
  } else {
    const Eigen::Vector2d zh = z / nz;
    phi(1) = P(1) - r * zh(0);
    phi(2) = P(2) - r * zh(1);
    if (A3 || B3) {
      const Eigen::Matrix2d G = (r / nz) * (Eigen::Matrix2d::Identity() - zh * zh.transpose());
      A.block<2, 2>(1, 1) = Eigen::Matrix2d::Identity() - G;
      B.block<2, 2>(1, 1) = rhoT * G;
      if (tN > 0) {
        A.block<2, 1>(1, 0) = -mu * zh;
        B.block<2, 1>(1, 0) = mu * rhoN * zh;
      }
    }
  }
  if (A3) *A3 = A;
  if (B3) *B3 = B;
}

namespace {

// One frictional block of the whole problem: zt[i] makes tangent row i a zero
// row (its P and U taken as 0, its equation P_T = 0).
void acFrictional(const double* P, const double* U, double mu, double rhoN, double rhoT,
                  const bool zt[2], double* phi, Matrix3d* A3, Matrix3d* B3) {
  const Vector3d p(P[0], zt[0] ? 0.0 : P[1], zt[1] ? 0.0 : P[2]);
  const Vector3d u(U[0], zt[0] ? 0.0 : U[1], zt[1] ? 0.0 : U[2]);
  Vector3d f;
  Matrix3d A, B;
  const bool jacobian = A3 || B3;
  alartCurnierContact(p, u, mu, rhoN, rhoT, f, jacobian ? &A : nullptr, jacobian ? &B : nullptr);
  for (int i = 0; i < 3; ++i) phi[i] = f(i);
  for (int i = 0; i < 2; ++i) {
    if (!zt[i]) continue;
    phi[1 + i] = P[1 + i];
    if (!jacobian) continue;
    A.row(1 + i).setZero();
    A.col(1 + i).setZero();
    B.row(1 + i).setZero();
    B.col(1 + i).setZero();
    A(1 + i, 1 + i) = 1;
  }
  if (A3) *A3 = A;
  if (B3) *B3 = B;
}

}  // namespace

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

namespace {

// Rows r..r+2 of B W into J, column by column: each entry B(i, 0) W(r, j) +
// B(i, 1) W(r + 1, j) + B(i, 2) W(r + 2, j), summed as Eigen's product of a
// 3 x 3 by a 3 x m block sums it on SSE2 (rows 0 and 1 in a packet,
// (t0 + t1) + t2; row 2 alone, t0 + (t1 + t2)): the same bits, signs of zero
// aside. A row sums its nonzero terms only (the normal row has B(0, 0) alone, a
// sticking tangent rhoT on the diagonal).
void frictionalRows(const Eigen::Ref<const Eigen::MatrixXd>& W, int r, const Matrix3d& B, int m,
                    Eigen::Ref<Eigen::MatrixXd> J) {
  const Eigen::Index ldj = J.outerStride(), ldw = W.outerStride();
  const double* w0 = W.data() + r;
  for (int i = 0; i < 3; ++i) {
    const double b0 = B(i, 0), b1 = B(i, 1), b2 = B(i, 2);
    const int terms = (b0 != 0) + (b1 != 0) + (b2 != 0);
    double* Jrow = J.data() + r + i;
    if (terms == 0) {
      for (int j = 0; j < m; ++j) Jrow[j * ldj] = 0;
    } else if (terms == 1) {
      const int k = b0 != 0 ? 0 : b1 != 0 ? 1 : 2;
      const double bk = B(i, k);
      for (int j = 0; j < m; ++j) Jrow[j * ldj] = bk * w0[k + j * ldw];
    } else if (i < 2) {
      for (int j = 0; j < m; ++j) {
        const double* wc = w0 + j * ldw;
        Jrow[j * ldj] = (b0 * wc[0] + b1 * wc[1]) + b2 * wc[2];
      }
    } else {
      for (int j = 0; j < m; ++j) {
        const double* wc = w0 + j * ldw;
        Jrow[j * ldj] = b0 * wc[0] + (b1 * wc[1] + b2 * wc[2]);
      }
    }
  }
}

}  // namespace

void acJacobian(const Eigen::Ref<const Eigen::MatrixXd>& W, const std::vector<ProblemBlock>& blocks,
                const double* P, const double* U, const double* rho, const char* zeroRow,
                double delta, Eigen::Ref<Eigen::MatrixXd> J) {
  const int m = int(J.rows());
  // Every row is written below when the blocks tile the m rows (they do for
  // the problems the engine builds); otherwise the rows between are zero.
  int tiled = 0;
  for (const ProblemBlock& bl : blocks) tiled += bl.size;
  if (tiled != m) J.setZero();
  double phi3[3];
  for (const ProblemBlock& bl : blocks) {
    const int r = bl.row;
    if (bl.kind == BlockKind::Frictional && !zeroRow[r]) {
      const bool zt[2] = {zeroRow[r + 1] != 0, zeroRow[r + 2] != 0};
      Matrix3d A, B;
      acFrictional(P + r, U + r, bl.mu, rho[r], rho[r + 1], zt, phi3, &A, &B);
      frictionalRows(W, r, B, m, J);
      J.block<3, 3>(r, r) += A;
      for (int c = 0; c < 3; ++c) J.col(r + c).segment<3>(r) += (delta * W(r + c, r + c)) * B.col(c);
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
        J.row(i).setZero();
        J(i, i) = 1;
      }
    }
  }
}

}  // namespace nscd
