// A prescribed actuator: a kinematic driver. With joint=, the joint coordinate
// follows the command (1 row); with link=, the body translates along the axis by
// the command from its initial pose and its other 5 DOF stay fixed (6 rows), or,
// with constrain="axis", only that translation is prescribed (1 row, the other 5
// DOF free: a plunger guided by contacts).
// The row targets are the commanded rate; the errors the position mismatch.
#include "joint_rows.hpp"

namespace nscd {

void appendPrescribedRows(const Model& m, const State& s, int ai, double rate,
                          ConstraintBlock& blk, int& r, Eigen::MatrixXd& G) {
  const Actuator& ac = m.actuators[ai];
  const double command = s.commands[ai];
  if (ac.joint >= 0) {
    const Joint& j = m.joints[ac.joint];
    const BodyState& a = bodyOrGround(s, j.body_a);
    const BodyState& b = bodyOrGround(s, j.body_b);
    blk.body_a = j.body_a;
    blk.body_b = j.body_b;
    const Vec3 axis = a.q * j.axis_a;
    if (j.type == JointType::Prismatic) {
      const Vec3 pa = a.q * j.anchor_a + a.x;
      const Vec3 pb = b.q * j.anchor_b + b.x;
      putRow(G, r, s, j.body_a, j.body_b, axis, (pb - b.x).cross(axis), -axis,
             -((pa - a.x).cross(axis)) + axis.cross(pb - pa));
    } else {
      rotationRow(G, r, s, j.body_a, j.body_b, axis);
    }
    blk.error[0] = jointPosition(m, s, ac.joint) - command;
    blk.target[0] = rate;
    ++r;
    return;
  }
  const Body& body = m.bodies[ac.body];
  const BodyState& b = s.bodies[ac.body];
  blk.body_a = kGround;
  blk.body_b = ac.body;
  const Frame3 f = frameAround(ac.axis);
  const Vec3 disp = b.x - body.initial_pose.p - command * ac.axis;
  if (ac.axis_only) {
    putRow(G, r, s, kGround, ac.body, f.e[0], Vec3::Zero(), Vec3::Zero(), Vec3::Zero());
    blk.error[0] = disp.dot(f.e[0]);
    blk.target[0] = rate;
    ++r;
    return;
  }
  for (int i = 0; i < 3; ++i) {
    putRow(G, r, s, kGround, ac.body, f.e[i], Vec3::Zero(), Vec3::Zero(), Vec3::Zero());
    blk.error[i] = disp.dot(f.e[i]);
    blk.target[i] = i == 0 ? rate : 0.0;
    ++r;
  }
  const Vec3 rot_err = logMap(b.q * body.initial_pose.q.conjugate());
  for (int i = 0; i < 3; ++i) {
    rotationRow(G, r, s, kGround, ac.body, Vec3::Unit(i));
    blk.error[3 + i] = rot_err[i];
    ++r;
  }
}

}  // namespace nscd
