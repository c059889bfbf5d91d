// Stage 2a: bilateral rows of the ideal joints and prescribed actuators, each
// joint kind in its own file; here the row helpers they share and the pass over
// the model.
#include "joint_rows.hpp"

#include <cmath>

namespace nscd {

Frame3 frameAround(const Vec3& axis) {
  Frame3 f;
  f.e[0] = axis;
  f.e[1] = anyOrthogonal(axis);
  f.e[2] = axis.cross(f.e[1]);
  return f;
}

JointPlacement placeJoint(const Joint& j, const State& s) {
  const BodyState& a = bodyOrGround(s, j.body_a);
  const BodyState& b = bodyOrGround(s, j.body_b);
  const Vec3 pa = a.q * j.anchor_a + a.x;
  const Vec3 pb = b.q * j.anchor_b + b.x;
  const Vec3 axis_a = a.q * j.axis_a;
  return JointPlacement{a, b, pa, pb, axis_a, frameAround(axis_a), pb - pa};
}

JointPlacement placeJointOnGround(const Joint& j, const State& s, const PlacementMemo& g) {
  const BodyState& b = bodyOrGround(s, j.body_b);
  const Vec3 pb = b.q * j.anchor_b + b.x;
  return JointPlacement{bodyOrGround(s, kGround), b, g.pa, pb, g.axis_a, Frame3{{g.frame[0], g.frame[1], g.frame[2]}},
                        pb - g.pa};
}

void placeGroundSides(const Model& m, StepWorkspace& ws) {
  // placeJoint's own arithmetic on the ground's (constant) pose: the same bits.
  ws.ground_sides.assign(m.joints.size(), PlacementMemo{});
  for (size_t ji = 0; ji < m.joints.size(); ++ji) {
    const Joint& j = m.joints[ji];
    if (j.body_a != kGround) continue;
    const BodyState a{};  // the ground's pose (bodyOrGround)
    const Vec3 pa = a.q * j.anchor_a + a.x;
    const Vec3 axis_a = a.q * j.axis_a;
    const Frame3 f = frameAround(axis_a);
    ws.ground_sides[ji] = PlacementMemo{pa, Vec3::Zero(), axis_a, Vec3::Zero(), {f.e[0], f.e[1], f.e[2]}};
  }
}

void putRow(Eigen::MatrixXd& G, int row, const State& s, int body_a, int body_b,
            const Vec3& lin_b, const Vec3& ang_b_world, const Vec3& lin_a,
            const Vec3& ang_a_world) {
  // The row is zero (clearConstraintRows); body_a may be body_b, hence +=.
  if (body_b != kGround) {
    const BodyState& b = s.bodies[body_b];
    G.block<1, 3>(row, 6 * body_b) = lin_b.transpose();
    G.block<1, 3>(row, 6 * body_b + 3) = (b.q.conjugate() * ang_b_world).transpose();
  }
  if (body_a != kGround) {
    const BodyState& a = s.bodies[body_a];
    G.block<1, 3>(row, 6 * body_a) += lin_a.transpose();
    G.block<1, 3>(row, 6 * body_a + 3) += (a.q.conjugate() * ang_a_world).transpose();
  }
}

void pointRow(Eigen::MatrixXd& G, int row, const State& s, int ia, int ib, const Vec3& pa,
              const Vec3& pb, const Vec3& d) {
  const BodyState& a = bodyOrGround(s, ia);
  const BodyState& b = bodyOrGround(s, ib);
  putRow(G, row, s, ia, ib, d, (pb - b.x).cross(d), -d, -((pa - a.x).cross(d)));
}

void rotationRow(Eigen::MatrixXd& G, int row, const State& s, int ia, int ib, const Vec3& d) {
  putRow(G, row, s, ia, ib, Vec3::Zero(), d, Vec3::Zero(), -d);
}

void appendPointRows(const Joint& j, const State& s, const JointPlacement& p,
                     ConstraintBlock& blk, int& r, Eigen::MatrixXd& G) {
  for (int i = 0; i < 3; ++i) {
    const Vec3 d = Vec3::Unit(i);
    pointRow(G, r, s, j.body_a, j.body_b, p.pa, p.pb, d);
    blk.error[r - blk.row] = p.dp.dot(d);
    ++r;
  }
}

void appendOrientationLockRows(const Joint& j, const State& s, const JointPlacement& p,
                               ConstraintBlock& blk, int& r, Eigen::MatrixXd& G) {
  // Error: the rotation vector of q_b (q_a Z)^-1, world frame.
  const Vec3 rot_err = logMap(p.b.q * (p.a.q * j.rel_rot_zero).conjugate());
  for (int i = 0; i < 3; ++i) {
    rotationRow(G, r, s, j.body_a, j.body_b, Vec3::Unit(i));
    blk.error[r - blk.row] = rot_err[i];
    ++r;
  }
}

double jointCoordinate(const Joint& j, const BodyState& a, const BodyState& b) {
  return j.type == JointType::Prismatic ? prismaticPosition(j, a, b) : revoluteAngle(j, a, b);
}

double jointRate(const Joint& j, const BodyState& a, const BodyState& b) {
  return j.type == JointType::Prismatic ? prismaticRate(j, a, b) : revoluteRate(j, a, b);
}

double jointCoordinateNear(const Joint& j, const BodyState& a, const BodyState& b,
                           double reference) {
  const double raw = jointCoordinate(j, a, b);
  if (j.type == JointType::Prismatic) return raw;
  const double turns = std::round((reference - raw) / (2 * M_PI));
  return turns == 0 ? raw : raw + 2 * M_PI * turns;
}

double jointPosition(const Model& m, const State& s, int joint) {
  const Joint& j = m.joints[joint];
  return jointCoordinateNear(j, bodyOrGround(s, j.body_a), bodyOrGround(s, j.body_b),
                             s.joint_position[joint]);
}

void trackJointPositions(const Model& m, State& s) {
  for (size_t j = 0; j < m.joints.size(); ++j) s.joint_position[j] = jointPosition(m, s, static_cast<int>(j));
}

double jointVelocity(const Model& m, const State& s, int joint) {
  const Joint& j = m.joints[joint];
  return jointRate(j, bodyOrGround(s, j.body_a), bodyOrGround(s, j.body_b));
}

void appendBilateralRows(const Model& m, const State& s, const std::vector<double>& rates,
                         StepWorkspace& ws, bool jacobian) {
  if (jacobian) clearStaleJointRows(m, ws, ws.rows);
  for (size_t ji = 0; ji < m.joints.size(); ++ji) {
    const Joint& j = m.joints[ji];
    if (j.clearance >= 0) continue;  // replaced by unilateral contacts
    const JointPlacement p = j.body_a == kGround ? placeJointOnGround(j, s, ws.ground_sides[ji]) : placeJoint(j, s);
    ConstraintBlock& blk = ws.blocks.emplace_back();  // built in place (a block is ~0.4 kB)
    blk.kind = BlockKind::Bilateral;
    blk.body_a = j.body_a;
    blk.body_b = j.body_b;
    blk.joint = static_cast<int>(ji);
    blk.row = ws.rows;
    int r = ws.rows;
    switch (j.type) {
      case JointType::Revolute:
        if (jacobian) {
          appendRevoluteRows(j, s, p, blk, r, ws.G);
        } else {
          appendRevoluteErrors(j, p, blk, r);
          ws.placements[ji] = PlacementMemo{p.pa, p.pb, p.axis_a, p.dp, {p.fa.e[0], p.fa.e[1], p.fa.e[2]}};
        }
        break;
      case JointType::Prismatic: appendPrismaticRows(j, s, p, blk, r, ws.G); break;
      case JointType::Fixed: appendFixedRows(j, s, p, blk, r, ws.G); break;
    }
    blk.size = r - blk.row;
    ws.rows = r;
  }
  for (size_t ai = 0; ai < m.actuators.size(); ++ai) {
    if (m.actuators[ai].type != ActuatorType::Prescribed) continue;
    ConstraintBlock blk;
    blk.kind = BlockKind::Bilateral;
    blk.actuator = static_cast<int>(ai);
    blk.row = ws.rows;
    int r = ws.rows;
    appendPrescribedRows(m, s, static_cast<int>(ai), rates[ai], blk, r, ws.G);
    blk.size = r - blk.row;
    ws.rows = r;
    ws.blocks.push_back(blk);
  }
}

void completeBilateralRows(const Model& m, const State& s, StepWorkspace& ws) {
  if (ws.blocks.empty()) return;
  clearStaleJointRows(m, ws, ws.blocks.front().row);  // a full gather's start (bilateral blocks come first)
  for (ConstraintBlock& blk : ws.blocks) {
    if (blk.joint < 0) continue;
    const Joint& j = m.joints[blk.joint];
    if (j.type != JointType::Revolute) continue;  // the other kinds wrote G already
    const PlacementMemo& pm = ws.placements[blk.joint];
    const JointPlacement p{bodyOrGround(s, j.body_a), bodyOrGround(s, j.body_b), pm.pa, pm.pb, pm.axis_a,
                           Frame3{{pm.frame[0], pm.frame[1], pm.frame[2]}}, pm.dp};
    int r = blk.row;
    appendRevoluteRows(j, s, p, blk, r, ws.G);  // its errors again, the same
  }
}

}  // namespace nscd
