// The ideal revolute joint: the anchors coincide (3 rows) and the child's axis
// stays on the parent's (2 rows); its angle and rate about the axis.
#include <cmath>

#include "joint_rows.hpp"

namespace nscd {

void appendRevoluteRows(const Joint& j, const State& s, const JointPlacement& p,
                        ConstraintBlock& blk, int& r, Eigen::MatrixXd& G) {
  appendPointRows(j, s, p, blk, r, G);
  const Vec3 axis_b = p.b.q * j.axis_b;
  for (int i = 1; i < 3; ++i) {
    const Vec3 c = axis_b.cross(p.fa.e[i]);
    putRow(G, r, s, j.body_a, j.body_b, Vec3::Zero(), c, Vec3::Zero(), -c);
    blk.error[r - blk.row] = axis_b.dot(p.fa.e[i]);
    ++r;
  }
}

// Twist angle of the child about the joint axis, from the URDF zero, in (-pi, pi].
double revoluteAngle(const Joint& j, const BodyState& a, const BodyState& b) {
  Quat dev = (a.q.conjugate() * b.q) * j.rel_rot_zero.conjugate();
  if (dev.w() < 0) dev.coeffs() = -dev.coeffs();
  return 2.0 * std::atan2(dev.vec().dot(j.axis_a), dev.w());
}

double revoluteRate(const Joint& j, const BodyState& a, const BodyState& b) {
  return (b.q * b.w - a.q * a.w).dot(a.q * j.axis_a);
}

}  // namespace nscd
