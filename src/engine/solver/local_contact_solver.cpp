// The exact local problem of one 3D Coulomb contact: U = W P + b, Coulomb's law
// with coefficient mu. Stages, cheapest first: take-off, frictionless, sticking
// (all closed form), semismooth Newton on the Alart-Curnier function, a
// projected fixed point, and, last, the exact enumeration of sliding solutions
// over the slip direction (roots of a quartic), polished by Newton.
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <limits>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <Eigen/LU>

#include "alart_curnier.hpp"
#include "nscd_sim/friction_contact_solver.hpp"

namespace nscd {

using Eigen::Matrix2d;
using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

constexpr double kRelTiny = 1e-14;   // a normal diagonal below this * max diagonal is "zero"
constexpr double kRelZeroRow = 1e-20;  // tangent rows this small are decoupled (planar scenes)
constexpr int kNewtonIterations = 40;
constexpr int kLineSearchSteps = 40;
constexpr int kSlowSteps = 4;
constexpr int kFixedPointIterations = 300;

// The sticking stage's 3 x 3 LDLT, operation for operation as Eigen 3.4's
// LDLT<Matrix3d> computes it (LDLT.h: ldlt_inplace<Lower>::unblocked and
// _solve_impl_transposed): the first largest |diagonal| as pivot and its swap in the
// lower triangle, the updates (a single product subtracted as Eigen's runtime inner
// product adds -1 times it), the division by the pivot; then P b, the unit-lower
// solve, D's pseudo-inverse (|d| > DBL_MIN, else 0), the unit-upper solve, P^T.
// Without its set-up (L1 norm, sign, workspace): the same bits as Eigen, so the
// answer does not depend on which of the two factored it (LocalSolver.
// StickIsEigensLdltBitForBit; docs/solver.md). False where Eigen stops at a zero
// first pivot (the caller uses Eigen).
bool ldlt3Factor(const Matrix3d& a, Matrix3d& m, int* t) {
  m = a;
  for (int k = 0; k < 3; ++k) {
    int p = k;
    double big = std::abs(m(k, k));
    for (int i = k + 1; i < 3; ++i) {
      const double v = std::abs(m(i, i));
      if (v > big) {
        big = v;
        p = i;
      }
    }
    t[k] = p;
    if (p != k) {
      for (int c = 0; c < k; ++c) std::swap(m(k, c), m(p, c));
      for (int r = p + 1; r < 3; ++r) std::swap(m(r, k), m(r, p));
      std::swap(m(k, k), m(p, p));
      for (int i = k + 1; i < p; ++i) {
        const double tmp = m(i, k);
        m(i, k) = m(p, i);
        m(p, i) = tmp;
      }
    }
    if (k == 1) {
      const double t0 = m(0, 0) * m(1, 0);
      m(1, 1) -= m(1, 0) * t0;
      m(2, 1) += -1.0 * (m(2, 0) * t0);
    } else if (k == 2) {
      const double t0 = m(0, 0) * m(2, 0), t1 = m(1, 1) * m(2, 1);
      m(2, 2) -= m(2, 0) * t0 + m(2, 1) * t1;
    }
    const double akk = m(k, k);
    const bool valid = std::abs(akk) > 0.0;
    if (k == 0 && !valid) return false;
    if (valid)
      for (int i = k + 1; i < 3; ++i) m(i, k) /= akk;
  }
  return true;
}

Vector3d ldlt3Solve(const Matrix3d& m, const int* t, const Vector3d& rhs) {
  Vector3d x = rhs;
  for (int k = 0; k < 3; ++k) std::swap(x(k), x(t[k]));
  x(1) -= m(1, 0) * x(0);
  x(2) -= m(2, 0) * x(0) + m(2, 1) * x(1);
  const double tol = std::numeric_limits<double>::min();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(m(i, i)) > tol) x(i) /= m(i, i);
    else x(i) = 0;
  }
  x(1) -= m(2, 1) * x(2);
  x(0) -= m(1, 0) * x(1) + m(2, 0) * x(2);
  for (int k = 2; k >= 0; --k) std::swap(x(k), x(t[k]));
  return x;
}

bool allFinite3(const Vector3d& v) { return std::isfinite(v(0)) && std::isfinite(v(1)) && std::isfinite(v(2)); }

// The Alart-Curnier function at P (U = W P + b) and, with J, one element of its
// generalised Jacobian J = A + B W (alart_curnier.cpp).
void alartCurnier(const Matrix3d& W, const Vector3d& b, double mu, double rhoN, double rhoT,
                  const Vector3d& P, Vector3d& phi, Matrix3d* J) {
  const Vector3d U = W * P + b;
  if (!J) {
    alartCurnierContact(P, U, mu, rhoN, rhoT, phi, nullptr, nullptr);
    return;
  }
  Matrix3d A, B;
  alartCurnierContact(P, U, mu, rhoN, rhoT, phi, &A, &B);
  *J = A + B * W;
}

double errorOf(const Matrix3d& W, const Vector3d& b, double mu, const Vector3d& P) {
  return localCoulombError(P, W * P + b, mu);
}

// Keeps the best iterate seen across stages.
struct Best {
  Vector3d P = Vector3d::Zero();
  double err = INFINITY;
  void offer(const Vector3d& p, double e) {
    if (e < err && allFinite3(p)) {
      err = e;
      P = p;
    }
  }
};

// Semismooth Newton with Armijo backtracking on 0.5|Phi|^2. Returns iterations used.
int newtonAlartCurnier(const Matrix3d& W, const Vector3d& b, double mu, double rhoN, double rhoT,
                       double tolAbs, Vector3d P, Best& best) {
  Vector3d phi;
  Matrix3d J;
  int slow = 0;
  for (int it = 0; it < kNewtonIterations; ++it) {
    const double e = errorOf(W, b, mu, P);
    best.offer(P, e);
    if (e <= tolAbs) return it;
    alartCurnier(W, b, mu, rhoN, rhoT, P, phi, &J);
    // Closed-form 3x3 inverse (cofactors); a relatively tiny determinant means singular.
    const double jmax = J.cwiseAbs().maxCoeff();
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-14 * jmax * jmax * jmax)) return it;
    const Vector3d d = -(J.inverse() * phi);
    if (!allFinite3(d)) return it;
    const double m0 = 0.5 * phi.squaredNorm();
    double t = 1;
    bool accepted = false;
    Vector3d phiT;
    for (int ls = 0; ls < kLineSearchSteps; ++ls) {
      const Vector3d Pt = P + t * d;
      alartCurnier(W, b, mu, rhoN, rhoT, Pt, phiT, nullptr);
      const double mt = 0.5 * phiT.squaredNorm();
      if (mt <= (1 - 2e-4 * t) * m0) {
        P = Pt;
        accepted = true;
        // Creeping (merit barely decreasing): a local minimum of the merit, not a root.
        slow = mt > 0.9 * m0 ? slow + 1 : 0;
        break;
      }
      t *= 0.5;
    }
    if (!accepted || slow >= kSlowSteps) return it + 1;  // stalled (round-off, kink or local min)
  }
  best.offer(P, errorOf(W, b, mu, P));
  return kNewtonIterations;
}

// Projected fixed point P <- proj_K(P - rho (W P + b + mu|U_T| e_N)).
void fixedPoint(const Matrix3d& W, const Vector3d& b, double mu, double tolAbs, Vector3d P,
                Best& best) {
  Eigen::SelfAdjointEigenSolver<Matrix3d> es;
  es.computeDirect(W, Eigen::EigenvaluesOnly);
  const double lmax = es.eigenvalues()(2);
  if (!(lmax > 0)) return;
  const double rho = 1.0 / lmax;
  for (int it = 0; it < kFixedPointIterations; ++it) {
    Vector3d U = W * P + b;
    const double e = localCoulombError(P, U, mu);
    best.offer(P, e);
    if (e <= tolAbs) return;
    U(0) += mu * U.tail<2>().norm();
    P = projectFrictionCone(P - rho * U, mu);
  }
  best.offer(P, errorOf(W, b, mu, P));
}

// Sliding solutions: P = pN (e_N - mu d), d = (cos psi, sin psi), and
// U = W P + b = s (0, d) with pN > 0, s >= 0. For a given d this is the linear
// system pN a(d) - s (0, d) = -b, a(d) = W (e_N - mu d), solvable iff
//   h(psi) = a(d) . ((0, d) x b) = l . d + d^T S d = 0,
// a trigonometric polynomial of degree 2 (no poles): at most 4 roots.
struct SlipFunction {
  Vector2d l;
  Matrix2d S;
  SlipFunction(const Matrix3d& W, const Vector3d& b, double mu) {
    Eigen::Matrix<double, 3, 2> C;  // (0, d) x b = C d
    C << b(2), -b(1), 0, b(0), -b(0), 0;
    const Eigen::Matrix<double, 3, 2> Aw = -mu * W.block<3, 2>(0, 1);
    l = C.transpose() * W.col(0);
    const Matrix2d Q = Aw.transpose() * C;
    S = 0.5 * (Q + Q.transpose());
  }
  double h(double psi) const {
    const Vector2d d(std::cos(psi), std::sin(psi));
    return l.dot(d) + d.dot(S * d);
  }
  double dh(double psi) const {  // derivative: d' = (-sin, cos)
    const Vector2d d(std::cos(psi), std::sin(psi)), dp(-d.y(), d.x());
    return l.dot(dp) + 2 * dp.dot(S * d);
  }
};

// A root psi of h polished by Newton on h, and the sliding answer there offered.
void offerSlidingRoot(const Matrix3d& W, const Vector3d& b, double mu, const SlipFunction& f, double psi,
                      Best& best) {
  for (int k = 0; k < 8; ++k) {
    const double hv = f.h(psi), dv = f.dh(psi);
    if (hv == 0 || !(std::abs(dv) > 0)) break;
    const double step = hv / dv;
    if (!(std::abs(f.h(psi - step)) < std::abs(hv))) break;
    psi -= step;
  }
  const Vector2d d(std::cos(psi), std::sin(psi));
  Eigen::Matrix<double, 3, 2> M;
  M.col(0) = W.col(0) - mu * W.block<3, 2>(0, 1) * d;
  M.col(1) << 0, -d.x(), -d.y();
  const Vector2d x = M.colPivHouseholderQr().solve(-b);  // (pN, s)
  if (!(x(0) > 0)) return;
  Vector3d Pc;
  Pc(0) = x(0);
  Pc.tail<2>() = -mu * x(0) * d;
  best.offer(Pc, errorOf(W, b, mu, Pc));
}

// The sliding solutions, the roots of h found as the roots of a quartic in
// t = tan((psi - psi0) / 2), each offered.
void slipAngle(const Matrix3d& W, const Vector3d& b, double mu, Best& best) {
  const SlipFunction f(W, b, mu);
  // Origin psi0 with |h(psi0 + pi)| large keeps the quartic's leading term away from 0.
  double psi0 = 0, hmax = -1;
  for (int i = 0; i < 8; ++i) {
    const double v = std::abs(f.h(i * M_PI / 4 + M_PI));
    if (v > hmax) {
      hmax = v;
      psi0 = i * M_PI / 4;
    }
  }
  if (!(hmax > 0)) return;  // h == 0: degenerate, leave it to the other stages
  // Coefficients of h(psi0 + phi) = a0 + a1 cos phi + b1 sin phi + a2 cos 2phi + b2 sin 2phi.
  const Matrix2d R = Eigen::Rotation2Dd(psi0).toRotationMatrix();
  const Vector2d lr = R.transpose() * f.l;
  const Matrix2d Sr = R.transpose() * f.S * R;
  const double a0 = 0.5 * (Sr(0, 0) + Sr(1, 1)), a2 = 0.5 * (Sr(0, 0) - Sr(1, 1)), b2 = Sr(0, 1);
  const double a1 = lr(0), b1 = lr(1);
  // (1 + t^2)^2 h = c4 t^4 + c3 t^3 + c2 t^2 + c1 t + c0.
  const double c4 = a0 - a1 + a2, c3 = 2 * b1 - 4 * b2, c2 = 2 * a0 - 6 * a2, c1 = 2 * b1 + 4 * b2,
               c0 = a0 + a1 + a2;
  Eigen::Matrix4d comp = Eigen::Matrix4d::Zero();
  comp(1, 0) = comp(2, 1) = comp(3, 2) = 1;
  comp(0, 3) = -c0 / c4;
  comp(1, 3) = -c1 / c4;
  comp(2, 3) = -c2 / c4;
  comp(3, 3) = -c3 / c4;
  const Eigen::EigenSolver<Eigen::Matrix4d> es(comp, false);
  if (es.info() != Eigen::Success) return;
  for (int r = 0; r < 4; ++r) {
    // Near-double roots come out as complex pairs with a small imaginary part:
    // try every root's real part, polish on h, and let the Coulomb error decide.
    const std::complex<double> t = es.eigenvalues()(r);
    if (std::abs(t.imag()) > 1e-3 * (1 + std::abs(t))) continue;
    offerSlidingRoot(W, b, mu, f, psi0 + 2 * std::atan(t.real()), best);
  }
}

}  // namespace

Vector3d projectFrictionCone(const Vector3d& x, double mu) {
  const double xn = x(0);
  if (mu <= 0) return Vector3d(std::max(0.0, xn), 0, 0);
  const double nt = x.tail<2>().norm();
  if (nt <= mu * xn) return x;
  if (mu * nt <= -xn) return Vector3d::Zero();
  const double a = (xn + mu * nt) / (1 + mu * mu);
  Vector3d p;
  p(0) = a;
  p.tail<2>() = (mu * a / nt) * x.tail<2>();
  return p;
}

double localCoulombError(const Vector3d& P, const Vector3d& U, double mu) {
  Vector3d Uh = U;
  Uh(0) += mu * U.tail<2>().norm();
  return (P - projectFrictionCone(P - Uh, mu)).norm();
}

bool solveLocalFrictional(const Matrix3d& Wloc, const Vector3d& bloc, double mu, double tol,
                          Vector3d& P) {
  return solveLocalFrictional(Wloc, bloc, mu, tol, P, nullptr);
}

bool solveLocalFrictional(const Matrix3d& Win, const Vector3d& b, double mu, double tol,
                          Vector3d& P, LocalSolveInfo* info) {
  return solveLocalFrictional(Win, b, mu, tol, P, info, nullptr);
}

namespace {

// The answer and its report: every exit reports the error of the original
// problem (Win; the stages may solve a modified W).
struct LocalAnswer {
  const Matrix3d& Win;
  const Vector3d& b;
  double mu;
  double tolAbs;
  Vector3d& P;
  LocalSolveInfo& inf;
  bool report(LocalStage stage, bool ok) {
    ok = ok && inf.error <= tolAbs;
    inf.stage = ok ? stage : LocalStage::Failed;
    return ok;
  }
  bool finish(LocalStage stage, const Vector3d& p, bool ok) {
    P = p;
    inf.error = localCoulombError(p, Win * p + b, mu);
    return report(stage, ok);
  }
  // An exit whose error of the original problem is known already (the same
  // expression on the same W, b, mu, p): only its report.
  bool finishKnown(LocalStage stage, const Vector3d& p, double error, bool ok) {
    P = p;
    inf.error = error;
    return report(stage, ok);
  }
};

// A zero tangent row (planar scenes) with b_T = 0 there: replaced by a
// decoupled unit-scale row; the solution then has P = 0 on it, as it must.
// True if W was changed.
bool decoupleZeroTangents(const Vector3d& b, double maxDiag, double tolAbs, Matrix3d& W) {
  bool modified = false;
  for (int i = 1; i < 3; ++i) {
    if (W(i, i) <= kRelZeroRow * maxDiag && std::abs(b(i)) <= tolAbs) {
      modified = true;
      W.row(i).setZero();
      W.col(i).setZero();
      W(i, i) = W(0, 0);
    }
  }
  return modified;
}

// Second tangent row decoupled (planar scenes): a 2D contact, solved in
// closed form. Stick: the 2 x 2 system U = 0; slide in direction s = +-1:
// P_T = -s mu P_N, U_N = 0 gives P_N, valid if s U_T >= 0. True with Pc and
// its stage if one of them solves it.
bool planarClosedForm(const Matrix3d& W, const Vector3d& b, double mu, double tiny, double maxDiag,
                      double tolAbs, Vector3d& Pc, LocalStage& stage) {
  if (!(W(0, 2) == 0 && W(1, 2) == 0 && b(2) == 0)) return false;
  const Eigen::Matrix2d W2 = W.topLeftCorner<2, 2>();
  const double det = W2.determinant();
  if (det > tiny * maxDiag) {
    const Eigen::Vector2d p = W2.inverse() * -b.head<2>();
    if (p(0) > 0 && std::abs(p(1)) <= mu * p(0)) {
      Pc = Vector3d(p(0), p(1), 0);
      stage = LocalStage::Stick;
      if (errorOf(W, b, mu, Pc) <= tolAbs) return true;
    }
  }
  for (double sgn : {1.0, -1.0}) {
    const double wn = W(0, 0) - sgn * mu * W(0, 1);
    if (!(wn > tiny)) continue;
    const double pn = -b(0) / wn;
    Pc = Vector3d(pn, -sgn * mu * pn, 0);
    stage = LocalStage::Newton;
    const double ut = W(1, 0) * Pc(0) + W(1, 1) * Pc(1) + b(1);
    if (pn > 0 && sgn * ut >= 0 && errorOf(W, b, mu, Pc) <= tolAbs) return true;
  }
  return false;
}

// Sticking: U = 0, W P = -b. The factor of this very W (bit for bit) from the
// cache if it has it: the same factor as computing it again.
Vector3d stickingImpulse(const Matrix3d& W, const Vector3d& b, LocalFactorCache& fc) {
  if (!fc.valid || std::memcmp(fc.W.data(), W.data(), sizeof(Matrix3d)) != 0) {
    fc.W = W;
    fc.factored = ldlt3Factor(W, fc.factor, fc.perm);
    fc.valid = true;
  }
  return fc.factored ? ldlt3Solve(fc.factor, fc.perm, -b) : Vector3d(Eigen::LDLT<Matrix3d>(W).solve(-b));
}

// Semismooth Newton from the starts (warm, projected stick, frictionless),
// best merit first; the merit 0.5|Phi|^2 has local minima, so a stalled run
// is retried from the next start. Returns the Newton iterations.
int newtonFromStarts(const Matrix3d& W, const Vector3d& b, double mu, double tiny, double tolAbs,
                     const Vector3d& warm, const Vector3d& Ps, Best& best) {
  const double rhoN = 1.0 / W(0, 0);
  const double wT = 0.5 * (W(1, 1) + W(2, 2));
  const double rhoT = wT > tiny ? 1.0 / wT : rhoN;
  Vector3d starts[3];
  double merit[3];
  int nStarts = 0;
  const auto addStart = [&](const Vector3d& c) {
    if (!allFinite3(c)) return;
    Vector3d phi;
    alartCurnier(W, b, mu, rhoN, rhoT, c, phi, nullptr);
    const double mc = phi.squaredNorm();
    int i = nStarts++;
    for (; i > 0 && merit[i - 1] > mc; --i) {
      starts[i] = starts[i - 1];
      merit[i] = merit[i - 1];
    }
    starts[i] = c;
    merit[i] = mc;
  };
  if (allFinite3(warm) && !warm.isZero(0)) addStart(warm);
  if (allFinite3(Ps)) addStart(projectFrictionCone(Ps, mu));
  addStart(Vector3d(-b(0) / W(0, 0), 0, 0));
  int iterations = 0;
  for (int i = 0; i < nStarts && best.err > tolAbs; ++i)
    iterations += newtonAlartCurnier(W, b, mu, rhoN, rhoT, tolAbs, starts[i], best);
  return iterations;
}

}  // namespace

bool solveLocalFrictional(const Matrix3d& Win, const Vector3d& b, double mu, double tol,
                          Vector3d& P, LocalSolveInfo* info, LocalFactorCache* cache) {
  LocalSolveInfo local;
  LocalSolveInfo& inf = info ? *info : local;
  inf = LocalSolveInfo{};
  if (!Win.allFinite() || !allFinite3(b) || !std::isfinite(mu)) {
    P.setZero();
    inf.error = INFINITY;
    return false;
  }
  const double tolAbs = tol * std::max(1.0, b.norm());
  LocalAnswer ans{Win, b, mu, tolAbs, P, inf};

  // Take-off: P = 0 leaves U = b with U_N >= 0.
  if (b(0) >= 0) return ans.finish(LocalStage::TakeOff, Vector3d::Zero(), true);
  const double maxDiag = Win.diagonal().maxCoeff();
  const double tiny = kRelTiny * maxDiag;
  if (!(Win(0, 0) > tiny)) {  // approaching, but no impulse can stop it: no solution
    return ans.finish(LocalStage::Failed, Vector3d::Zero(), false);
  }
  if (mu <= 0) return ans.finish(LocalStage::Frictionless, Vector3d(-b(0) / Win(0, 0), 0, 0), true);
  Matrix3d W = Win;
  const bool modified = decoupleZeroTangents(b, maxDiag, tolAbs, W);  // W != Win

  // Warm start already a solution (NSGS near convergence): nothing to do.
  if (allFinite3(P) && !P.isZero(0)) {
    const double e = errorOf(Win, b, mu, P);
    if (e <= tolAbs) return ans.finishKnown(LocalStage::WarmStart, P, e, true);
  }
  Vector3d Pc;
  LocalStage planar = LocalStage::Stick;
  if (planarClosedForm(W, b, mu, tiny, maxDiag, tolAbs, Pc, planar)) return ans.finish(planar, Pc, true);

  Best best;
  LocalFactorCache scratch;
  const Vector3d Ps = stickingImpulse(W, b, cache ? *cache : scratch);
  if (allFinite3(Ps)) {
    const double e = errorOf(W, b, mu, Ps);
    if (e <= tolAbs && Ps(0) > 0)
      return modified ? ans.finish(LocalStage::Stick, Ps, true) : ans.finishKnown(LocalStage::Stick, Ps, e, true);
    best.offer(Ps, e);
  }
  const Vector3d warm = P;
  inf.newton_iterations += newtonFromStarts(W, b, mu, tiny, tolAbs, warm, Ps, best);
  if (best.err <= tolAbs) return ans.finish(LocalStage::Newton, best.P, true);

  fixedPoint(W, b, mu, tolAbs, best.P, best);
  if (best.err <= tolAbs) return ans.finish(LocalStage::FixedPoint, best.P, true);

  // Last resort: enumerate sliding solutions, then polish the best by Newton.
  slipAngle(W, b, mu, best);
  if (best.err > tolAbs && std::isfinite(best.err)) {
    const double rhoN = 1.0 / W(0, 0);
    const double wT = 0.5 * (W(1, 1) + W(2, 2));
    newtonAlartCurnier(W, b, mu, rhoN, wT > tiny ? 1.0 / wT : rhoN, tolAbs, best.P, best);
  }
  return ans.finish(LocalStage::SlipAngle, best.P, true);
}

}  // namespace nscd
