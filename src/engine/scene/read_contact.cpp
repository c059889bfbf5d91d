// <contact>: a named pair of shapes, each on a link, with friction and restitution.
#include <algorithm>
#include <sstream>
#include <vector>

#include "nscd_sim/contact_geometry.hpp"
#include "scene_build.hpp"

namespace nscd {

namespace {

// ---------------------------------------------------------------- contacts
const char* shapeName(ShapeType t) {
  switch (t) {
    case ShapeType::Sphere: return "sphere";
    case ShapeType::Capsule: return "capsule";
    case ShapeType::Cylinder: return "cylinder";
    case ShapeType::Box: return "box";
    case ShapeType::Plane: return "plane";
    case ShapeType::Ring: return "ring";
    case ShapeType::Face: return "face";
  }
  return "?";
}

constexpr double kTwoPi = 6.283185307179586;

// Optional `start` and `span` (rad) of a ring or cylinder: span in (0, 2 pi]
// (a value that rounds 2 pi up by 1e-9 relative is taken as 2 pi).
void readArc(SceneBuild& sb, const XMLElement* e, Shape& s) {
  s.start = optNumber(sb.c, e, "start", 0);
  s.span = optNumber(sb.c, e, "span", kTwoPi);
  requireRange(sb.c, e, "span", s.span, 0, true, kTwoPi * (1 + 1e-9), false);
  s.span = std::min(s.span, kTwoPi);
}

// Optional `hollow` of a cylinder: "true" or "false" (default).
bool readHollow(SceneBuild& sb, const XMLElement* e) {
  if (!has(e, "hollow")) return false;
  const std::string v = reqString(sb.c, e, "hollow");
  if (v == "true") return true;
  if (v == "false") return false;
  sb.c.fail(e->GetLineNum(), "attribute 'hollow' of <shape> must be 'true' or 'false', got " + squote(v));
  return false;
}

// `size="sx sy"` of a face: two numbers > 0.
Vec3 readFaceHalfSize(SceneBuild& sb, const XMLElement* e) {
  const std::string v = reqString(sb.c, e, "size");
  std::istringstream in(v);
  std::vector<std::string> parts;
  for (std::string w; in >> w;) parts.push_back(w);
  if (parts.size() != 2)
    sb.c.fail(e->GetLineNum(), "attribute 'size' of <shape> type 'face': expected 2 numbers, got " + squote(v));
  const double sx = toNumber(sb.c, e, "size", parts[0]), sy = toNumber(sb.c, e, "size", parts[1]);
  if (!(sx > 0 && sy > 0))
    sb.c.fail(e->GetLineNum(), "attribute 'size' of <shape> type 'face' must be 2 numbers > 0, got " + squote(v));
  return Vec3(0.5 * sx, 0.5 * sy, 0);
}

Shape readShape(SceneBuild& sb, const XMLElement* e) {
  checkChildren(sb.c, e, vocabularyOf("shape", "sphere").children);
  const int l = sb.findLink(e, reqString(sb.c, e, "link"));
  const std::string type = reqString(sb.c, e, "type");
  Shape s;
  if (type == "sphere") {
    checkAttributes(sb.c, e, vocabularyOf("shape", "sphere").attributes);
    s.type = ShapeType::Sphere;
  } else if (type == "capsule" || type == "cylinder") {
    checkAttributes(sb.c, e, vocabularyOf("shape", type).attributes);
    s.type = type == "capsule" ? ShapeType::Capsule : ShapeType::Cylinder;
    s.length = reqNumber(sb.c, e, "length");
    requireRange(sb.c, e, "length", s.length, 0, true, kInf, false);
    if (s.type == ShapeType::Cylinder) {
      readArc(sb, e, s);
      s.hollow = readHollow(sb, e);
    }
  } else if (type == "box") {
    checkAttributes(sb.c, e, vocabularyOf("shape", "box").attributes);
    s.type = ShapeType::Box;
    const Vec3 size = reqVec3(sb.c, e, "size");
    if (!(size.minCoeff() > 0))
      sb.c.fail(e->GetLineNum(), "attribute 'size' of <shape> must be 3 numbers > 0");
    s.half_extents = 0.5 * size;
  } else if (type == "plane") {
    checkAttributes(sb.c, e, vocabularyOf("shape", "plane").attributes);
    s.type = ShapeType::Plane;
  } else if (type == "ring") {
    checkAttributes(sb.c, e, vocabularyOf("shape", "ring").attributes);
    s.type = ShapeType::Ring;
    readArc(sb, e, s);
  } else if (type == "face") {
    checkAttributes(sb.c, e, vocabularyOf("shape", "face").attributes);
    s.type = ShapeType::Face;
    s.half_extents = readFaceHalfSize(sb, e);
  } else {
    sb.c.fail(e->GetLineNum(), "unknown shape type " + squote(type) + " (sphere, capsule, cylinder, box, plane, ring, face)");
  }
  if (s.type == ShapeType::Sphere || s.type == ShapeType::Capsule || s.type == ShapeType::Cylinder ||
      s.type == ShapeType::Ring) {
    s.radius = reqNumber(sb.c, e, "radius");
    requireRange(sb.c, e, "radius", s.radius, 0, true, kInf, false);
  }
  s.body = sb.links[l].body;
  s.pose = sb.links[l].in_body * originChild(sb.c, e);
  return s;
}

}  // namespace

void readContact(SceneBuild& sb, const XMLElement* e) {
  checkElement(sb.c, e, "contact");
  ContactPair cp;
  cp.name = reqString(sb.c, e, "name");
  for (const ContactPair& o : sb.m.contacts)
    if (o.name == cp.name)
      sb.c.fail(e->GetLineNum(), "duplicate contact name " + squote(cp.name) + " (first at line " + std::to_string(o.src.line) + ")");
  cp.mu = optNumber(sb.c, e, "mu", 0);
  requireRange(sb.c, e, "mu", cp.mu, 0, false, kInf, false);
  cp.e = optNumber(sb.c, e, "e", 0);
  requireRange(sb.c, e, "e", cp.e, 0, false, 1, false);
  std::vector<const XMLElement*> shapes;
  for (const XMLElement* s = e->FirstChildElement("shape"); s; s = s->NextSiblingElement("shape")) shapes.push_back(s);
  if (shapes.size() != 2)
    sb.c.fail(e->GetLineNum(), "contact " + squote(cp.name) + " needs exactly two <shape>, got " + std::to_string(shapes.size()));
  cp.a = readShape(sb, shapes[0]);
  cp.b = readShape(sb, shapes[1]);
  if (cp.a.body == cp.b.body)
    sb.c.fail(e->GetLineNum(), "contact " + squote(cp.name) + ": both shapes are on " +
                                 (cp.a.body == kGround ? std::string("ground") : "body " + squote(sb.m.bodies[cp.a.body].name)));
  if (!shapePairSupported(cp.a.type, cp.b.type)) {
    std::string list;
    const ShapeType all[] = {ShapeType::Sphere, ShapeType::Capsule, ShapeType::Cylinder, ShapeType::Box,
                             ShapeType::Plane, ShapeType::Ring, ShapeType::Face};
    const int count = sizeof(all) / sizeof(all[0]);
    for (int i = 0; i < count; ++i)
      for (int k = i; k < count; ++k)
        if (shapePairSupported(all[i], all[k]))
          list += (list.empty() ? "" : ", ") + std::string(shapeName(all[i])) + "-" + shapeName(all[k]);
    sb.c.fail(e->GetLineNum(), "contact " + squote(cp.name) + ": " + shapeName(cp.a.type) + "-" + shapeName(cp.b.type) +
                                 " pairs are not supported (supported: " + list + ")");
  }
  const Shape& other_of_hollow = cp.a.hollow ? cp.b : cp.a;
  if ((cp.a.hollow || cp.b.hollow) && other_of_hollow.type != ShapeType::Ring)
    sb.c.fail(e->GetLineNum(), "contact " + squote(cp.name) + ": a hollow cylinder pairs only with a ring, not a " +
                                 shapeName(other_of_hollow.type));
  cp.src = SourceRef{sb.c.file, e->GetLineNum()};
  sb.m.contacts.push_back(cp);
}

}  // namespace nscd
