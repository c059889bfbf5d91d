// <spring>: a linear spring between two points, or a torsion spring on a joint or on
// the relative angle of two links (<angle>); by default a line force or a pure moment
// pair, or else the body-fixed loads its scalar is applied as (<force>, <couple>).
#include <cmath>

#include "scene_build.hpp"

namespace nscd {
namespace {

std::string bodyName(const SceneBuild& sb, int body) {
  return body == kGround ? std::string("ground") : "body " + squote(sb.m.bodies[body].name);
}

// <angle link_a link_b axis>: the torsion spring reads the angle of link_b's frame
// relative to link_a's about `axis` (link_a frame), 0 where the two frames coincide.
void readRelativeAngle(SceneBuild& sb, const XMLElement* x, Spring& s) {
  checkElement(sb.c, x, "angle");
  const int la = sb.findLink(x, reqString(sb.c, x, "link_a"));
  const int lb = sb.findLink(x, reqString(sb.c, x, "link_b"));
  if (sb.links[la].body == sb.links[lb].body)
    sb.c.fail(x->GetLineNum(), "<angle> of spring " + squote(s.name) + ": links " + squote(sb.links[la].name) +
                                   " and " + squote(sb.links[lb].name) + " are both on " +
                                   bodyName(sb, sb.links[la].body));
  const Vec3 axis = reqVec3(sb.c, x, "axis");
  if (!(axis.norm() > 1e-12)) sb.c.fail(x->GetLineNum(), "<angle> of spring " + squote(s.name) + ": axis must be non-zero");
  // The revolute joint whose coordinate this angle is (joint frame = link_a's frame).
  s.relative = sb.makeJoint(s.name, JointType::Revolute, la, lb, Pose{}, axis.normalized(), false, x->GetLineNum());
  const Joint& j = s.relative;
  s.body_a = j.body_a;
  s.body_b = j.body_b;
  // Its value at the initial placement, in [-pi, pi] (revoluteAngle's expression).
  const Pose A = sb.bodyWorld(j.body_a), B = sb.bodyWorld(j.body_b);
  Quat dev = (A.q.conjugate() * B.q) * j.rel_rot_zero.conjugate();
  if (dev.w() < 0) dev.coeffs() = -dev.coeffs();
  s.relative_initial = 2.0 * std::atan2(dev.vec().dot(j.axis_a), dev.w());
}

// <force link xyz direction scale> and <couple link axis scale>: the loads that
// replace the spring's own line force or moment pair.
void readLoads(SceneBuild& sb, const XMLElement* e, Spring& s) {
  for (const XMLElement* x = e->FirstChildElement(); x; x = x->NextSiblingElement()) {
    const std::string n = x->Name();
    if (n != "force" && n != "couple") continue;
    checkElement(sb.c, x, n);
    SpringLoad load;
    load.couple = n == "couple";
    load.line = x->GetLineNum();
    const std::string what = "<" + n + "> of spring " + squote(s.name);
    const int l = sb.findLink(x, reqString(sb.c, x, "link"));
    const int body = sb.links[l].body;
    if (body == kGround)
      sb.c.fail(x->GetLineNum(), what + ": link " + squote(sb.links[l].name) + " is ground, which takes no load");
    if (body != s.body_a && body != s.body_b)
      sb.c.fail(x->GetLineNum(), what + ": link " + squote(sb.links[l].name) + " is on " + bodyName(sb, body) +
                                     ", not on one of the spring's bodies (" + bodyName(sb, s.body_a) + ", " +
                                     bodyName(sb, s.body_b) + ")");
    load.on_b = body == s.body_b;
    const char* dir_attr = load.couple ? "axis" : "direction";
    const Vec3 d = reqVec3(sb.c, x, dir_attr);
    if (!(d.norm() > 1e-12)) sb.c.fail(x->GetLineNum(), what + ": " + dir_attr + " must be non-zero");
    const Pose& in = sb.links[l].in_body;
    load.direction = in.rotate(d).normalized();
    if (!load.couple) load.point = in.apply(optVec3(sb.c, x, "xyz", Vec3::Zero()));
    load.scale = reqNumber(sb.c, x, "scale");
    s.loads.push_back(load);
  }
}

// A linear spring between two <end> points; its rest length (default: no preload).
void readLinearSpring(SceneBuild& sb, const XMLElement* e, Spring& s) {
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
    sb.c.fail(e->GetLineNum(), "spring " + squote(s.name) + ": both ends are on " + bodyName(sb, body[0]));
  s.body_a = body[0];
  s.body_b = body[1];
  s.end_a = p[0];
  s.end_b = p[1];
  // No preload unless asked: the default rest length is the initial distance.
  const double d = (sb.bodyWorld(s.body_a).apply(s.end_a) - sb.bodyWorld(s.body_b).apply(s.end_b)).norm();
  s.rest = optNumber(sb.c, e, "rest_length", d);
  requireRange(sb.c, e, "rest_length", s.rest, 0, false, kInf, false);
}

// A torsion spring on a revolute joint, or on the relative angle of two links (<angle>).
void readTorsionSpring(SceneBuild& sb, const XMLElement* e, Spring& s) {
  checkElement(sb.c, e, "spring", "torsion");
  s.type = SpringType::Torsion;
  std::vector<const XMLElement*> angles;
  for (const XMLElement* x = e->FirstChildElement("angle"); x; x = x->NextSiblingElement("angle")) angles.push_back(x);
  const bool by_joint = has(e, "joint");
  if (by_joint == !angles.empty() || angles.size() > 1)
    sb.c.fail(e->GetLineNum(), "torsion spring " + squote(s.name) +
                                   " needs either a joint attribute or one <angle> child, got " +
                                   (by_joint ? std::string("the joint and ") : std::string()) +
                                   std::to_string(angles.size()) + " <angle>");
  if (by_joint) {
    const std::string jn = reqString(sb.c, e, "joint");
    s.joint = sb.modelJoint(e, jn, "torsion spring " + squote(s.name));
    const Joint& j = sb.m.joints[s.joint];
    if (j.type != JointType::Revolute)
      sb.c.fail(e->GetLineNum(), "torsion spring " + squote(s.name) + ": joint " + squote(jn) + " is " +
                                     sb.jointTypeName(s.joint) + "; a torsion spring needs a revolute or continuous joint");
    s.body_a = j.body_a;
    s.body_b = j.body_b;
  } else {
    readRelativeAngle(sb, angles[0], s);
  }
  s.rest = optNumber(sb.c, e, "rest_angle", 0);  // from the joint's URDF zero, or the links' frames aligned
}

}  // namespace

void readSpring(SceneBuild& sb, const XMLElement* e) {
  Spring s;
  s.name = reqString(sb.c, e, "name");
  for (const Spring& o : sb.m.springs)
    if (o.name == s.name)
      sb.c.fail(e->GetLineNum(), "duplicate spring name " + squote(s.name) + " (first at line " + std::to_string(o.src.line) + ")");
  const std::string type = reqString(sb.c, e, "type");
  if (type == "linear") {
    readLinearSpring(sb, e, s);
  } else if (type == "torsion") {
    readTorsionSpring(sb, e, s);
  } else {
    sb.c.fail(e->GetLineNum(), "spring " + squote(s.name) + ": unknown type " + squote(type) + " (linear, torsion)");
  }
  s.stiffness = reqNumber(sb.c, e, "stiffness");
  requireRange(sb.c, e, "stiffness", s.stiffness, 0, false, kInf, false);
  s.damping = optNumber(sb.c, e, "damping", 0);
  requireRange(sb.c, e, "damping", s.damping, 0, false, kInf, false);
  readLoads(sb, e, s);
  s.src = SourceRef{sb.c.file, e->GetLineNum()};
  sb.m.springs.push_back(s);
}

}  // namespace nscd
