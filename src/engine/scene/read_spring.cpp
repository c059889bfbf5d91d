// <spring>: a linear spring between two points, or a torsion spring on a joint.
#include "scene_build.hpp"

namespace nscd {

// ---------------------------------------------------------------- springs
void readSpring(SceneBuild& sb, const XMLElement* e) {
  Spring s;
  s.name = reqString(sb.c, e, "name");
  for (const Spring& o : sb.m.springs)
    if (o.name == s.name)
      sb.c.fail(e->GetLineNum(), "duplicate spring name " + squote(s.name) + " (first at line " + std::to_string(o.src.line) + ")");
  const std::string type = reqString(sb.c, e, "type");
  if (type == "linear") {
    checkElement(sb.c, e, "spring", "linear");
    s.type = SpringType::Linear;
    std::vector<const XMLElement*> ends;
    for (const XMLElement* x = e->FirstChildElement("end"); x; x = x->NextSiblingElement("end")) ends.push_back(x);
    if (ends.size() != 2)
      sb.c.fail(e->GetLineNum(), "spring " + squote(s.name) + " needs exactly two <end>, got " + std::to_string(ends.size()));
    int body[2];
    Vec3 p[2];
    for (int i = 0; i < 2; ++i) {
      checkElement(sb.c, ends[i], "end");
      const int l = sb.findLink(ends[i], reqString(sb.c, ends[i], "link"));
      body[i] = sb.links[l].body;
      p[i] = sb.links[l].in_body.apply(optVec3(sb.c, ends[i], "xyz", Vec3::Zero()));
    }
    if (body[0] == body[1])
      sb.c.fail(e->GetLineNum(), "spring " + squote(s.name) + ": both ends are on " +
                                   (body[0] == kGround ? std::string("ground") : "body " + squote(sb.m.bodies[body[0]].name)));
    s.body_a = body[0];
    s.body_b = body[1];
    s.end_a = p[0];
    s.end_b = p[1];
    // No preload unless asked: the default rest length is the initial distance.
    const double d = (sb.bodyWorld(s.body_a).apply(s.end_a) - sb.bodyWorld(s.body_b).apply(s.end_b)).norm();
    s.rest = optNumber(sb.c, e, "rest_length", d);
    requireRange(sb.c, e, "rest_length", s.rest, 0, false, kInf, false);
  } else if (type == "torsion") {
    checkElement(sb.c, e, "spring", "torsion");
    s.type = SpringType::Torsion;
    const std::string jn = reqString(sb.c, e, "joint");
    s.joint = sb.modelJoint(e, jn, "torsion spring " + squote(s.name));
    const Joint& j = sb.m.joints[s.joint];
    if (j.type != JointType::Revolute)
      sb.c.fail(e->GetLineNum(), "torsion spring " + squote(s.name) + ": joint " + squote(jn) + " is " +
                                   sb.jointTypeName(s.joint) + "; a torsion spring needs a revolute or continuous joint");
    s.body_a = j.body_a;
    s.body_b = j.body_b;
    s.rest = optNumber(sb.c, e, "rest_angle", 0);  // from the URDF zero of the joint
  } else {
    sb.c.fail(e->GetLineNum(), "spring " + squote(s.name) + ": unknown type " + squote(type) + " (linear, torsion)");
  }
  s.stiffness = reqNumber(sb.c, e, "stiffness");
  requireRange(sb.c, e, "stiffness", s.stiffness, 0, false, kInf, false);
  s.damping = optNumber(sb.c, e, "damping", 0);
  requireRange(sb.c, e, "damping", s.damping, 0, false, kInf, false);
  s.src = SourceRef{sb.c.file, e->GetLineNum()};
  sb.m.springs.push_back(s);
}

}  // namespace nscd
