// Actuator handles for interactive markers (actuator_handle.hpp).
#include "actuator_handle.hpp"

#include <cmath>

#include "nscd_sim/scene_loader.hpp"

namespace nscd_node {
namespace {

// The link that names a body's frame in tf: the link carrying its inertia, else
// any link riding on it. -1 if none.
int linkOfBody(const nscd::Model& model, int body) {
  int any = -1;
  for (size_t i = 0; i < model.links.size(); ++i) {
    if (model.links[i].body != body) continue;
    if (model.links[i].name == model.bodies[body].name) return static_cast<int>(i);
    if (any < 0) any = static_cast<int>(i);
  }
  return any;
}

// A frame whose x is `x` (unit) and whose y is as near `y_hint` as orthogonality allows.
nscd::Quat frameWithX(const nscd::Vec3& x, const nscd::Vec3& y_hint) {
  nscd::Vec3 y = y_hint - y_hint.dot(x) * x;
  y = y.norm() > 1e-9 ? y.normalized() : nscd::anyOrthogonal(x);
  nscd::Mat3 r;
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = x.cross(y);
  return nscd::Quat(r).normalized();
}

// For a handle in the world frame, a y in the world's x-y plane where possible (a
// top-down view then sees the slider's arrows flat).
nscd::Vec3 planarHint(const nscd::Vec3& x) {
  const nscd::Vec3 h = nscd::Vec3::UnitZ().cross(x);
  return h.norm() > 1e-6 ? h : nscd::Vec3(nscd::Vec3::UnitY());
}

}  // namespace

nscd::Pose ActuatorHandle::poseAt(double command) const {
  nscd::Pose p;
  if (motion == Motion::Rotate) {
    p.p = origin;
    p.q = (nscd::Quat(Eigen::AngleAxisd(command, axis)) * zero).normalized();
  } else {
    p.p = origin + command * axis;
    p.q = zero;
  }
  return p;
}

double ActuatorHandle::commandAt(const nscd::Pose& pose, double near) const {
  if (motion == Motion::Slide) return (pose.p - origin).dot(axis);
  // The twist of pose.q * zero^-1 about the axis.
  const nscd::Quat r = pose.q * zero.conjugate();
  double angle = 2.0 * std::atan2(r.vec().dot(axis), r.w());
  // atan2 gives (-pi, pi] for the half angle's sign choice: bring it to the turn nearest `near`.
  angle += 2.0 * M_PI * std::round((near - angle) / (2.0 * M_PI));
  return angle;
}

namespace {

// The index of actuator `name`; throws SceneError naming the ones there are.
int findActuatorOrThrow(const nscd::Model& model, const std::string& name) {
  const int index = model.findActuator(name);
  if (index < 0) {
    std::string all;
    for (const nscd::Actuator& a : model.actuators) all += (all.empty() ? "" : ", ") + a.name;
    throw nscd::SceneError("no actuator '" + name + "' in " + model.source_file +
                           " (actuators: " + (all.empty() ? "none" : all) + ")");
  }
  return index;
}

// Places the handle of an actuator driving joint `j`: at the joint, in its parent's
// frame (the world frame, or a link of the parent body); throws SceneError.
void placeOnJoint(const nscd::Model& model, const nscd::Joint& j, ActuatorHandle& h) {
  nscd::Pose in_frame;  // parent body frame -> marker frame
  nscd::Pose parent;    // parent body frame in the world at the initial placement
  if (j.body_a == nscd::kGround) {
    h.frame = model.world_frame;
  } else {
    const int link = linkOfBody(model, j.body_a);
    if (link < 0)
      throw nscd::SceneError("actuator '" + h.name + "': joint '" + j.name + "' has a parent with no link");
    h.frame = model.links[link].name;
    in_frame = model.links[link].in_body.inverse();
    parent = model.bodies[j.body_a].initial_pose;
  }
  h.origin = in_frame.apply(j.anchor_a);
  h.axis = in_frame.rotate(j.axis_a).normalized();
  if (j.type == nscd::JointType::Revolute) {
    h.motion = ActuatorHandle::Motion::Rotate;
    // The lever: towards the child's centre of mass, turned back to joint angle 0.
    nscd::Vec3 com = h.origin;
    if (j.body_b != nscd::kGround)
      com = in_frame.apply(parent.inverse().apply(model.bodies[j.body_b].initial_pose.p));
    nscd::Vec3 lever = com - h.origin;
    lever -= lever.dot(h.axis) * h.axis;
    h.lever = lever.norm();
    lever = Eigen::AngleAxisd(-j.initial_position, h.axis) * lever;
    h.zero = frameWithX(h.axis, lever);
  } else {
    h.motion = ActuatorHandle::Motion::Slide;
    h.zero = frameWithX(h.axis, j.body_a == nscd::kGround ? planarHint(h.axis)
                                                            : nscd::Vec3(nscd::anyOrthogonal(h.axis)));
  }
}

}  // namespace

ActuatorHandle actuatorHandle(const nscd::Model& model, const std::string& name) {
  const int index = findActuatorOrThrow(model, name);
  const nscd::Actuator& a = model.actuators[index];
  ActuatorHandle h;
  h.name = name;
  h.actuator = index;
  const bool joint_driven =
      a.joint >= 0 && (a.type == nscd::ActuatorType::Position || a.type == nscd::ActuatorType::Prescribed);
  if (joint_driven) {
    placeOnJoint(model, model.joints[a.joint], h);
    return h;
  }
  if (a.type == nscd::ActuatorType::Prescribed && a.body >= 0) {
    h.motion = ActuatorHandle::Motion::Slide;
    h.frame = model.world_frame;
    h.origin = model.bodies[a.body].initial_pose.p;
    h.axis = a.axis.normalized();
    h.zero = frameWithX(h.axis, planarHint(h.axis));
    return h;
  }
  throw nscd::SceneError("actuator '" + name + "' is a " +
                         (a.type == nscd::ActuatorType::Force ? "force" : "torque") +
                         " actuator: no handle to drag (a joint or prescribed actuator has one)");
}

}  // namespace nscd_node
