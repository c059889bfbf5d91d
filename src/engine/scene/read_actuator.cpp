// <actuator>: a PD position drive, a prescribed motion, a force or a torque; its
// command comes from a topic or a schedule (the scene's own, or a front end's).
#include <stdexcept>

#include "nscd_sim/command_schedule.hpp"
#include "scene_build.hpp"

namespace nscd {

namespace {

// ---------------------------------------------------------------- actuators
int actuatedBody(const SceneBuild& sb, const XMLElement* e, const std::string& what) {
  const int l = sb.findLink(e, reqString(sb.c, e, "link"));
  if (sb.links[l].body == kGround)
    sb.c.fail(e->GetLineNum(), what + ": link " + squote(sb.links[l].name) + " is ground and cannot be actuated");
  return l;
}

// A force or torque actuator on a link: its body, and the non-zero vector
// attribute `attr` (a direction or an axis, link frame) as a unit vector in the
// body frame. Returns the link.
int linkDirection(const SceneBuild& sb, const XMLElement* e, const std::string& what,
                  const std::string& kind, const char* attr, Actuator& a) {
  if (!has(e, "link")) sb.c.fail(e->GetLineNum(), what + " (" + kind + ") needs attribute 'link'");
  const int l = actuatedBody(sb, e, what);
  a.body = sb.links[l].body;
  const Vec3 d = reqVec3(sb.c, e, attr);
  if (!(d.norm() > 1e-12)) sb.c.fail(e->GetLineNum(), what + ": " + attr + " must be non-zero");
  a.direction = sb.links[l].in_body.rotate(d).normalized();
  return l;
}

// A PD position drive on a joint.
void readPositionActuator(SceneBuild& sb, const XMLElement* e, const std::string& what, Actuator& a) {
  checkAttributes(sb.c, e, vocabularyOf("actuator", "position").attributes);
  a.type = ActuatorType::Position;
  if (!has(e, "joint")) sb.c.fail(e->GetLineNum(), what + " (position) needs attribute 'joint'");
  a.joint = sb.modelJoint(e, reqString(sb.c, e, "joint"), what);
  if (sb.m.joints[a.joint].type == JointType::Fixed)
    sb.c.fail(e->GetLineNum(), what + ": joint " + squote(sb.m.joints[a.joint].name) + " is fixed");
  a.kp = optNumber(sb.c, e, "kp", 0);
  requireRange(sb.c, e, "kp", a.kp, 0, false, kInf, false);
  a.kd = optNumber(sb.c, e, "kd", 0);
  requireRange(sb.c, e, "kd", a.kd, 0, false, kInf, false);
  a.max_effort = optNumber(sb.c, e, "max_effort", 0);
  requireRange(sb.c, e, "max_effort", a.max_effort, 0, false, kInf, false);
  a.initial_command = sb.initialPosition(a.joint);
}

// A prescribed motion: of a link along an axis (and the other 5 DOF fixed, or
// not: constrain="axis"), or of a joint's coordinate.
void readPrescribedActuator(SceneBuild& sb, const XMLElement* e, const std::string& what, Actuator& a) {
  checkAttributes(sb.c, e, vocabularyOf("actuator", "prescribed").attributes);
  a.type = ActuatorType::Prescribed;
  if (has(e, "link") && has(e, "joint")) sb.c.fail(e->GetLineNum(), what + ": give either 'link' or 'joint', not both");
  if (has(e, "link")) {
    const int l = actuatedBody(sb, e, what);
    a.body = sb.links[l].body;
    const Vec3 ax = reqVec3(sb.c, e, "axis");
    if (!(ax.norm() > 1e-12)) sb.c.fail(e->GetLineNum(), what + ": axis must be non-zero");
    a.axis = sb.links[l].world.rotate(ax).normalized();  // link frame -> world, at the initial pose
    const std::string constrain = has(e, "constrain") ? reqString(sb.c, e, "constrain") : "all";
    if (constrain == "axis") a.axis_only = true;
    else if (constrain != "all")
      sb.c.fail(e->GetLineNum(), what + ": constrain must be 'all' (the other 5 DOF fixed) or 'axis' (only the translation "
                                        "along axis prescribed), not " + squote(constrain));
  } else if (has(e, "joint")) {
    if (has(e, "constrain")) sb.c.fail(e->GetLineNum(), what + ": 'constrain' applies to link= only (a joint drive prescribes its one coordinate)");
    if (has(e, "axis")) sb.c.fail(e->GetLineNum(), what + ": 'axis' applies to link= only (a joint moves about its own axis)");
    a.joint = sb.modelJoint(e, reqString(sb.c, e, "joint"), what);
    if (sb.m.joints[a.joint].type == JointType::Fixed)
      sb.c.fail(e->GetLineNum(), what + ": joint " + squote(sb.m.joints[a.joint].name) + " is fixed");
    a.initial_command = sb.initialPosition(a.joint);
  } else {
    sb.c.fail(e->GetLineNum(), what + " (prescribed) needs attribute 'link' or 'joint'");
  }
}

}  // namespace

void readActuator(SceneBuild& sb, const XMLElement* e) {
  checkChildren(sb.c, e, vocabularyOf("actuator", "position").children);
  Actuator a;
  a.name = reqString(sb.c, e, "name");
  for (const Actuator& o : sb.m.actuators)
    if (o.name == a.name)
      sb.c.fail(e->GetLineNum(), "duplicate actuator name " + squote(a.name) + " (first at line " + std::to_string(o.src.line) + ")");
  const std::string type = reqString(sb.c, e, "type");
  const std::string what = "actuator " + squote(a.name);
  if (type == "position") {
    readPositionActuator(sb, e, what, a);
  } else if (type == "prescribed") {
    readPrescribedActuator(sb, e, what, a);
  } else if (type == "force") {
    checkAttributes(sb.c, e, vocabularyOf("actuator", "force").attributes);
    a.type = ActuatorType::Force;
    const int l = linkDirection(sb, e, what, "force", "direction", a);
    a.point = sb.links[l].in_body.apply(optVec3(sb.c, e, "xyz", Vec3::Zero()));
  } else if (type == "torque") {
    checkAttributes(sb.c, e, vocabularyOf("actuator", "torque").attributes);
    a.type = ActuatorType::Torque;
    linkDirection(sb, e, what, "torque", "axis", a);
  } else {
    sb.c.fail(e->GetLineNum(), what + ": unknown actuator type " + squote(type) + " (position, prescribed, force, torque)");
  }
  a.initial_command = optNumber(sb.c, e, "command", a.initial_command);
  if (has(e, "schedule")) {
    // The format of nscd_run --command, without the NAME= part.
    try {
      a.schedule = parseCommandSchedule(a.name + "=" + reqString(sb.c, e, "schedule")).points;
    } catch (const std::invalid_argument& err) {
      sb.c.fail(e->GetLineNum(), "attribute 'schedule' of <actuator>: " + std::string(err.what()));
    }
  }
  a.src = SourceRef{sb.c.file, e->GetLineNum()};
  sb.m.actuators.push_back(a);
}

}  // namespace nscd
