// <initial>: a tree joint's initial position, or a body's initial velocity.
#include "scene_build.hpp"

namespace nscd {

void readInitial(SceneBuild& sb, const XMLElement* e) {
  if (has(e, "joint")) {
    checkAttributes(sb.c, e, vocabularyOf("initial", "joint").attributes);
    const std::string name = reqString(sb.c, e, "joint");
    auto it = sb.joint_index.find(name);
    if (it == sb.joint_index.end()) {
      if (sb.loop_line.count(name))
        sb.c.fail(e->GetLineNum(), "<initial>: loop joint " + squote(name) + " does not place anything; set the position of a tree joint instead");
      sb.c.fail(e->GetLineNum(), "<initial>: unknown joint " + squote(name));
    }
    JointInfo& j = sb.joints[it->second];
    if (j.type != "revolute" && j.type != "continuous" && j.type != "prismatic")
      sb.c.fail(e->GetLineNum(), "<initial>: joint " + squote(name) + " is " + j.type +
                                   "; only revolute, continuous and prismatic joints take a position");
    if (j.has_initial) sb.c.fail(e->GetLineNum(), "<initial>: joint " + squote(name) + " given twice");
    j.has_initial = true;
    j.initial = reqNumber(sb.c, e, "position");
  } else if (has(e, "link")) {
    checkAttributes(sb.c, e, vocabularyOf("initial", "link").attributes);
    const int l = sb.findLink(e, reqString(sb.c, e, "link"));
    const int b = sb.links[l].body;
    if (b == kGround)
      sb.c.fail(e->GetLineNum(), "<initial>: link " + squote(sb.links[l].name) + " is ground and cannot move");
    for (const auto& v : sb.initial_v)
      if (v.first == b)
        sb.c.fail(e->GetLineNum(), "<initial>: velocity of body " + squote(sb.m.bodies[b].name) + " given twice");
    sb.initial_v.push_back({b, Vec3(optNumber(sb.c, e, "vx", 0), optNumber(sb.c, e, "vy", 0), optNumber(sb.c, e, "vz", 0))});
    sb.initial_w.push_back({b, Vec3(optNumber(sb.c, e, "wx", 0), optNumber(sb.c, e, "wy", 0), optNumber(sb.c, e, "wz", 0))});
  } else {
    sb.c.fail(e->GetLineNum(), "<initial> needs attribute 'joint' (with 'position') or 'link' (with velocities)");
  }
}

}  // namespace nscd
