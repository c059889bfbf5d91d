// The immutable description of a mechanism: what the scene loader produces and
// every stage of a time step reads. Flat structs, indices instead of pointers.
//
// Frames. Every free body has a body frame at its centre of mass (the URDF
// <inertial><origin>, including its rpy). All attachment data below (joint
// anchors and axes, shapes, spring ends, actuator points) is already expressed
// in that body frame; for ground (body == kGround) it is expressed in the world
// frame (the frame of the URDF root link).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "nscd_sim/types.hpp"

namespace nscd {

constexpr int kGround = -1;

// Where a bad-input message points: "FILE:LINE: what".
struct SourceRef {
  std::string file;
  int line = 0;
};

struct Body {
  std::string name;            // the URDF link carrying the inertia
  double mass = 0;
  Mat3 inertia = Mat3::Identity();  // about the centre of mass, body axes
  Pose initial_pose;           // body frame in world, at the start
  Vec3 initial_velocity = Vec3::Zero();          // world frame, of the centre of mass
  Vec3 initial_angular_velocity = Vec3::Zero();  // world frame
};

// Every URDF link, so that tf can publish each one.
struct Link {
  std::string name;
  int body = kGround;  // body the link rides on (kGround for ground links)
  Pose in_body;        // link frame in the body frame (in world if ground)
};

enum class JointType { Revolute, Prismatic, Fixed };

// An ideal (bilateral) joint, or the kinematic pair a clearance joint replaces.
// body_a is the URDF parent, body_b the child. The joint frame is the child link
// frame (URDF convention); at joint position 0 anchor_a and anchor_b coincide and
// the relative rotation q_a^-1 q_b equals rel_rot_zero.
struct Joint {
  std::string name;
  JointType type = JointType::Revolute;
  int body_a = kGround;
  int body_b = kGround;
  Vec3 anchor_a = Vec3::Zero();  // joint origin, body_a frame
  Vec3 anchor_b = Vec3::Zero();  // joint origin, body_b frame
  Vec3 axis_a = Vec3::UnitZ();   // unit joint axis, body_a frame
  Vec3 axis_b = Vec3::UnitZ();   // the same axis, body_b frame
  Quat rel_rot_zero = Quat::Identity();  // q_a^-1 * q_b at joint position 0
  bool loop = false;        // declared as <nscd><joint> (loop closure)
  // Coordinate at the initial placement (rad or m; a tree joint's <initial>
  // position, which may be many turns): where its continuous angle starts.
  double initial_position = 0;
  int clearance = -1;       // index into Model::clearance_joints, -1 if ideal
  SourceRef src;
};

// A revolute joint with radial and axial clearance (docs/scene-format.md).
// The journal body carries the pin, the bearing body the hole; both are centred
// on the joint frame along the joint axis.
struct ClearanceJoint {
  std::string name;     // the joint's name
  int joint = -1;       // index into Model::joints
  int journal_body = kGround;
  int bearing_body = kGround;
  Vec3 journal_center = Vec3::Zero();  // joint origin, journal body frame
  Vec3 journal_axis = Vec3::UnitZ();   // journal body frame
  Vec3 bearing_center = Vec3::Zero();  // joint origin, bearing body frame
  Vec3 bearing_axis = Vec3::UnitZ();   // bearing body frame
  Vec3 bearing_ref = Vec3::UnitX();    // unit, orthogonal to bearing_axis: angle origin
  double radius = 0;         // journal radius r_j
  double radial = 0;         // radial clearance c_r
  double length = 0;         // bearing length L
  double axial = 0;          // total axial play c_a
  int bumps = 3;             // per bearing face
  double bump_radius = 0;    // section radius of a bump
  double bump_at = 0;        // pitch radius of the bumps
  double mu = 0;
  double e = 0;
  // Where the journal starts inside its bearing: its centre's offset from the
  // bore's centre, world frame at the initial placement, m (<clearance
  // initial_offset>); the bodies are moved there before the assembly.
  bool has_initial_offset = false;
  Vec3 initial_offset = Vec3::Zero();
  SourceRef src;
};

enum class ShapeType { Sphere, Capsule, Cylinder, Box, Plane, Ring, Face };

// A contact shape fixed to a body. Its frame (pose, in the body frame) gives the
// axis (z) of capsules, cylinders and rings and the outward normal (+z) of
// planes and faces.
struct Shape {
  ShapeType type = ShapeType::Sphere;
  int body = kGround;
  Pose pose;
  double radius = 0;                    // sphere, capsule, cylinder, ring
  double length = 0;                    // capsule, cylinder (along z, centred)
  Vec3 half_extents = Vec3::Zero();     // box; face: (sx/2, sy/2, 0)
  // Ring: the arc of the circle kept; cylinder: the angular extent of its
  // lateral surface. Angles (rad) from the frame's +x about +z; start + [0, span].
  double start = 0;
  double span = 6.283185307179586;      // 2 pi: the full circle
  // Cylinder: the material lies outside its lateral surface (a bore, a concave
  // guide); a ring is then kept inside it.
  bool hollow = false;
};

// A named <nscd><contact>: one shape pair, possibly several contact points.
struct ContactPair {
  std::string name;
  Shape a;
  Shape b;
  double mu = 0;
  double e = 0;
  SourceRef src;
};

enum class SpringType { Linear, Torsion };

// How a spring's scalar reaches a body when the scene says so (<force>, <couple>):
// a force along a body-fixed direction at a body-fixed point, or a body-fixed
// couple, `scale` times the scalar (the tension, or the torque on body_b).
struct SpringLoad {
  bool couple = false;
  bool on_b = false;               // the load's body: body_b, else body_a
  Vec3 point = Vec3::Zero();       // force: application point, body frame
  Vec3 direction = Vec3::UnitX();  // unit; force direction or couple axis, body frame
  double scale = 1;                // N per unit scalar (1/m for a torsion spring's force, m for a linear spring's couple)
  int line = 0;                    // its element's line in the scene
};

struct Spring {
  std::string name;
  SpringType type = SpringType::Linear;
  double stiffness = 0;
  double rest = 0;       // rest length (m) or rest angle (rad)
  double damping = 0;
  int body_a = kGround;  // linear: first <end>; torsion: joint parent, or <angle link_a>
  int body_b = kGround;  // linear: second <end>; torsion: joint child, or <angle link_b>
  Vec3 end_a = Vec3::Zero();  // linear: attachment points, body frames
  Vec3 end_b = Vec3::Zero();
  int joint = -1;        // torsion: the joint whose coordinate it reads (index into Model::joints), or -1
  // Torsion without a joint (<angle>): the angle of body_b relative to body_a about
  // an axis fixed in body_a, held as the revolute joint that would have that
  // coordinate (axis_a, rel_rot_zero; body_a, body_b; anchors unused). Read within
  // ±pi of its value at the initial placement, relative_initial.
  Joint relative;
  double relative_initial = 0;
  // Empty: the spring acts as a spring (a line force between its ends, or a pure
  // moment pair about its axis). Else these loads replace that: they do work the
  // spring's potential does not account for (energy_bookkeeping.cpp).
  std::vector<SpringLoad> loads;
  SourceRef src;
};

enum class ActuatorType { Position, Prescribed, Force, Torque };

struct Actuator {
  std::string name;
  ActuatorType type = ActuatorType::Position;
  int joint = -1;     // position; prescribed with joint=
  int body = kGround; // prescribed with link=; force; torque
  Vec3 axis = Vec3::UnitX();       // prescribed link: unit direction, world frame
  // Prescribed link: constrain="axis" prescribes only the translation along `axis` (1 row;
  // the other 5 DOF are free); the default "all" also holds them fixed (6 rows).
  bool axis_only = false;
  Vec3 point = Vec3::Zero();       // force: application point, body frame
  Vec3 direction = Vec3::UnitX();  // force: unit direction; torque: unit axis; body frame
  double kp = 0, kd = 0;
  double max_effort = 0;           // 0 = unlimited
  double initial_command = 0;
  // The scene's command schedule (`schedule` attribute): (time, value) points, times
  // non-decreasing; empty = none. bindCommandSchedules binds it unless a front-end
  // schedule (nscd_run --command, the node's ~schedule) names the same actuator.
  std::vector<std::pair<double, double>> schedule;
  SourceRef src;
};

enum class PlanarMode { None, XY };

// What the rows of ideal joints constrain in a step.
// None: the theta-average velocity theta v_{k+1} + (1 - theta) v_k, the velocity
//   the positions move with: the joint impulses do no work over the step, so a
//   mechanism turning on ideal joints keeps its energy (exactly, for theta = 1/2
//   and no other force), and its joints do not drift apart at first order.
// Moreau: v_{k+1}, as Moreau-Jean's scheme. A joint whose direction turns by
//   omega h in a step then takes (omega h)^2 of the kinetic energy every step.
enum class JointWork { None, Moreau };

// How the step length is chosen (docs/step_control.md).
// Fixed: every step is dt.
// Adaptive: dt is the first and the largest step; each step of length h is taken
//   as 2 substeps of h/2 and as 4 of h/4, their difference is the local error
//   estimate, a PI controller picks the next length from it (rejecting a step
//   whose error exceeds the tolerance), and where no contact opened, closed,
//   stuck or slipped in the step the answer is the Richardson extrapolation of
//   the two. A step with such an event, or at dt with the 4 substeps' own
//   estimate far within the tolerance, takes the 4 alone.
enum class StepControl { Fixed, Adaptive };

struct Settings {
  double dt = 1e-4;
  double theta = 0.5;
  Vec3 gravity = Vec3(0, 0, -9.81);
  double tolerance = 1e-8;          // friction-contact solver, normalised residual
  int max_iterations = 200;         // solver sweeps
  // A step whose friction-contact problem the solver leaves unsolved is taken
  // again as two steps of h/2, each of them halved again while unsolved, down to
  // h / 2^max_step_halvings, where the later rescues of rescue_policy.cpp apply.
  // Once a substep there stays unsolved, the rest of the step is not halved
  // again (its substeps already begun are taken once each, with those rescues).
  // 0: never.
  int max_step_halvings = 8;
  bool projection = true;           // combined projection after each step
  double projection_tolerance = 1e-9;  // m (and rad for orientation rows)
  int projection_max_iterations = 100;  // passes; backtracking keeps extra passes from diverging
  double activation_gamma = 0.5;    // predicted gap g + gamma h u_N
  // Extra distance (m) under which a candidate contact enters the solver even if
  // it cannot close within the step. 0 (default) skips every contact that cannot
  // close; a large value puts every candidate in the solver (it then acts as a
  // velocity-level constraint): a knob to measure what skipping saves.
  double activation_margin = 0;
  // Where the rows (normal, points, Jacobian) of an active contact are built: at
  // q_k + contact_prediction h v_k, the same feature as at q_k, as long as its
  // normal turns by less than 0.1 rad in between (else at q_k). 1 (default): the
  // end of the step predicted by v_k, as Siconos's time stepping does; 0: at q_k.
  // Gaps and activation are always those of q_k.
  double contact_prediction = 1;
  JointWork joint_work = JointWork::None;
  PlanarMode planar = PlanarMode::None;
  StepControl step_control = StepControl::Fixed;
  // Adaptive steps: a step is kept when every component of the body states
  // (position, orientation, velocity, angular velocity) of its two paths differ
  // by at most atol + rtol |value|, rotations measured by what they move a point
  // at the body's length by (docs/step_control.md), so atol is m and m/s; where a
  // contact changed mode, velocity differences count times h, as displacements.
  double rtol = 1e-3;
  double atol = 1e-6;
  // Adaptive steps: the floor of the step length, s; a step at the floor is kept
  // whatever its error (counted). 0: dt * 1e-6.
  double dt_min = 0;
  // Adaptive steps: the highest order a step extrapolates to where no contact is
  // closed and nothing nonsmooth happens in it (Aitken-Neville over paths of 2, 4,
  // 6, ... 2 max_order substeps; docs/step_control.md). 2: the coarse and fine
  // paths' Richardson combination only.
  int max_order = 6;
};

struct Model {
  std::string source_file;
  std::string world_frame = "world";  // name of the URDF root link
  std::vector<Body> bodies;
  std::vector<Link> links;
  std::vector<Joint> joints;
  std::vector<ClearanceJoint> clearance_joints;
  std::vector<ContactPair> contacts;
  std::vector<Spring> springs;
  std::vector<Actuator> actuators;
  Settings settings;

  int findBody(const std::string& name) const {
    for (size_t i = 0; i < bodies.size(); ++i)
      if (bodies[i].name == name) return static_cast<int>(i);
    return kGround - 1;  // not found
  }
  int findActuator(const std::string& name) const {
    for (size_t i = 0; i < actuators.size(); ++i)
      if (actuators[i].name == name) return static_cast<int>(i);
    return -1;
  }
  int findContact(const std::string& name) const {
    for (size_t i = 0; i < contacts.size(); ++i)
      if (contacts[i].name == name) return static_cast<int>(i);
    return -1;
  }
};

}  // namespace nscd
