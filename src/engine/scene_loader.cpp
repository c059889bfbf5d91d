// Scene loader: URDF + <nscd> annotations -> Model (shared spec scene-format.md).
//
// Two parsers read the same text: tinyxml2 for structure, line numbers and the
// <nscd> elements, urdfdom for the URDF values (origins, axes, inertials), so the
// URDF meaning is exactly what every other URDF tool sees. Everything is built
// into a local Model that is returned only when the whole scene is valid.
#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "nscd_sim/clearance_geometry.hpp"
#include "nscd_sim/contact_geometry.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "number_text.hpp"

namespace nscd {
namespace {

using tinyxml2::XMLAttribute;
using tinyxml2::XMLDocument;
using tinyxml2::XMLElement;

constexpr double kMaxMass = 1e6;     // kg
constexpr double kMaxInertia = 1e6;  // kg m^2

// ------------------------------------------------------------------ messages

struct Ctx {
  std::string file;
  [[noreturn]] void fail(int line, const std::string& what) const {
    if (line > 0) throw SceneError(file + ":" + std::to_string(line) + ": " + what);
    throw SceneError(file + ": " + what);
  }
};

std::string num(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

std::string tag(const XMLElement* e) { return std::string("<") + e->Name() + ">"; }

std::string squote(const std::string& s) { return "'" + s + "'"; }

// --------------------------------------------------------------- attributes

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

bool isAllowed(const char* name, std::initializer_list<const char*> allowed) {
  for (const char* n : allowed)
    if (std::strcmp(n, name) == 0) return true;
  return false;
}

// " (allowed: a, b)" with each name wrapped as pre + name + post, or " (it takes none)".
std::string allowedList(std::initializer_list<const char*> allowed, const char* pre,
                        const char* post) {
  std::string list;
  for (const char* n : allowed) list += (list.empty() ? "" : ", ") + std::string(pre) + n + post;
  return list.empty() ? " (it takes none)" : " (allowed: " + list + ")";
}

// Every attribute of e must be in `allowed`.
void checkAttributes(const Ctx& c, const XMLElement* e, std::initializer_list<const char*> allowed) {
  for (const XMLAttribute* a = e->FirstAttribute(); a; a = a->Next())
    if (!isAllowed(a->Name(), allowed))
      c.fail(e->GetLineNum(), std::string("unknown attribute '") + a->Name() + "' on " + tag(e) +
                                  allowedList(allowed, "", ""));
}

// Every child element of e must be named in `allowed`.
void checkChildren(const Ctx& c, const XMLElement* e, std::initializer_list<const char*> allowed) {
  for (const XMLElement* ch = e->FirstChildElement(); ch; ch = ch->NextSiblingElement())
    if (!isAllowed(ch->Name(), allowed))
      c.fail(ch->GetLineNum(), "unknown element " + tag(ch) + " in " + tag(e) +
                                   allowedList(allowed, "<", ">"));
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

// URDF roll-pitch-yaw (fixed axes x, y, z): R = Rz(yaw) Ry(pitch) Rx(roll).
Quat rpyToQuat(const Vec3& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
      .normalized();
}

// The optional single <origin xyz rpy> child of e.
Pose originChild(const Ctx& c, const XMLElement* e) {
  const XMLElement* o = e->FirstChildElement("origin");
  if (!o) return Pose{};
  if (o->NextSiblingElement("origin"))
    c.fail(o->NextSiblingElement("origin")->GetLineNum(), "more than one <origin> in " + tag(e));
  checkAttributes(c, o, {"xyz", "rpy"});
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

constexpr double kInf = std::numeric_limits<double>::infinity();

// ------------------------------------------------------------- URDF pre-pass

struct LinkInfo {
  std::string name;
  const XMLElement* elem = nullptr;
  int parent_joint = -1;       // index into joints, -1 for the root
  std::vector<int> child_joints;
  bool inertial = false;
  int body = kGround;
  Pose in_body;                // link frame in its body frame (world for ground)
  Pose world;                  // initial placement
};

struct JointInfo {
  std::string name;
  const XMLElement* elem = nullptr;
  std::string type;            // URDF type string
  int parent = -1, child = -1; // link indices
  Pose origin;                 // joint frame in parent link frame (zero position)
  Vec3 axis = Vec3::UnitX();   // unit, joint frame
  int model_joint = -1;        // index into Model::joints, -1 if none
  bool has_initial = false;
  double initial = 0;
};

const std::set<std::string> kUrdfJointTypes = {"revolute", "continuous", "prismatic", "fixed",
                                               "floating", "planar"};

// Numeric URDF attributes of a <link> or <joint> are checked here so that NaN, inf
// and typos get a line (urdfdom would only say that something failed).
void checkUrdfNumbers(const Ctx& c, const XMLElement* e) {
  for (const XMLElement* ch = e->FirstChildElement(); ch; ch = ch->NextSiblingElement()) {
    const std::string n = ch->Name();
    if (n == "origin") {
      if (has(ch, "xyz")) toVec3(c, ch, "xyz", ch->Attribute("xyz"));
      if (has(ch, "rpy")) toVec3(c, ch, "rpy", ch->Attribute("rpy"));
    } else if (n == "axis") {
      if (has(ch, "xyz")) toVec3(c, ch, "xyz", ch->Attribute("xyz"));
    } else if (n == "mass") {
      if (has(ch, "value")) toNumber(c, ch, "value", ch->Attribute("value"));
    } else if (n == "inertia") {
      for (const char* k : {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"})
        if (has(ch, k)) toNumber(c, ch, k, ch->Attribute(k));
    }
    checkUrdfNumbers(c, ch);
  }
}

// Collects urdfdom's error messages instead of letting it print them.
class CaptureErrors : public console_bridge::OutputHandler {
 public:
  std::vector<std::string> errors;
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) errors.push_back(text);
  }
};

struct CaptureGuard {
  CaptureErrors cap;
  console_bridge::LogLevel old_level;
  CaptureGuard() : old_level(console_bridge::getLogLevel()) {
    console_bridge::useOutputHandler(&cap);
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_ERROR);
  }
  ~CaptureGuard() {
    console_bridge::restorePreviousOutputHandler();
    console_bridge::setLogLevel(old_level);
  }
};

Pose fromUrdf(const urdf::Pose& p) {
  Pose r;
  r.p = Vec3(p.position.x, p.position.y, p.position.z);
  r.q = Quat(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z);
  if (!std::isfinite(r.q.norm()) || r.q.norm() < 1e-12) r.q = Quat::Identity();
  r.q.normalize();
  return r;
}

// Pose of a joint at position q relative to its zero position (joint frame).
Pose jointMotion(const JointInfo& j, double q) {
  Pose m;
  if (j.type == "revolute" || j.type == "continuous") m.q = Quat(Eigen::AngleAxisd(q, j.axis));
  else if (j.type == "prismatic") m.p = q * j.axis;
  return m;
}

// ----------------------------------------------------------------- the loader

class Loader {
 public:
  Loader(const std::string& text, const std::string& name) : c_{name}, text_(text) {}

  Model load(const std::vector<SettingOverride>& overrides) {
    m_.source_file = c_.file;
    parseXml();
    prepassUrdf();
    parseUrdfdom();
    collectNscd();
    readSimulation(overrides);
    buildBodies();
    buildUrdfJoints();
    for (const XMLElement* e : nscd_["joint"]) readLoopJoint(e);
    for (const XMLElement* e : nscd_["initial"]) readInitial(e);
    place();
    for (const XMLElement* e : nscd_["clearance"]) readClearance(e);
    for (const XMLElement* e : nscd_["contact"]) readContact(e);
    for (const XMLElement* e : nscd_["spring"]) readSpring(e);
    for (const XMLElement* e : nscd_["actuator"]) readActuator(e);
    return std::move(m_);
  }

 private:
  Ctx c_;
  std::string text_;
  XMLDocument doc_;
  const XMLElement* robot_ = nullptr;
  std::vector<LinkInfo> links_;
  std::vector<JointInfo> joints_;
  std::map<std::string, int> link_index_, joint_index_;
  int root_ = -1;
  std::map<std::string, std::vector<const XMLElement*>> nscd_;
  std::map<std::string, int> model_joint_by_name_;  // URDF and loop joints in Model::joints
  std::map<std::string, int> loop_line_;            // loop joint name -> line
  std::vector<std::pair<int, Vec3>> initial_v_, initial_w_;
  Model m_;

  // ---------------------------------------------------------------- XML
  void parseXml() {
    doc_.Parse(text_.c_str(), text_.size());
    if (doc_.Error()) {
      // tinyxml2's detail, if any, follows the line number: "... Line number=N: XMLElement name=x".
      std::string detail = doc_.ErrorStr() ? doc_.ErrorStr() : "";
      const size_t ln = detail.find("Line number=");
      const size_t colon = ln == std::string::npos ? std::string::npos : detail.find(": ", ln);
      detail = colon == std::string::npos ? "" : detail.substr(colon + 2);
      const size_t nm = detail.find("name=");
      const std::string elem = nm == std::string::npos ? "" : " <" + detail.substr(nm + 5) + ">";
      std::string what;
      switch (doc_.ErrorID()) {
        case tinyxml2::XML_ERROR_PARSING: what = "unterminated element (truncated file?)"; break;
        case tinyxml2::XML_ERROR_MISMATCHED_ELEMENT: what = "mismatched closing tag of" + elem; break;
        case tinyxml2::XML_ERROR_PARSING_ATTRIBUTE: what = "malformed attribute in" + elem; break;
        case tinyxml2::XML_ERROR_PARSING_ELEMENT: what = "malformed element" + elem; break;
        case tinyxml2::XML_ERROR_PARSING_COMMENT: what = "unterminated comment"; break;
        case tinyxml2::XML_ERROR_PARSING_TEXT: what = "malformed text"; break;
        case tinyxml2::XML_ERROR_PARSING_CDATA: what = "malformed CDATA section"; break;
        case tinyxml2::XML_ERROR_PARSING_DECLARATION: what = "malformed declaration"; break;
        case tinyxml2::XML_ERROR_PARSING_UNKNOWN: what = "malformed markup"; break;
        case tinyxml2::XML_ERROR_EMPTY_DOCUMENT: what = "no XML element"; break;
        case tinyxml2::XML_ELEMENT_DEPTH_EXCEEDED: what = "elements nested too deeply"; break;
        default: {
          what = XMLDocument::ErrorIDToName(doc_.ErrorID());
          if (!elem.empty()) what += " in" + elem;
        }
      }
      for (char& ch : what)
        if (ch == '\n' || ch == '\r') ch = ' ';
      c_.fail(doc_.ErrorLineNum(), "XML error: " + what);
    }
    robot_ = doc_.RootElement();
    if (!robot_) c_.fail(0, "not a URDF: no root element");
    if (std::string(robot_->Name()) != "robot")
      c_.fail(robot_->GetLineNum(), "not a URDF: root element is " + tag(robot_) + ", expected <robot>");
  }

  int linkLine(int i) const { return links_[i].elem->GetLineNum(); }

  int findLink(const XMLElement* e, const std::string& name) const {
    auto it = link_index_.find(name);
    if (it == link_index_.end()) c_.fail(e->GetLineNum(), "unknown link " + squote(name));
    return it->second;
  }

  // Tree structure from tinyxml2, so every URDF-level error has a line.
  void prepassUrdf() {
    if (!has(robot_, "name")) c_.fail(robot_->GetLineNum(), "<robot> is missing attribute 'name'");
    for (const XMLElement* e = robot_->FirstChildElement("link"); e; e = e->NextSiblingElement("link")) {
      const std::string n = reqString(c_, e, "name");
      if (link_index_.count(n))
        c_.fail(e->GetLineNum(), "duplicate link name " + squote(n) + " (first at line " +
                                     std::to_string(linkLine(link_index_[n])) + ")");
      link_index_[n] = static_cast<int>(links_.size());
      LinkInfo li;
      li.name = n;
      li.elem = e;
      li.inertial = e->FirstChildElement("inertial") != nullptr;
      links_.push_back(li);
    }
    if (links_.empty()) c_.fail(robot_->GetLineNum(), "<robot> has no <link>");
    for (const XMLElement* e = robot_->FirstChildElement("joint"); e; e = e->NextSiblingElement("joint")) {
      JointInfo j;
      j.name = reqString(c_, e, "name");
      j.elem = e;
      if (joint_index_.count(j.name))
        c_.fail(e->GetLineNum(), "duplicate joint name " + squote(j.name) + " (first at line " +
                                     std::to_string(joints_[joint_index_[j.name]].elem->GetLineNum()) + ")");
      j.type = reqString(c_, e, "type");
      if (!kUrdfJointTypes.count(j.type))
        c_.fail(e->GetLineNum(), "joint " + squote(j.name) + ": unknown joint type " + squote(j.type));
      if (j.type == "planar")
        c_.fail(e->GetLineNum(), "joint " + squote(j.name) + ": planar joints are not supported");
      const XMLElement* p = e->FirstChildElement("parent");
      const XMLElement* ch = e->FirstChildElement("child");
      if (!p || !has(p, "link")) c_.fail(e->GetLineNum(), "joint " + squote(j.name) + " has no <parent link=\"...\"/>");
      if (!ch || !has(ch, "link")) c_.fail(e->GetLineNum(), "joint " + squote(j.name) + " has no <child link=\"...\"/>");
      j.parent = findLink(p, p->Attribute("link"));
      j.child = findLink(ch, ch->Attribute("link"));
      if (j.parent == j.child) c_.fail(e->GetLineNum(), "joint " + squote(j.name) + " connects link " + squote(links_[j.child].name) + " to itself");
      LinkInfo& cl = links_[j.child];
      if (cl.parent_joint >= 0)
        c_.fail(e->GetLineNum(), "link " + squote(cl.name) + " is the child of two joints (" +
                                     squote(joints_[cl.parent_joint].name) + " and " + squote(j.name) + ")");
      cl.parent_joint = static_cast<int>(joints_.size());
      links_[j.parent].child_joints.push_back(static_cast<int>(joints_.size()));
      joint_index_[j.name] = static_cast<int>(joints_.size());
      joints_.push_back(j);
    }
    std::vector<int> roots;
    for (size_t i = 0; i < links_.size(); ++i)
      if (links_[i].parent_joint < 0) roots.push_back(static_cast<int>(i));
    if (roots.size() != 1) {
      std::string list;
      for (int r : roots) list += (list.empty() ? "" : ", ") + squote(links_[r].name);
      c_.fail(roots.empty() ? robot_->GetLineNum() : linkLine(roots[1]),
              roots.empty() ? std::string("no root link (the joints form a cycle)")
                            : "more than one root link (" + list + "): every link but one needs a parent joint");
    }
    root_ = roots[0];
    // Reachability from the root rules out cycles among the other links.
    std::vector<char> seen(links_.size(), 0);
    std::vector<int> stack{root_};
    while (!stack.empty()) {
      int l = stack.back();
      stack.pop_back();
      seen[l] = 1;
      for (int j : links_[l].child_joints) stack.push_back(joints_[j].child);
    }
    for (size_t i = 0; i < links_.size(); ++i)
      if (!seen[i]) c_.fail(linkLine(static_cast<int>(i)), "link " + squote(links_[i].name) + " is not connected to the root link " + squote(links_[root_].name) + " (cycle of joints)");
    for (const LinkInfo& l : links_) checkUrdfNumbers(c_, l.elem);
    for (const JointInfo& j : joints_) checkUrdfNumbers(c_, j.elem);
    // <nscd> belongs directly under <robot>.
    std::vector<const XMLElement*> todo{robot_};
    while (!todo.empty()) {
      const XMLElement* e = todo.back();
      todo.pop_back();
      for (const XMLElement* ch = e->FirstChildElement(); ch; ch = ch->NextSiblingElement()) {
        if (std::string(ch->Name()) == "nscd" && e != robot_)
          c_.fail(ch->GetLineNum(), "<nscd> must be directly under <robot>, not inside " + tag(e));
        if (std::string(ch->Name()) != "nscd") todo.push_back(ch);
      }
    }
  }

  // urdfdom reads the values; its messages are captured and given a line when
  // they name a link or joint.
  void parseUrdfdom() {
    urdf::ModelInterfaceSharedPtr model;
    std::vector<std::string> errors;
    {
      CaptureGuard guard;
      try {
        model = urdf::parseURDF(text_);
      } catch (const std::exception& ex) {
        guard.cap.errors.push_back(ex.what());
        model.reset();
      }
      errors = guard.cap.errors;
    }
    if (!model) {
      std::string msg;
      int line = robot_->GetLineNum();
      bool located = false;
      for (const std::string& er : errors) {
        msg += (msg.empty() ? "" : "; ") + er;
        for (size_t a = er.find('['); !located && a != std::string::npos; a = er.find('[', a + 1)) {
          const size_t b = er.find(']', a);
          if (b == std::string::npos) break;
          const std::string n = er.substr(a + 1, b - a - 1);
          if (link_index_.count(n)) line = linkLine(link_index_[n]), located = true;
          else if (joint_index_.count(n)) line = joints_[joint_index_[n]].elem->GetLineNum(), located = true;
        }
      }
      for (char& ch : msg)
        if (ch == '\n' || ch == '\r') ch = ' ';
      c_.fail(line, "URDF error: " + (msg.empty() ? std::string("urdfdom rejected the file") : msg));
    }
    for (JointInfo& j : joints_) {
      auto uj = model->getJoint(j.name);
      if (!uj) c_.fail(j.elem->GetLineNum(), "URDF error: joint " + squote(j.name) + " not found by urdfdom");
      j.origin = fromUrdf(uj->parent_to_joint_origin_transform);
      const int line = j.elem->FirstChildElement("axis") ? j.elem->FirstChildElement("axis")->GetLineNum()
                                                          : j.elem->GetLineNum();
      if (j.type == "revolute" || j.type == "continuous" || j.type == "prismatic") {
        const Vec3 a(uj->axis.x, uj->axis.y, uj->axis.z);
        if (!(a.allFinite() && a.norm() > 1e-12))
          c_.fail(line, "joint " + squote(j.name) + ": axis must be non-zero");
        j.axis = a.normalized();
      }
    }
    for (LinkInfo& l : links_) {
      auto ul = model->getLink(l.name);
      if (!ul) c_.fail(l.elem->GetLineNum(), "URDF error: link " + squote(l.name) + " not found by urdfdom");
      if (!ul->inertial) {
        l.inertial = false;
        continue;
      }
      const XMLElement* ie = l.elem->FirstChildElement("inertial");
      const XMLElement* me = ie ? ie->FirstChildElement("mass") : nullptr;
      const XMLElement* ne = ie ? ie->FirstChildElement("inertia") : nullptr;
      const int iline = ie ? ie->GetLineNum() : l.elem->GetLineNum();
      if (l.parent_joint < 0)
        c_.fail(iline, "root link " + squote(l.name) + " must be ground (no <inertial>)");
      const auto& in = *ul->inertial;
      Body b;
      b.name = l.name;
      b.mass = in.mass;
      const int mline = me ? me->GetLineNum() : iline;
      if (!std::isfinite(b.mass) || b.mass <= 0)
        c_.fail(mline, "link " + squote(l.name) + ": mass must be > 0, got " + num(b.mass));
      if (b.mass > kMaxMass)
        c_.fail(mline, "link " + squote(l.name) + ": mass " + num(b.mass) + " kg exceeds the limit of " + num(kMaxMass) + " kg");
      b.inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
      const int nline = ne ? ne->GetLineNum() : iline;
      if (!b.inertia.allFinite())
        c_.fail(nline, "link " + squote(l.name) + ": inertia is not finite");
      Eigen::SelfAdjointEigenSolver<Mat3> es(b.inertia, Eigen::EigenvaluesOnly);
      const Vec3 ev = es.eigenvalues();
      if (!(ev.minCoeff() > 0))
        c_.fail(nline, "link " + squote(l.name) + ": inertia is not positive definite (eigenvalues " +
                           num(ev[0]) + ", " + num(ev[1]) + ", " + num(ev[2]) + ")");
      if (ev.maxCoeff() > kMaxInertia)
        c_.fail(nline, "link " + squote(l.name) + ": inertia " + num(ev.maxCoeff()) +
                           " kg m^2 exceeds the limit of " + num(kMaxInertia) + " kg m^2");
      // Body frame = inertial origin: the link frame seen from the body frame is its inverse.
      l.in_body = fromUrdf(in.origin).inverse();
      l.body = static_cast<int>(m_.bodies.size());
      m_.bodies.push_back(b);
    }
  }

  // ---------------------------------------------------------------- <nscd>
  void collectNscd() {
    static const std::set<std::string> kinds = {"joint", "initial", "clearance", "contact",
                                                "spring", "actuator", "simulation"};
    for (const XMLElement* n = robot_->FirstChildElement("nscd"); n; n = n->NextSiblingElement("nscd")) {
      checkAttributes(c_, n, {});
      for (const XMLElement* e = n->FirstChildElement(); e; e = e->NextSiblingElement()) {
        if (!kinds.count(e->Name()))
          c_.fail(e->GetLineNum(), "unknown element " + tag(e) + " in <nscd> (allowed: <joint>, <initial>, "
                                   "<clearance>, <contact>, <spring>, <actuator>, <simulation>)");
        nscd_[e->Name()].push_back(e);
      }
    }
  }

  void readSimulation(const std::vector<SettingOverride>& overrides) {
    const auto& sims = nscd_["simulation"];
    if (sims.size() > 1)
      c_.fail(sims[1]->GetLineNum(), "more than one <simulation> element (first at line " +
                                         std::to_string(sims[0]->GetLineNum()) + ")");
    for (const XMLElement* e : sims) {
      checkChildren(c_, e, {});
      const std::string where = c_.file + ":" + std::to_string(e->GetLineNum());
      for (const XMLAttribute* a = e->FirstAttribute(); a; a = a->Next())
        applySetting(m_.settings, SettingOverride{a->Name(), a->Value(), where});
    }
    for (const SettingOverride& o : overrides) applySetting(m_.settings, o);
  }

  // ---------------------------------------------------------------- tree
  // Which body each link rides on, in tree order from the root.
  void buildBodies() {
    m_.world_frame = links_[root_].name;
    links_[root_].body = kGround;
    links_[root_].in_body = Pose{};
    std::vector<int> order{root_};
    for (size_t k = 0; k < order.size(); ++k) {
      for (int ji : links_[order[k]].child_joints) {
        const JointInfo& j = joints_[ji];
        LinkInfo& ch = links_[j.child];
        const LinkInfo& pa = links_[j.parent];
        if (!ch.inertial) {
          if (j.type != "fixed")
            c_.fail(j.elem->GetLineNum(), "link " + squote(ch.name) + " has no <inertial> but hangs on " +
                                              j.type + " joint " + squote(j.name) +
                                              ": a massless link must be attached by a fixed joint");
          ch.body = pa.body;
          ch.in_body = pa.in_body * j.origin;
        }
        order.push_back(j.child);
      }
    }
    for (const LinkInfo& l : links_) m_.links.push_back(Link{l.name, l.body, l.in_body});
  }

  // Fills a Joint between the bodies of two links; the joint frame is `origin`
  // in the parent link frame and coincides with the child link frame at zero.
  Joint makeJoint(const std::string& name, JointType type, int parent, int child, const Pose& origin,
                  const Vec3& axis, bool loop, int line) {
    const LinkInfo& pa = links_[parent];
    const LinkInfo& ch = links_[child];
    if (pa.body == ch.body)
      c_.fail(line, "joint " + squote(name) + " connects " +
                        (pa.body == kGround ? std::string("ground to ground")
                                            : "body " + squote(m_.bodies[pa.body].name) + " to itself") +
                        " (links " + squote(pa.name) + " and " + squote(ch.name) + ")");
    Joint j;
    j.name = name;
    j.type = type;
    j.body_a = pa.body;
    j.body_b = ch.body;
    const Pose fa = pa.in_body * origin;  // joint frame in body_a frame
    const Pose& fb = ch.in_body;          // joint frame (= child link frame) in body_b frame
    j.anchor_a = fa.p;
    j.anchor_b = fb.p;
    j.axis_a = (fa.q * axis).normalized();
    j.axis_b = (fb.q * axis).normalized();
    j.rel_rot_zero = (fa.q * fb.q.conjugate()).normalized();
    j.loop = loop;
    j.src = SourceRef{c_.file, line};
    return j;
  }

  void buildUrdfJoints() {
    for (JointInfo& j : joints_) {
      if (j.type == "floating" || !links_[j.child].inertial) continue;  // placement only
      const JointType t = j.type == "prismatic" ? JointType::Prismatic
                          : j.type == "fixed"   ? JointType::Fixed
                                                : JointType::Revolute;
      const Vec3 axis = t == JointType::Fixed ? Vec3::UnitX() : j.axis;
      j.model_joint = static_cast<int>(m_.joints.size());
      model_joint_by_name_[j.name] = j.model_joint;
      m_.joints.push_back(makeJoint(j.name, t, j.parent, j.child, j.origin, axis, false, j.elem->GetLineNum()));
    }
  }

  void readLoopJoint(const XMLElement* e) {
    checkAttributes(c_, e, {"name", "type", "parent", "child"});
    checkChildren(c_, e, {"origin", "axis"});
    const std::string name = reqString(c_, e, "name");
    if (joint_index_.count(name))
      c_.fail(e->GetLineNum(), "duplicate joint name " + squote(name) + " (URDF joint at line " +
                                   std::to_string(joints_[joint_index_[name]].elem->GetLineNum()) + ")");
    if (loop_line_.count(name))
      c_.fail(e->GetLineNum(), "duplicate joint name " + squote(name) + " (first at line " +
                                   std::to_string(loop_line_[name]) + ")");
    const std::string type = reqString(c_, e, "type");
    JointType t;
    if (type == "revolute" || type == "continuous") t = JointType::Revolute;
    else if (type == "prismatic") t = JointType::Prismatic;
    else if (type == "fixed") t = JointType::Fixed;
    else c_.fail(e->GetLineNum(), "loop joint " + squote(name) + ": type " + squote(type) +
                                  " is not supported (revolute, continuous, prismatic, fixed)");
    const int parent = findLink(e, reqString(c_, e, "parent"));
    const int child = findLink(e, reqString(c_, e, "child"));
    const Pose origin = originChild(c_, e);
    Vec3 axis = Vec3::UnitX();
    if (const XMLElement* a = e->FirstChildElement("axis")) {
      if (a->NextSiblingElement("axis")) c_.fail(a->NextSiblingElement("axis")->GetLineNum(), "more than one <axis> in <joint>");
      checkAttributes(c_, a, {"xyz"});
      axis = reqVec3(c_, a, "xyz");
      if (!(axis.norm() > 1e-12)) c_.fail(a->GetLineNum(), "joint " + squote(name) + ": axis must be non-zero");
      axis.normalize();
    }
    if (t == JointType::Fixed) axis = Vec3::UnitX();
    loop_line_[name] = e->GetLineNum();
    model_joint_by_name_[name] = static_cast<int>(m_.joints.size());
    m_.joints.push_back(makeJoint(name, t, parent, child, origin, axis, true, e->GetLineNum()));
  }

  void readInitial(const XMLElement* e) {
    if (has(e, "joint")) {
      checkAttributes(c_, e, {"joint", "position"});
      const std::string name = reqString(c_, e, "joint");
      auto it = joint_index_.find(name);
      if (it == joint_index_.end()) {
        if (loop_line_.count(name))
          c_.fail(e->GetLineNum(), "<initial>: loop joint " + squote(name) + " does not place anything; set the position of a tree joint instead");
        c_.fail(e->GetLineNum(), "<initial>: unknown joint " + squote(name));
      }
      JointInfo& j = joints_[it->second];
      if (j.type != "revolute" && j.type != "continuous" && j.type != "prismatic")
        c_.fail(e->GetLineNum(), "<initial>: joint " + squote(name) + " is " + j.type +
                                     "; only revolute, continuous and prismatic joints take a position");
      if (j.has_initial) c_.fail(e->GetLineNum(), "<initial>: joint " + squote(name) + " given twice");
      j.has_initial = true;
      j.initial = reqNumber(c_, e, "position");
    } else if (has(e, "link")) {
      checkAttributes(c_, e, {"link", "vx", "vy", "vz", "wx", "wy", "wz"});
      const int l = findLink(e, reqString(c_, e, "link"));
      const int b = links_[l].body;
      if (b == kGround)
        c_.fail(e->GetLineNum(), "<initial>: link " + squote(links_[l].name) + " is ground and cannot move");
      for (const auto& v : initial_v_)
        if (v.first == b)
          c_.fail(e->GetLineNum(), "<initial>: velocity of body " + squote(m_.bodies[b].name) + " given twice");
      initial_v_.push_back({b, Vec3(optNumber(c_, e, "vx", 0), optNumber(c_, e, "vy", 0), optNumber(c_, e, "vz", 0))});
      initial_w_.push_back({b, Vec3(optNumber(c_, e, "wx", 0), optNumber(c_, e, "wy", 0), optNumber(c_, e, "wz", 0))});
    } else {
      c_.fail(e->GetLineNum(), "<initial> needs attribute 'joint' (with 'position') or 'link' (with velocities)");
    }
  }

  // Initial placement: the tree from the root with the <initial> joint positions.
  void place() {
    links_[root_].world = Pose{};
    std::vector<int> order{root_};
    for (size_t k = 0; k < order.size(); ++k) {
      for (int ji : links_[order[k]].child_joints) {
        const JointInfo& j = joints_[ji];
        links_[j.child].world = links_[j.parent].world * j.origin * jointMotion(j, j.initial);
        order.push_back(j.child);
      }
    }
    // Ground links hang on fixed joints only, so their in_body (set in buildBodies)
    // already is their world pose.
    for (const LinkInfo& l : links_)
      if (l.inertial) m_.bodies[l.body].initial_pose = l.world * l.in_body.inverse();
    // Initial velocity: <initial link> gives the world-frame velocity of the centre of
    // mass of the body the link rides on, and its world-frame angular velocity.
    for (const auto& v : initial_v_) m_.bodies[v.first].initial_velocity = v.second;
    for (const auto& w : initial_w_) m_.bodies[w.first].initial_angular_velocity = w.second;
  }

  Pose bodyWorld(int b) const { return b == kGround ? Pose{} : m_.bodies[b].initial_pose; }

  // Joint position at the initial placement (tree joints: the <initial> value).
  double initialPosition(int mj) const {
    const Joint& j = m_.joints[mj];
    auto it = joint_index_.find(j.name);
    if (it != joint_index_.end()) return joints_[it->second].initial;
    const Pose A = bodyWorld(j.body_a), B = bodyWorld(j.body_b);
    if (j.type == JointType::Prismatic)
      return (B.apply(j.anchor_b) - A.apply(j.anchor_a)).dot(A.rotate(j.axis_a));
    if (j.type == JointType::Revolute) {
      // q_a^-1 q_b = rel_rot_zero * R(axis_b, angle)
      const Quat r = j.rel_rot_zero.conjugate() * (A.q.conjugate() * B.q);
      return 2.0 * std::atan2(r.vec().dot(j.axis_b), r.w());
    }
    return 0;
  }

  int modelJoint(const XMLElement* e, const std::string& name, const std::string& what) const {
    auto it = model_joint_by_name_.find(name);
    if (it != model_joint_by_name_.end()) return it->second;
    auto u = joint_index_.find(name);
    if (u != joint_index_.end())
      c_.fail(e->GetLineNum(), what + ": joint " + squote(name) + " is " + joints_[u->second].type +
                                   (links_[joints_[u->second].child].inertial ? "" : " (attaches a massless link)") +
                                   " and imposes nothing");
    c_.fail(e->GetLineNum(), what + ": unknown joint " + squote(name));
  }

  std::string jointTypeName(int mj) const {
    const Joint& j = m_.joints[mj];
    auto u = joint_index_.find(j.name);
    if (u != joint_index_.end()) return joints_[u->second].type;
    return j.type == JointType::Revolute ? "revolute" : j.type == JointType::Prismatic ? "prismatic" : "fixed";
  }

  // ---------------------------------------------------------------- clearance
  void readClearance(const XMLElement* e) {
    checkAttributes(c_, e, {"joint", "journal", "radius", "radial", "length", "axial", "bumps",
                            "bump_radius", "bump_at", "mu", "e"});
    checkChildren(c_, e, {});
    const std::string name = reqString(c_, e, "joint");
    const int mj = modelJoint(e, name, "clearance");
    Joint& j = m_.joints[mj];
    if (j.type != JointType::Revolute)
      c_.fail(e->GetLineNum(), "clearance on " + jointTypeName(mj) + " joint " + squote(name) +
                                   ": only revolute and continuous joints can have a clearance");
    if (j.clearance >= 0)
      c_.fail(e->GetLineNum(), "joint " + squote(name) + " is referenced by a second <clearance> (first at line " +
                                   std::to_string(m_.clearance_joints[j.clearance].src.line) + ")");
    ClearanceJoint cj;
    cj.name = name;
    cj.joint = mj;
    const std::string journal = has(e, "journal") ? reqString(c_, e, "journal") : "parent";
    if (journal != "parent" && journal != "child")
      c_.fail(e->GetLineNum(), "attribute 'journal' of <clearance> must be 'parent' or 'child', got " + squote(journal));
    cj.radius = reqNumber(c_, e, "radius");
    requireRange(c_, e, "radius", cj.radius, 0, true, kInf, false);
    cj.radial = reqNumber(c_, e, "radial");
    requireRange(c_, e, "radial", cj.radial, 0, true, kInf, false);
    cj.length = reqNumber(c_, e, "length");
    requireRange(c_, e, "length", cj.length, 0, true, kInf, false);
    cj.axial = reqNumber(c_, e, "axial");
    requireRange(c_, e, "axial", cj.axial, 0, true, kInf, false);
    cj.bumps = optInt(c_, e, "bumps", 3);
    if (cj.bumps < 0 || cj.bumps > kMaxBumps)
      c_.fail(e->GetLineNum(), "attribute 'bumps' of <clearance> must be in 0.." + std::to_string(kMaxBumps) +
                                   ", got " + std::to_string(cj.bumps));
    cj.bump_radius = optNumber(c_, e, "bump_radius", cj.radius / 8);
    requireRange(c_, e, "bump_radius", cj.bump_radius, 0, false, kInf, false);
    cj.bump_at = optNumber(c_, e, "bump_at", 1.5 * (cj.radius + cj.radial));
    requireRange(c_, e, "bump_at", cj.bump_at, 0, true, kInf, false);
    cj.mu = optNumber(c_, e, "mu", 0);
    requireRange(c_, e, "mu", cj.mu, 0, false, kInf, false);
    cj.e = optNumber(c_, e, "e", 0);
    requireRange(c_, e, "e", cj.e, 0, false, 1, false);
    const bool jp = journal == "parent";
    cj.journal_body = jp ? j.body_a : j.body_b;
    cj.bearing_body = jp ? j.body_b : j.body_a;
    cj.journal_center = jp ? j.anchor_a : j.anchor_b;
    cj.journal_axis = jp ? j.axis_a : j.axis_b;
    cj.bearing_center = jp ? j.anchor_b : j.anchor_a;
    cj.bearing_axis = jp ? j.axis_b : j.axis_a;
    cj.bearing_ref = anyOrthogonal(cj.bearing_axis);
    cj.src = SourceRef{c_.file, e->GetLineNum()};
    j.clearance = static_cast<int>(m_.clearance_joints.size());
    m_.clearance_joints.push_back(cj);
  }

  // ---------------------------------------------------------------- contacts
  static const char* shapeName(ShapeType t) {
    switch (t) {
      case ShapeType::Sphere: return "sphere";
      case ShapeType::Capsule: return "capsule";
      case ShapeType::Cylinder: return "cylinder";
      case ShapeType::Box: return "box";
      case ShapeType::Plane: return "plane";
    }
    return "?";
  }

  Shape readShape(const XMLElement* e) {
    checkChildren(c_, e, {"origin"});
    const int l = findLink(e, reqString(c_, e, "link"));
    const std::string type = reqString(c_, e, "type");
    Shape s;
    if (type == "sphere") {
      checkAttributes(c_, e, {"link", "type", "radius"});
      s.type = ShapeType::Sphere;
    } else if (type == "capsule" || type == "cylinder") {
      checkAttributes(c_, e, {"link", "type", "radius", "length"});
      s.type = type == "capsule" ? ShapeType::Capsule : ShapeType::Cylinder;
      s.length = reqNumber(c_, e, "length");
      requireRange(c_, e, "length", s.length, 0, true, kInf, false);
    } else if (type == "box") {
      checkAttributes(c_, e, {"link", "type", "size"});
      s.type = ShapeType::Box;
      const Vec3 size = reqVec3(c_, e, "size");
      if (!(size.minCoeff() > 0))
        c_.fail(e->GetLineNum(), "attribute 'size' of <shape> must be 3 numbers > 0");
      s.half_extents = 0.5 * size;
    } else if (type == "plane") {
      checkAttributes(c_, e, {"link", "type"});
      s.type = ShapeType::Plane;
    } else {
      c_.fail(e->GetLineNum(), "unknown shape type " + squote(type) + " (sphere, capsule, cylinder, box, plane)");
    }
    if (s.type == ShapeType::Sphere || s.type == ShapeType::Capsule || s.type == ShapeType::Cylinder) {
      s.radius = reqNumber(c_, e, "radius");
      requireRange(c_, e, "radius", s.radius, 0, true, kInf, false);
    }
    s.body = links_[l].body;
    s.pose = links_[l].in_body * originChild(c_, e);
    return s;
  }

  void readContact(const XMLElement* e) {
    checkAttributes(c_, e, {"name", "mu", "e"});
    checkChildren(c_, e, {"shape"});
    ContactPair cp;
    cp.name = reqString(c_, e, "name");
    for (const ContactPair& o : m_.contacts)
      if (o.name == cp.name)
        c_.fail(e->GetLineNum(), "duplicate contact name " + squote(cp.name) + " (first at line " + std::to_string(o.src.line) + ")");
    cp.mu = optNumber(c_, e, "mu", 0);
    requireRange(c_, e, "mu", cp.mu, 0, false, kInf, false);
    cp.e = optNumber(c_, e, "e", 0);
    requireRange(c_, e, "e", cp.e, 0, false, 1, false);
    std::vector<const XMLElement*> shapes;
    for (const XMLElement* s = e->FirstChildElement("shape"); s; s = s->NextSiblingElement("shape")) shapes.push_back(s);
    if (shapes.size() != 2)
      c_.fail(e->GetLineNum(), "contact " + squote(cp.name) + " needs exactly two <shape>, got " + std::to_string(shapes.size()));
    cp.a = readShape(shapes[0]);
    cp.b = readShape(shapes[1]);
    if (cp.a.body == cp.b.body)
      c_.fail(e->GetLineNum(), "contact " + squote(cp.name) + ": both shapes are on " +
                                   (cp.a.body == kGround ? std::string("ground") : "body " + squote(m_.bodies[cp.a.body].name)));
    if (!shapePairSupported(cp.a.type, cp.b.type)) {
      std::string list;
      const ShapeType all[] = {ShapeType::Sphere, ShapeType::Capsule, ShapeType::Cylinder, ShapeType::Box, ShapeType::Plane};
      for (int i = 0; i < 5; ++i)
        for (int k = i; k < 5; ++k)
          if (shapePairSupported(all[i], all[k]))
            list += (list.empty() ? "" : ", ") + std::string(shapeName(all[i])) + "-" + shapeName(all[k]);
      c_.fail(e->GetLineNum(), "contact " + squote(cp.name) + ": " + shapeName(cp.a.type) + "-" + shapeName(cp.b.type) +
                                   " pairs are not supported (supported: " + list + ")");
    }
    cp.src = SourceRef{c_.file, e->GetLineNum()};
    m_.contacts.push_back(cp);
  }

  // ---------------------------------------------------------------- springs
  void readSpring(const XMLElement* e) {
    Spring s;
    s.name = reqString(c_, e, "name");
    for (const Spring& o : m_.springs)
      if (o.name == s.name)
        c_.fail(e->GetLineNum(), "duplicate spring name " + squote(s.name) + " (first at line " + std::to_string(o.src.line) + ")");
    const std::string type = reqString(c_, e, "type");
    if (type == "linear") {
      checkAttributes(c_, e, {"name", "type", "stiffness", "rest_length", "damping"});
      checkChildren(c_, e, {"end"});
      s.type = SpringType::Linear;
      std::vector<const XMLElement*> ends;
      for (const XMLElement* x = e->FirstChildElement("end"); x; x = x->NextSiblingElement("end")) ends.push_back(x);
      if (ends.size() != 2)
        c_.fail(e->GetLineNum(), "spring " + squote(s.name) + " needs exactly two <end>, got " + std::to_string(ends.size()));
      int body[2];
      Vec3 p[2];
      for (int i = 0; i < 2; ++i) {
        checkAttributes(c_, ends[i], {"link", "xyz"});
        checkChildren(c_, ends[i], {});
        const int l = findLink(ends[i], reqString(c_, ends[i], "link"));
        body[i] = links_[l].body;
        p[i] = links_[l].in_body.apply(optVec3(c_, ends[i], "xyz", Vec3::Zero()));
      }
      if (body[0] == body[1])
        c_.fail(e->GetLineNum(), "spring " + squote(s.name) + ": both ends are on " +
                                     (body[0] == kGround ? std::string("ground") : "body " + squote(m_.bodies[body[0]].name)));
      s.body_a = body[0];
      s.body_b = body[1];
      s.end_a = p[0];
      s.end_b = p[1];
      // No preload unless asked: the default rest length is the initial distance.
      const double d = (bodyWorld(s.body_a).apply(s.end_a) - bodyWorld(s.body_b).apply(s.end_b)).norm();
      s.rest = optNumber(c_, e, "rest_length", d);
      requireRange(c_, e, "rest_length", s.rest, 0, false, kInf, false);
    } else if (type == "torsion") {
      checkAttributes(c_, e, {"name", "type", "joint", "stiffness", "rest_angle", "damping"});
      checkChildren(c_, e, {});
      s.type = SpringType::Torsion;
      const std::string jn = reqString(c_, e, "joint");
      s.joint = modelJoint(e, jn, "torsion spring " + squote(s.name));
      const Joint& j = m_.joints[s.joint];
      if (j.type != JointType::Revolute)
        c_.fail(e->GetLineNum(), "torsion spring " + squote(s.name) + ": joint " + squote(jn) + " is " +
                                     jointTypeName(s.joint) + "; a torsion spring needs a revolute or continuous joint");
      s.body_a = j.body_a;
      s.body_b = j.body_b;
      s.rest = optNumber(c_, e, "rest_angle", 0);  // from the URDF zero of the joint
    } else {
      c_.fail(e->GetLineNum(), "spring " + squote(s.name) + ": unknown type " + squote(type) + " (linear, torsion)");
    }
    s.stiffness = reqNumber(c_, e, "stiffness");
    requireRange(c_, e, "stiffness", s.stiffness, 0, false, kInf, false);
    s.damping = optNumber(c_, e, "damping", 0);
    requireRange(c_, e, "damping", s.damping, 0, false, kInf, false);
    s.src = SourceRef{c_.file, e->GetLineNum()};
    m_.springs.push_back(s);
  }

  // ---------------------------------------------------------------- actuators
  int actuatedBody(const XMLElement* e, const std::string& what) const {
    const int l = findLink(e, reqString(c_, e, "link"));
    if (links_[l].body == kGround)
      c_.fail(e->GetLineNum(), what + ": link " + squote(links_[l].name) + " is ground and cannot be actuated");
    return l;
  }

  void readActuator(const XMLElement* e) {
    checkChildren(c_, e, {});
    Actuator a;
    a.name = reqString(c_, e, "name");
    for (const Actuator& o : m_.actuators)
      if (o.name == a.name)
        c_.fail(e->GetLineNum(), "duplicate actuator name " + squote(a.name) + " (first at line " + std::to_string(o.src.line) + ")");
    const std::string type = reqString(c_, e, "type");
    const std::string what = "actuator " + squote(a.name);
    if (type == "position") {
      checkAttributes(c_, e, {"name", "type", "joint", "kp", "kd", "max_effort", "command"});
      a.type = ActuatorType::Position;
      if (!has(e, "joint")) c_.fail(e->GetLineNum(), what + " (position) needs attribute 'joint'");
      a.joint = modelJoint(e, reqString(c_, e, "joint"), what);
      if (m_.joints[a.joint].type == JointType::Fixed)
        c_.fail(e->GetLineNum(), what + ": joint " + squote(m_.joints[a.joint].name) + " is fixed");
      a.kp = optNumber(c_, e, "kp", 0);
      requireRange(c_, e, "kp", a.kp, 0, false, kInf, false);
      a.kd = optNumber(c_, e, "kd", 0);
      requireRange(c_, e, "kd", a.kd, 0, false, kInf, false);
      a.max_effort = optNumber(c_, e, "max_effort", 0);
      requireRange(c_, e, "max_effort", a.max_effort, 0, false, kInf, false);
      a.initial_command = initialPosition(a.joint);
    } else if (type == "prescribed") {
      checkAttributes(c_, e, {"name", "type", "link", "joint", "axis", "command"});
      a.type = ActuatorType::Prescribed;
      if (has(e, "link") && has(e, "joint")) c_.fail(e->GetLineNum(), what + ": give either 'link' or 'joint', not both");
      if (has(e, "link")) {
        const int l = actuatedBody(e, what);
        a.body = links_[l].body;
        const Vec3 ax = reqVec3(c_, e, "axis");
        if (!(ax.norm() > 1e-12)) c_.fail(e->GetLineNum(), what + ": axis must be non-zero");
        a.axis = links_[l].world.rotate(ax).normalized();  // link frame -> world, at the initial pose
      } else if (has(e, "joint")) {
        if (has(e, "axis")) c_.fail(e->GetLineNum(), what + ": 'axis' applies to link= only (a joint moves about its own axis)");
        a.joint = modelJoint(e, reqString(c_, e, "joint"), what);
        if (m_.joints[a.joint].type == JointType::Fixed)
          c_.fail(e->GetLineNum(), what + ": joint " + squote(m_.joints[a.joint].name) + " is fixed");
        a.initial_command = initialPosition(a.joint);
      } else {
        c_.fail(e->GetLineNum(), what + " (prescribed) needs attribute 'link' or 'joint'");
      }
    } else if (type == "force") {
      checkAttributes(c_, e, {"name", "type", "link", "xyz", "direction", "command"});
      a.type = ActuatorType::Force;
      if (!has(e, "link")) c_.fail(e->GetLineNum(), what + " (force) needs attribute 'link'");
      const int l = actuatedBody(e, what);
      a.body = links_[l].body;
      a.point = links_[l].in_body.apply(optVec3(c_, e, "xyz", Vec3::Zero()));
      const Vec3 d = reqVec3(c_, e, "direction");
      if (!(d.norm() > 1e-12)) c_.fail(e->GetLineNum(), what + ": direction must be non-zero");
      a.direction = links_[l].in_body.rotate(d).normalized();
    } else {
      c_.fail(e->GetLineNum(), what + ": unknown actuator type " + squote(type) + " (position, prescribed, force)");
    }
    a.initial_command = optNumber(c_, e, "command", a.initial_command);
    a.src = SourceRef{c_.file, e->GetLineNum()};
    m_.actuators.push_back(a);
  }
};

bool blank(const std::string& s) {
  for (char ch : s)
    if (!std::isspace(static_cast<unsigned char>(ch))) return false;
  return true;
}

}  // namespace

Model loadSceneFromString(const std::string& urdf_xml, const std::string& name,
                          const std::vector<SettingOverride>& overrides) {
  if (blank(urdf_xml)) throw SceneError(name + ": empty scene");
  return Loader(urdf_xml, name).load(overrides);
}

Model loadScene(const std::string& path, const std::vector<SettingOverride>& overrides) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SceneError(path + ": cannot read file (a directory)");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw SceneError(path + ": cannot read file");
  std::stringstream buf;
  buf << f.rdbuf();
  if (f.bad()) throw SceneError(path + ": cannot read file");
  const std::string text = buf.str();
  if (blank(text)) throw SceneError(path + ": empty file");
  return Loader(text, path).load(overrides);
}

}  // namespace nscd
