// Stage 2a: bilateral constraint rows of ideal joints and prescribed actuators,
// with their position errors (for the projection) and rheonomic target rates.
//
// Row convention: for a row with world direction d acting on the relative
// motion "B minus A" at points pb, pa, the Jacobian is
//   body B: [ d^T, (R_b^T (rb x d))^T ]   body A: -[ d^T, (R_a^T (ra x d))^T ]
// and for a pure rotational row with world direction d:
//   body B: [0, (R_b^T d)^T]              body A: -[0, (R_a^T d)^T].
#include <cmath>

#include "step_workspace.hpp"

namespace nscd {
namespace {


// Jacobian of one row, written into G: linear part (world) and the angular
// part given as a world vector for each body; converted to body frames here.
void putRow(Eigen::MatrixXd& G, int row, const State& s, int body_a, int body_b,
            const Vec3& lin_b, const Vec3& ang_b_world, const Vec3& lin_a,
            const Vec3& ang_a_world) {
  G.row(row).setZero();
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

// Point-coincidence row along world direction d: error (pb - pa).d
void pointRow(Eigen::MatrixXd& G, int row, const State& s, int ia, int ib, const Vec3& pa,
              const Vec3& pb, const Vec3& d) {
  const BodyState& a = bodyOrGround(s, ia);
  const BodyState& b = bodyOrGround(s, ib);
  putRow(G, row, s, ia, ib, d, (pb - b.x).cross(d), -d, -((pa - a.x).cross(d)));
}

// Rotation row about world direction d.
void rotationRow(Eigen::MatrixXd& G, int row, const State& s, int ia, int ib, const Vec3& d) {
  putRow(G, row, s, ia, ib, Vec3::Zero(), d, Vec3::Zero(), -d);
}

struct Frame3 {
  Vec3 e[3];
};
Frame3 frameAround(const Vec3& axis) {
  Frame3 f;
  f.e[0] = axis;
  f.e[1] = anyOrthogonal(axis);
  f.e[2] = axis.cross(f.e[1]);
  return f;
}

}  // namespace

void appendBilateralBlocks(const Model& m, const State& s, const std::vector<double>& commands,
                           const std::vector<double>& rates, StepWorkspace& ws) {
  for (size_t ji = 0; ji < m.joints.size(); ++ji) {
    const Joint& j = m.joints[ji];
    if (j.clearance >= 0) continue;  // replaced by unilateral contacts
    const BodyState& a = bodyOrGround(s, j.body_a);
    const BodyState& b = bodyOrGround(s, j.body_b);
    const Vec3 pa = a.q * j.anchor_a + a.x;
    const Vec3 pb = b.q * j.anchor_b + b.x;
    const Vec3 axis_a = a.q * j.axis_a;
    const Frame3 fa = frameAround(axis_a);
    ConstraintBlock blk;
    blk.kind = BlockKind::Bilateral;
    blk.body_a = j.body_a;
    blk.body_b = j.body_b;
    blk.joint = static_cast<int>(ji);
    blk.row = ws.rows;
    int r = ws.rows;
    const Vec3 dp = pb - pa;
    if (j.type == JointType::Revolute) {
      for (int i = 0; i < 3; ++i) {
        const Vec3 d = Vec3::Unit(i);
        pointRow(ws.G, r, s, j.body_a, j.body_b, pa, pb, d);
        blk.error[r - blk.row] = dp.dot(d);
        ++r;
      }
      const Vec3 axis_b = b.q * j.axis_b;
      for (int i = 1; i < 3; ++i) {
        const Vec3 c = axis_b.cross(fa.e[i]);
        putRow(ws.G, r, s, j.body_a, j.body_b, Vec3::Zero(), c, Vec3::Zero(), -c);
        blk.error[r - blk.row] = axis_b.dot(fa.e[i]);
        ++r;
      }
    } else {
      // Orientation lock: error = rotation vector of q_b (q_a Z)^-1, world frame.
      const Vec3 rot_err = logMap(b.q * (a.q * j.rel_rot_zero).conjugate());
      for (int i = 0; i < 3; ++i) {
        rotationRow(ws.G, r, s, j.body_a, j.body_b, Vec3::Unit(i));
        blk.error[r - blk.row] = rot_err[i];
        ++r;
      }
      if (j.type == JointType::Fixed) {
        for (int i = 0; i < 3; ++i) {
          const Vec3 d = Vec3::Unit(i);
          pointRow(ws.G, r, s, j.body_a, j.body_b, pa, pb, d);
          blk.error[r - blk.row] = dp.dot(d);
          ++r;
        }
      } else {  // prismatic: no relative motion across the axis
        for (int i = 1; i < 3; ++i) {
          const Vec3 e = fa.e[i];
          // d/dt (dp.e) = (vpb - vpa).e + dp.(w_a x e)
          putRow(ws.G, r, s, j.body_a, j.body_b, e, (pb - b.x).cross(e), -e,
                 -((pa - a.x).cross(e)) + e.cross(dp));
          blk.error[r - blk.row] = dp.dot(e);
          ++r;
        }
      }
    }
    blk.size = r - blk.row;
    ws.rows = r;
    ws.blocks.push_back(blk);
  }

  for (size_t ai = 0; ai < m.actuators.size(); ++ai) {
    const Actuator& ac = m.actuators[ai];
    if (ac.type != ActuatorType::Prescribed) continue;
    ConstraintBlock blk;
    blk.kind = BlockKind::Bilateral;
    blk.actuator = static_cast<int>(ai);
    blk.row = ws.rows;
    int r = ws.rows;
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
        putRow(ws.G, r, s, j.body_a, j.body_b, axis, (pb - b.x).cross(axis), -axis,
               -((pa - a.x).cross(axis)) + axis.cross(pb - pa));
      } else {
        rotationRow(ws.G, r, s, j.body_a, j.body_b, axis);
      }
      blk.error[0] = jointPosition(m, s, ac.joint) - commands[ai];
      blk.target[0] = rates[ai];
      ++r;
    } else {
      // A kinematic driver: the body translates along `axis` by the command
      // from its initial pose; the other 5 DOF stay fixed.
      const Body& body = m.bodies[ac.body];
      const BodyState& b = s.bodies[ac.body];
      blk.body_a = kGround;
      blk.body_b = ac.body;
      const Frame3 f = frameAround(ac.axis);
      const Vec3 disp = b.x - body.initial_pose.p - commands[ai] * ac.axis;
      for (int i = 0; i < 3; ++i) {
        putRow(ws.G, r, s, kGround, ac.body, f.e[i], Vec3::Zero(), Vec3::Zero(), Vec3::Zero());
        blk.error[i] = disp.dot(f.e[i]);
        blk.target[i] = i == 0 ? rates[ai] : 0.0;
        ++r;
      }
      const Vec3 rot_err = logMap(b.q * body.initial_pose.q.conjugate());
      for (int i = 0; i < 3; ++i) {
        rotationRow(ws.G, r, s, kGround, ac.body, Vec3::Unit(i));
        blk.error[3 + i] = rot_err[i];
        ++r;
      }
    }
    blk.size = r - blk.row;
    ws.rows = r;
    ws.blocks.push_back(blk);
  }
}

}  // namespace nscd
