// Small geometric types shared by every stage of the engine.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace nscd {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// A rigid transform: x_outer = q * x_inner + p.
struct Pose {
  Vec3 p = Vec3::Zero();
  Quat q = Quat::Identity();

  Vec3 apply(const Vec3& x) const { return q * x + p; }
  Vec3 rotate(const Vec3& d) const { return q * d; }
  Pose operator*(const Pose& o) const { return Pose{q * o.p + p, (q * o.q).normalized()}; }
  Pose inverse() const {
    Quat qi = q.conjugate();
    return Pose{-(qi * p), qi};
  }
};

inline Mat3 skew(const Vec3& v) {
  Mat3 s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

// Rotation by the rotation vector phi (exponential map), as a unit quaternion.
inline Quat expMap(const Vec3& phi) {
  const double a = phi.norm();
  if (a < 1e-8) {
    // Second-order series: unit to round-off for tiny angles.
    Quat r(1.0 - a * a / 8.0, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z());
    return r.normalized();
  }
  const double s = std::sin(0.5 * a) / a;
  return Quat(std::cos(0.5 * a), s * phi.x(), s * phi.y(), s * phi.z());
}

// Rotation vector of a unit quaternion (inverse of expMap, shortest arc).
inline Vec3 logMap(const Quat& qin) {
  Quat q = qin;
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Vec3 v = q.vec();
  const double s = v.norm();
  if (s < 1e-12) return 2.0 * v;
  return (2.0 * std::atan2(s, q.w()) / s) * v;
}

// A unit vector orthogonal to n (n unit).
inline Vec3 anyOrthogonal(const Vec3& n) {
  Vec3 t = (std::abs(n.x()) < 0.6) ? Vec3::UnitX() : Vec3::UnitY();
  return (t - t.dot(n) * n).normalized();
}

}  // namespace nscd
