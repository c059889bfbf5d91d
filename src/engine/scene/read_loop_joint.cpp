// A loop-closing <joint> in <nscd>: URDF meaning, but it does not place its child.
#include "scene_build.hpp"

namespace nscd {

void readLoopJoint(SceneBuild& sb, const XMLElement* e) {
  checkElement(sb.c, e, "joint");
  const std::string name = reqString(sb.c, e, "name");
  if (sb.joint_index.count(name))
    sb.c.fail(e->GetLineNum(), "duplicate joint name " + squote(name) + " (URDF joint at line " +
                                 std::to_string(sb.joints[sb.joint_index[name]].elem->GetLineNum()) + ")");
  if (sb.loop_line.count(name))
    sb.c.fail(e->GetLineNum(), "duplicate joint name " + squote(name) + " (first at line " +
                                 std::to_string(sb.loop_line[name]) + ")");
  const std::string type = reqString(sb.c, e, "type");
  JointType t;
  if (type == "revolute" || type == "continuous") t = JointType::Revolute;
  else if (type == "prismatic") t = JointType::Prismatic;
  else if (type == "fixed") t = JointType::Fixed;
  else sb.c.fail(e->GetLineNum(), "loop joint " + squote(name) + ": type " + squote(type) +
                                " is not supported (revolute, continuous, prismatic, fixed)");
  const int parent = sb.findLink(e, reqString(sb.c, e, "parent"));
  const int child = sb.findLink(e, reqString(sb.c, e, "child"));
  const Pose origin = originChild(sb.c, e);
  Vec3 axis = Vec3::UnitX();
  if (const XMLElement* a = e->FirstChildElement("axis")) {
    if (a->NextSiblingElement("axis")) sb.c.fail(a->NextSiblingElement("axis")->GetLineNum(), "more than one <axis> in <joint>");
    checkAttributes(sb.c, a, vocabularyOf("axis").attributes);
    axis = reqVec3(sb.c, a, "xyz");
    if (!(axis.norm() > 1e-12)) sb.c.fail(a->GetLineNum(), "joint " + squote(name) + ": axis must be non-zero");
    axis.normalize();
  }
  if (t == JointType::Fixed) axis = Vec3::UnitX();
  sb.loop_line[name] = e->GetLineNum();
  sb.model_joint_by_name[name] = static_cast<int>(sb.m.joints.size());
  sb.m.joints.push_back(sb.makeJoint(name, t, parent, child, origin, axis, true, e->GetLineNum()));
}

}  // namespace nscd
