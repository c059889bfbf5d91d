// <contact>: a named pair of shapes, each on a link, with friction and restitution.
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
  }
  return "?";
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
  } else {
    sb.c.fail(e->GetLineNum(), "unknown shape type " + squote(type) + " (sphere, capsule, cylinder, box, plane)");
  }
  if (s.type == ShapeType::Sphere || s.type == ShapeType::Capsule || s.type == ShapeType::Cylinder) {
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
    const ShapeType all[] = {ShapeType::Sphere, ShapeType::Capsule, ShapeType::Cylinder, ShapeType::Box, ShapeType::Plane};
    for (int i = 0; i < 5; ++i)
      for (int k = i; k < 5; ++k)
        if (shapePairSupported(all[i], all[k]))
          list += (list.empty() ? "" : ", ") + std::string(shapeName(all[i])) + "-" + shapeName(all[k]);
    sb.c.fail(e->GetLineNum(), "contact " + squote(cp.name) + ": " + shapeName(cp.a.type) + "-" + shapeName(cp.b.type) +
                                 " pairs are not supported (supported: " + list + ")");
  }
  cp.src = SourceRef{sb.c.file, e->GetLineNum()};
  sb.m.contacts.push_back(cp);
}

}  // namespace nscd
