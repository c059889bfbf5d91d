// Reading XML attributes and elements of a scene, each error one "FILE:LINE:
// what" line (scene_loader.cpp and the element readers share these).
#include "xml_reading.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>

#include "number_text.hpp"

namespace nscd {

std::string tag(const XMLElement* e) { return std::string("<") + e->Name() + ">"; }

std::string squote(const std::string& s) { return "'" + s + "'"; }

double toNumber(const Ctx& c, const XMLElement* e, const char* name, const std::string& v) {
  double x = 0;
  if (!parseNumber(v, x) || std::isnan(x))
    c.fail(e->GetLineNum(), std::string("attribute '") + name + "' of " + tag(e) + ": " +
                                squote(v) + " is not a number");
  if (!std::isfinite(x))
    c.fail(e->GetLineNum(), std::string("attribute '") + name + "' of " + tag(e) + ": " +
                                squote(v) + " is not finite");
  return x;
}

namespace {

bool isAllowed(const char* name, const std::vector<std::string>& allowed) {
  for (const std::string& n : allowed)
    if (n == name) return true;
  return false;
}

// " (allowed: a, b)" with each name wrapped as pre + name + post, or " (it takes none)".
std::string allowedList(const std::vector<std::string>& allowed, const char* pre,
                        const char* post) {
  std::string list;
  for (const std::string& n : allowed) list += (list.empty() ? "" : ", ") + std::string(pre) + n + post;
  return list.empty() ? " (it takes none)" : " (allowed: " + list + ")";
}

}  // namespace

void checkAttributes(const Ctx& c, const XMLElement* e, const std::vector<std::string>& allowed) {
  for (const XMLAttribute* a = e->FirstAttribute(); a; a = a->Next())
    if (!isAllowed(a->Name(), allowed))
      c.fail(e->GetLineNum(), std::string("unknown attribute '") + a->Name() + "' on " + tag(e) +
                                  allowedList(allowed, "", ""));
}

void checkChildren(const Ctx& c, const XMLElement* e, const std::vector<std::string>& allowed) {
  for (const XMLElement* ch = e->FirstChildElement(); ch; ch = ch->NextSiblingElement())
    if (!isAllowed(ch->Name(), allowed))
      c.fail(ch->GetLineNum(), "unknown element " + tag(ch) + " in " + tag(e) +
                                   allowedList(allowed, "<", ">"));
}

void checkElement(const Ctx& c, const XMLElement* e, const std::string& element,
                  const std::string& variant) {
  const SceneElementVocabulary& v = vocabularyOf(element, variant);
  checkAttributes(c, e, v.attributes);
  checkChildren(c, e, v.children);
}

bool has(const XMLElement* e, const char* name) { return e->Attribute(name) != nullptr; }

std::string reqString(const Ctx& c, const XMLElement* e, const char* name) {
  const char* v = e->Attribute(name);
  if (!v) c.fail(e->GetLineNum(), tag(e) + " is missing attribute '" + name + "'");
  if (trim(v).empty()) c.fail(e->GetLineNum(), std::string("attribute '") + name + "' of " + tag(e) + " is empty");
  return v;  // names are compared exactly, as urdfdom does
}

double optNumber(const Ctx& c, const XMLElement* e, const char* name, double def) {
  const char* v = e->Attribute(name);
  return v ? toNumber(c, e, name, v) : def;
}

double reqNumber(const Ctx& c, const XMLElement* e, const char* name) {
  if (!has(e, name)) c.fail(e->GetLineNum(), tag(e) + " is missing attribute '" + name + "'");
  return optNumber(c, e, name, 0);
}

Vec3 toVec3(const Ctx& c, const XMLElement* e, const char* name, const std::string& v) {
  std::istringstream in(v);
  std::vector<std::string> parts;
  for (std::string w; in >> w;) parts.push_back(w);
  if (parts.size() != 3)
    c.fail(e->GetLineNum(), std::string("attribute '") + name + "' of " + tag(e) +
                                ": expected 3 numbers, got " + squote(v));
  Vec3 r;
  for (int i = 0; i < 3; ++i) r[i] = toNumber(c, e, name, parts[i]);
  return r;
}

Vec3 optVec3(const Ctx& c, const XMLElement* e, const char* name, const Vec3& def) {
  const char* v = e->Attribute(name);
  return v ? toVec3(c, e, name, v) : def;
}

Vec3 reqVec3(const Ctx& c, const XMLElement* e, const char* name) {
  if (!has(e, name)) c.fail(e->GetLineNum(), tag(e) + " is missing attribute '" + name + "'");
  return optVec3(c, e, name, Vec3::Zero());
}

int optInt(const Ctx& c, const XMLElement* e, const char* name, int def) {
  const char* v = e->Attribute(name);
  if (!v) return def;
  const std::string s = trim(v);
  int x = 0;
  auto r = std::from_chars(s.data(), s.data() + s.size(), x);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size())
    c.fail(e->GetLineNum(), std::string("attribute '") + name + "' of " + tag(e) + ": " +
                                squote(v) + " is not an integer");
  return x;
}

Quat rpyToQuat(const Vec3& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
      .normalized();
}

Pose originChild(const Ctx& c, const XMLElement* e) {
  const XMLElement* o = e->FirstChildElement("origin");
  if (!o) return Pose{};
  if (o->NextSiblingElement("origin"))
    c.fail(o->NextSiblingElement("origin")->GetLineNum(), "more than one <origin> in " + tag(e));
  checkElement(c, o, "origin");
  Pose p;
  p.p = optVec3(c, o, "xyz", Vec3::Zero());
  p.q = rpyToQuat(optVec3(c, o, "rpy", Vec3::Zero()));
  return p;
}

void requireRange(const Ctx& c, const XMLElement* e, const char* name, double x, double lo,
                  bool lo_open, double hi, bool hi_open) {
  const bool ok = (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  if (ok) return;
  std::string range;
  if (std::isinf(hi)) range = std::string(lo_open ? "> " : ">= ") + num(lo);
  else range = std::string("in ") + (lo_open ? "(" : "[") + num(lo) + ", " + num(hi) + (hi_open ? ")" : "]");
  c.fail(e->GetLineNum(), std::string("attribute '") + name + "' of " + tag(e) + " must be " +
                              range + ", got " + num(x));
}

bool blank(const std::string& s) {
  for (char ch : s)
    if (!std::isspace(static_cast<unsigned char>(ch))) return false;
  return true;
}

}  // namespace nscd
