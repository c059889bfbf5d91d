// An actuator's handle for an interactive marker, from the scene alone (ROS-free,
// unit-tested): where the marker stands at a command, and which command a dragged
// marker pose asks for. A joint actuator (position, or prescribed with joint=) on a
// revolute joint turns about the joint axis (command: the joint angle, rad, from
// the URDF zero); on a prismatic joint it slides along the axis (m). A prescribed
// link slides along its axis (command: the displacement from its initial pose, m).
// Force and torque actuators have no handle (nothing to grab).
#pragma once

#include <string>

#include "nscd_sim/model.hpp"

namespace nscd_node {

struct ActuatorHandle {
  enum class Motion { Rotate, Slide };
  std::string name;      // the actuator's
  int actuator = -1;     // index into Model::actuators
  Motion motion = Motion::Slide;
  // The link whose frame the marker is in: the world frame, or for a joint whose
  // parent moves, a link of the parent (the marker then rides along, by tf).
  std::string frame;
  nscd::Vec3 origin = nscd::Vec3::Zero();  // Rotate: the pivot; Slide: the point at command 0 (frame)
  nscd::Vec3 axis = nscd::Vec3::UnitX();   // unit, frame
  // The marker's orientation at command 0: x along the axis (the axis of RViz's
  // ROTATE_AXIS and MOVE_AXIS controls); for Rotate, y towards the driven body's
  // centre of mass at command 0 (the lever drawn on the marker).
  nscd::Quat zero = nscd::Quat::Identity();
  double lever = 0;  // Rotate: distance of the driven body's centre of mass from the axis (m)

  // The marker's pose (in `frame`) at `command`.
  nscd::Pose poseAt(double command) const;
  // The command a marker pose asks for: the rotation about the axis (the turn
  // nearest `near`, so a handle may turn more than half a turn), or the
  // displacement along the axis. Off-axis parts of the pose are ignored.
  double commandAt(const nscd::Pose& pose, double near = 0) const;
};

// The handle of the named actuator. Throws nscd::SceneError (one line) for an
// unknown actuator or one that has no handle.
ActuatorHandle actuatorHandle(const nscd::Model& model, const std::string& name);

// An actuator's command range [min, max]; a command outside is clipped.
struct CommandRange {
  double min = 0, max = 0;
  double clip(double value) const { return value < min ? min : (value > max ? max : value); }
  bool contains(double value) const { return value >= min && value <= max; }
};

}  // namespace nscd_node
