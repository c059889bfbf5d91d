// Primal-dual interior point for the cone QP of cone_interior_point.hpp.
// Optimality: z = Q y + q, y and z in K (self-dual), y o z = 0 block by block
// (o: the Jordan product of the second-order cone, u o v = (u.v, u0 v1 + v0 u1);
// on a half-line the plain product). Each iteration linearises
//   Q dy - dz = -(Q y + q - z),   lambda o (W^-1 dy + W dz) = r,
// with W the Nesterov-Todd scaling (W z = W^-1 y = lambda), eliminates
// dz = W^-1 (lambda \ r) - W^-2 dy and solves (Q + W^-2) dy = ... by LU;
// r is first the affine (predictor) right-hand side -lambda o lambda, then the
// corrector's with Mehrotra's centring (sigma = (gap after the affine step / gap)^3).
#include "cone_interior_point.hpp"

#include <algorithm>
#include <cmath>

#include "dense_kernels.hpp"

namespace nscd {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr int kMaxIterations = 50;
constexpr double kResidualTol = 1e-11;
constexpr double kGapTol = 1e-13;
constexpr double kStepFraction = 0.99;  // of the step to the cone's boundary
constexpr double kRegularisation = 1e-13;  // added to the scaled system's diagonal (Q singular)
// Tikhonov term added to the scaled Q: the problem's optimal set is unbounded when
// a direction of zero curvature stays inside the cones (a hyperstatic set squeezed
// by opposed contacts), and the interior-point iterates then run off along it
// towards its analytic centre, with contact forces orders of magnitude above the
// load (docs/solver.md). With it the answer is the problem's nearest to y = 0,
// bounded, the squeeze left out.
constexpr double kTikhonov = 1e-8;

double lorentzDet(const double* u) { return u[0] * u[0] - u[1] * u[1] - u[2] * u[2]; }

// Nesterov-Todd scaling of a second-order cone pair (y, z), both interior.
bool scaling3(const double* y, const double* z, Matrix3d& W, Matrix3d& Winv) {
  const double dy = lorentzDet(y), dz = lorentzDet(z);
  if (!(dy > 0 && dz > 0)) return false;
  const double sy = std::sqrt(dy), sz = std::sqrt(dz);
  const Vector3d yb(y[0] / sy, y[1] / sy, y[2] / sy), zb(z[0] / sz, z[1] / sz, z[2] / sz);
  const double gamma = std::sqrt(0.5 * (1 + yb.dot(zb)));
  // w = (yb + J zb) / (2 gamma), J = diag(1, -1, -1): the scaling point.
  const Vector3d w((yb(0) + zb(0)) / (2 * gamma), (yb(1) - zb(1)) / (2 * gamma),
                   (yb(2) - zb(2)) / (2 * gamma));
  const double eta = std::sqrt(sy / sz);
  Matrix3d H;
  H(0, 0) = w(0);
  H(0, 1) = H(1, 0) = w(1);
  H(0, 2) = H(2, 0) = w(2);
  const double c = 1 / (1 + w(0));
  H(1, 1) = 1 + w(1) * w(1) * c;
  H(2, 2) = 1 + w(2) * w(2) * c;
  H(1, 2) = H(2, 1) = w(1) * w(2) * c;
  W = eta * H;
  // H^-1 = J H J.
  Winv = H / eta;
  Winv(0, 1) = Winv(1, 0) = -H(0, 1) / eta;
  Winv(0, 2) = Winv(2, 0) = -H(0, 2) / eta;
  return W.allFinite() && Winv.allFinite();
}

// u o v on a block of `size` rows (3: second-order cone, 1: half-line).
void jordanProduct(int size, const double* u, const double* v, double* out) {
  if (size == 1) {
    out[0] = u[0] * v[0];
    return;
  }
  out[0] = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
  out[1] = u[0] * v[1] + v[0] * u[1];
  out[2] = u[0] * v[2] + v[0] * u[2];
}

// x with u o x = v (u interior).
void jordanSolve(int size, const double* u, const double* v, double* x) {
  if (size == 1) {
    x[0] = v[0] / u[0];
    return;
  }
  const double d = lorentzDet(u);
  const double u1v1 = u[1] * v[1] + u[2] * v[2];
  x[0] = (u[0] * v[0] - u1v1) / d;
  for (int i = 1; i < 3; ++i) x[i] = (-u[i] * v[0] + (d / u[0]) * v[i] + u[i] * u1v1 / u[0]) / d;
}

// The largest t >= 0 with u + t d in the block's cone (u interior); INFINITY if unbounded.
double stepToBoundary(int size, const double* u, const double* d) {
  if (size == 1) return d[0] < 0 ? -u[0] / d[0] : INFINITY;
  double t = INFINITY;
  if (d[0] < 0) t = -u[0] / d[0];
  // det(u + t d) = c + 2 b t + a t^2 >= 0.
  const double a = lorentzDet(d);
  const double bq = u[0] * d[0] - u[1] * d[1] - u[2] * d[2];
  const double c = lorentzDet(u);
  if (std::abs(a) < 1e-300) {
    if (bq < 0) t = std::min(t, -c / (2 * bq));
  } else {
    const double disc = bq * bq - a * c;
    if (disc >= 0) {
      const double r = std::sqrt(disc);
      for (const double root : {(-bq - r) / a, (-bq + r) / a})
        if (root > 0) t = std::min(t, root);
    }
  }
  return t;
}

void grow(ConeQpBuffers& qp, int n, int cones) {
  if (n > qp.maxRows) {
    qp.maxRows = n;
    qp.Qs.resize(n, n);
    qp.K.resize(n, n);
    for (Eigen::VectorXd* v : {&qp.qs, &qp.y, &qp.z, &qp.rd, &qp.lam, &qp.dvec, &qp.rhs, &qp.dy, &qp.dz,
                               &qp.dya, &qp.dza, &qp.rc, &qp.ylast, &qp.zlast})
      v->resize(n);
    qp.piv.resize(n);
  }
  if (int(qp.W.size()) < cones) {
    qp.W.resize(cones);
    qp.Winv.resize(cones);
  }
}

// One solve's views of the buffers: the scaled problem (Qs, qs), the iterate
// (y, z), the residual and the buffers of the Newton system.
struct Ipm {
  Ipm(ConeQpBuffers& qp_, const std::vector<ConeBlock>& blocks_, int n_)
      : qp(qp_), blocks(blocks_), n(n_), ld(int(qp_.K.rows())), Qs(qp_.Qs.topLeftCorner(n_, n_)),
        qs(qp_.qs.head(n_)), y(qp_.y.head(n_)), z(qp_.z.head(n_)), rd(qp_.rd.head(n_)),
        lam(qp_.lam.head(n_)), dvec(qp_.dvec.head(n_)), rhs(qp_.rhs.head(n_)), rc(qp_.rc.head(n_)) {}
  ConeQpBuffers& qp;
  const std::vector<ConeBlock>& blocks;
  const int n, ld;
  Eigen::Block<Eigen::MatrixXd> Qs;
  Eigen::VectorBlock<Eigen::VectorXd> qs, y, z, rd, lam, dvec, rhs, rc;

  // The Nesterov-Todd scaling at (y, z), lambda, and the system Q + W^-2
  // factored in qp.K. False if an iterate left its cone or the LU failed.
  bool scaleAndFactor() {
    auto K = qp.K.topLeftCorner(n, n);
    K = Qs;
    bool ok = true;
    for (size_t k = 0; k < blocks.size() && ok; ++k) {
      const ConeBlock& bl = blocks[k];
      if (bl.kind == ConeBlock::Free) continue;
      if (bl.size == 3) {
        ok = scaling3(y.data() + bl.row, z.data() + bl.row, qp.W[k], qp.Winv[k]);
        lam.segment<3>(bl.row) = qp.W[k] * z.segment<3>(bl.row);
        K.block<3, 3>(bl.row, bl.row) += qp.Winv[k] * qp.Winv[k];
      } else {
        ok = y(bl.row) > 0 && z(bl.row) > 0;
        const double w = std::sqrt(y(bl.row) / z(bl.row));
        qp.W[k](0, 0) = w;
        qp.Winv[k](0, 0) = 1 / w;
        lam(bl.row) = std::sqrt(y(bl.row) * z(bl.row));
        K(bl.row, bl.row) += 1 / (w * w);
      }
    }
    if (!ok) return false;
    K.diagonal().array() += kRegularisation;
    return luFactor(qp.K.data(), ld, n, qp.piv.data());
  }

  // One Newton direction for the complementarity right-hand side rc.
  void direction(Eigen::VectorXd& dy, Eigen::VectorXd& dz) {
    rhs = -rd;
    for (size_t k = 0; k < blocks.size(); ++k) {
      const ConeBlock& bl = blocks[k];
      if (bl.kind == ConeBlock::Free) continue;
      jordanSolve(bl.size, lam.data() + bl.row, rc.data() + bl.row, dvec.data() + bl.row);
      if (bl.size == 3) rhs.segment<3>(bl.row) += qp.Winv[k] * dvec.segment<3>(bl.row);
      else rhs(bl.row) += qp.Winv[k](0, 0) * dvec(bl.row);
    }
    dy.head(n) = rhs;
    luSolve(qp.K.data(), ld, n, qp.piv.data(), dy.data());
    for (size_t k = 0; k < blocks.size(); ++k) {
      const ConeBlock& bl = blocks[k];
      if (bl.kind == ConeBlock::Free) {
        dz.segment(bl.row, bl.size).setZero();
      } else if (bl.size == 3) {
        dz.segment<3>(bl.row) = qp.Winv[k] * (dvec.segment<3>(bl.row) - qp.Winv[k] * dy.segment<3>(bl.row));
      } else {
        const double wi = qp.Winv[k](0, 0);
        dz(bl.row) = wi * (dvec(bl.row) - wi * dy(bl.row));
      }
    }
  }

  // The largest step along (dy, dz) that keeps y and z in their cones.
  double maxStep(const Eigen::VectorXd& dy, const Eigen::VectorXd& dz) const {
    double t = INFINITY;
    for (const ConeBlock& bl : blocks) {
      if (bl.kind == ConeBlock::Free) continue;
      t = std::min(t, stepToBoundary(bl.size, y.data() + bl.row, dy.data() + bl.row));
      t = std::min(t, stepToBoundary(bl.size, z.data() + bl.row, dz.data() + bl.row));
    }
    return t;
  }

  // The predictor's right-hand side -lambda o lambda.
  void predictorRhs() {
    for (const ConeBlock& bl : blocks) {
      if (bl.kind == ConeBlock::Free) continue;
      jordanProduct(bl.size, lam.data() + bl.row, lam.data() + bl.row, rc.data() + bl.row);
      rc.segment(bl.row, bl.size) *= -1;
    }
  }

  // The corrector's: -lambda o lambda - (W^-1 dy_a) o (W dz_a) + centring e.
  void correctorRhs(double centring) {
    for (size_t k = 0; k < blocks.size(); ++k) {
      const ConeBlock& bl = blocks[k];
      if (bl.kind == ConeBlock::Free) continue;
      double a[3] = {0, 0, 0}, c[3] = {0, 0, 0}, prod[3];
      if (bl.size == 3) {
        const Vector3d wa = qp.Winv[k] * qp.dya.segment<3>(bl.row);
        const Vector3d wc = qp.W[k] * qp.dza.segment<3>(bl.row);
        for (int i = 0; i < 3; ++i) a[i] = wa(i), c[i] = wc(i);
      } else {
        a[0] = qp.Winv[k](0, 0) * qp.dya(bl.row);
        c[0] = qp.W[k](0, 0) * qp.dza(bl.row);
      }
      jordanProduct(bl.size, lam.data() + bl.row, lam.data() + bl.row, rc.data() + bl.row);
      jordanProduct(bl.size, a, c, prod);
      for (int i = 0; i < bl.size; ++i) rc(bl.row + i) = -rc(bl.row + i) - prod[i];
      rc(bl.row) += centring;
    }
  }
};

}  // namespace

ConeQpReport solveConeQp(const Eigen::Ref<const Eigen::MatrixXd>& Q,
                         const Eigen::Ref<const Eigen::VectorXd>& q,
                         const std::vector<ConeBlock>& blocks, int n, ConeQpBuffers& qp,
                         Eigen::Ref<Eigen::VectorXd> yOut) {
  ConeQpReport rep;
  int cones = 0;
  for (const ConeBlock& bl : blocks) cones += bl.kind != ConeBlock::Free;
  grow(qp, n, int(blocks.size()));
  // Scaled to a unit largest diagonal of Q and a unit largest |q_i|.
  double qScale = q.head(n).cwiseAbs().maxCoeff();
  double qDiag = Q.topLeftCorner(n, n).diagonal().cwiseAbs().maxCoeff();
  if (!(qScale > 0) || !(qDiag > 0) || !std::isfinite(qScale) || !std::isfinite(qDiag)) {
    yOut.head(n).setZero();
    rep.converged = qScale == 0;
    return rep;
  }
  Ipm s(qp, blocks, n);
  s.Qs = Q.topLeftCorner(n, n) / qDiag;
  s.Qs.diagonal().array() += kTikhonov;
  s.qs = q.head(n) / qScale;
  const double qsNorm = s.qs.norm();
  s.y.setZero();
  s.z.setZero();
  for (const ConeBlock& bl : blocks)
    if (bl.kind != ConeBlock::Free) s.y(bl.row) = s.z(bl.row) = 1;  // the cone's identity e
  qp.ylast.head(n) = s.y;
  for (int it = 0; it < kMaxIterations; ++it) {
    s.rd.noalias() = s.Qs * s.y;
    s.rd += s.qs - s.z;  // z stays 0 on free rows: they carry no dual variable
    const double gap = cones > 0 ? s.y.dot(s.z) / cones : 0;
    if (!(std::isfinite(gap) && s.rd.allFinite())) {
      s.y = qp.ylast.head(n);
      break;
    }
    qp.ylast.head(n) = s.y;
    rep.iterations = it;
    if (s.rd.norm() <= kResidualTol * (1 + qsNorm) && gap <= kGapTol * (1 + std::abs(s.y.dot(s.qs)))) {
      rep.converged = true;
      break;
    }
    if (!s.scaleAndFactor()) break;
    s.predictorRhs();
    s.direction(qp.dya, qp.dza);
    const double ta = std::min(1.0, s.maxStep(qp.dya, qp.dza));
    const double gapAffine = (s.y + ta * qp.dya.head(n)).dot(s.z + ta * qp.dza.head(n)) / std::max(1, cones);
    const double sigma = std::pow(std::max(0.0, gapAffine) / std::max(gap, 1e-300), 3);  // Mehrotra
    s.correctorRhs(sigma * gap);
    s.direction(qp.dy, qp.dz);
    const double t = std::min(1.0, kStepFraction * s.maxStep(qp.dy, qp.dz));
    if (!(t > 0) || !qp.dy.head(n).allFinite() || !qp.dz.head(n).allFinite()) break;
    s.y += t * qp.dy.head(n);
    s.z += t * qp.dz.head(n);
    rep.iterations = it + 1;
  }
  yOut.head(n) = s.y * (qScale / qDiag);
  return rep;
}

}  // namespace nscd
