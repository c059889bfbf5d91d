// The ideal prismatic joint: the relative orientation is locked (3 rows) and the
// child's anchor stays on the parent's axis (2 rows); its position and rate.
#include "joint_rows.hpp"

namespace nscd {

void appendPrismaticRows(const Joint& j, const State& s, const JointPlacement& p,
                         ConstraintBlock& blk, int& r, Eigen::MatrixXd& G) {
  appendOrientationLockRows(j, s, p, blk, r, G);
  // No relative motion across the axis.
  for (int i = 1; i < 3; ++i) {
    const Vec3 e = p.fa.e[i];
    // d/dt (dp.e) = (vpb - vpa).e + dp.(w_a x e)
    putRow(G, r, s, j.body_a, j.body_b, e, (p.pb - p.b.x).cross(e), -e,
           -((p.pa - p.a.x).cross(e)) + e.cross(p.dp));
    blk.error[r - blk.row] = p.dp.dot(e);
    ++r;
  }
}

namespace {
Vec3 pointWorld(const BodyState& b, const Vec3& local) { return b.q * local + b.x; }
Vec3 pointVelocity(const BodyState& b, const Vec3& local) { return b.v + b.q * (b.w.cross(local)); }
}  // namespace

double prismaticPosition(const Joint& j, const BodyState& a, const BodyState& b) {
  return (pointWorld(b, j.anchor_b) - pointWorld(a, j.anchor_a)).dot(a.q * j.axis_a);
}

double prismaticRate(const Joint& j, const BodyState& a, const BodyState& b) {
  const Vec3 axis = a.q * j.axis_a;
  return (pointVelocity(b, j.anchor_b) - pointVelocity(a, j.anchor_a)).dot(axis);
}

}  // namespace nscd
