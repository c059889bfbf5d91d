// The URDF side of a scene: tinyxml2 gives the structure and a line for every
// error, urdfdom the values (origins, axes, inertials), so the URDF meaning is
// exactly what every other URDF tool sees. Then bodies, tree joints and the
// initial placement.
#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <set>

#include "scene_build.hpp"

namespace nscd {
namespace {

constexpr double kMaxMass = 1e6;     // kg
constexpr double kMaxInertia = 1e6;  // kg m^2

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

}  // namespace

int SceneBuild::findLink(const XMLElement* e, const std::string& name) const {
  auto it = link_index.find(name);
  if (it == link_index.end()) c.fail(e->GetLineNum(), "unknown link " + squote(name));
  return it->second;
}

Joint SceneBuild::makeJoint(const std::string& name, JointType type, int parent, int child, const Pose& origin,
                const Vec3& axis, bool loop, int line) {
  const LinkInfo& pa = links[parent];
  const LinkInfo& ch = links[child];
  if (pa.body == ch.body)
    c.fail(line, "joint " + squote(name) + " connects " +
                      (pa.body == kGround ? std::string("ground to ground")
                                          : "body " + squote(m.bodies[pa.body].name) + " to itself") +
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
  j.src = SourceRef{c.file, line};
  return j;
}

double SceneBuild::initialPosition(int mj) const {
  const Joint& j = m.joints[mj];
  auto it = joint_index.find(j.name);
  if (it != joint_index.end()) return joints[it->second].initial;
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

int SceneBuild::modelJoint(const XMLElement* e, const std::string& name, const std::string& what) const {
  auto it = model_joint_by_name.find(name);
  if (it != model_joint_by_name.end()) return it->second;
  auto u = joint_index.find(name);
  if (u != joint_index.end())
    c.fail(e->GetLineNum(), what + ": joint " + squote(name) + " is " + joints[u->second].type +
                                 (links[joints[u->second].child].inertial ? "" : " (attaches a massless link)") +
                                 " and imposes nothing");
  c.fail(e->GetLineNum(), what + ": unknown joint " + squote(name));
}

std::string SceneBuild::jointTypeName(int mj) const {
  const Joint& j = m.joints[mj];
  auto u = joint_index.find(j.name);
  if (u != joint_index.end()) return joints[u->second].type;
  return j.type == JointType::Revolute ? "revolute" : j.type == JointType::Prismatic ? "prismatic" : "fixed";
}

// ---------------------------------------------------------------- XML
void parseSceneXml(SceneBuild& sb) {
  sb.doc.Parse(sb.text.c_str(), sb.text.size());
  if (sb.doc.Error()) {
    // tinyxml2's detail, if any, follows the line number: "... Line number=N: XMLElement name=x".
    std::string detail = sb.doc.ErrorStr() ? sb.doc.ErrorStr() : "";
    const size_t ln = detail.find("Line number=");
    const size_t colon = ln == std::string::npos ? std::string::npos : detail.find(": ", ln);
    detail = colon == std::string::npos ? "" : detail.substr(colon + 2);
    const size_t nm = detail.find("name=");
    const std::string elem = nm == std::string::npos ? "" : " <" + detail.substr(nm + 5) + ">";
    std::string what;
    switch (sb.doc.ErrorID()) {
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
        what = XMLDocument::ErrorIDToName(sb.doc.ErrorID());
        if (!elem.empty()) what += " in" + elem;
      }
    }
    for (char& ch : what)
      if (ch == '\n' || ch == '\r') ch = ' ';
    sb.c.fail(sb.doc.ErrorLineNum(), "XML error: " + what);
  }
  sb.robot = sb.doc.RootElement();
  if (!sb.robot) sb.c.fail(0, "not a URDF: no root element");
  if (std::string(sb.robot->Name()) != "robot")
    sb.c.fail(sb.robot->GetLineNum(), "not a URDF: root element is " + tag(sb.robot) + ", expected <robot>");
}

namespace {

// <link>s: names unique; a LinkInfo each, in document order.
void readUrdfLinks(SceneBuild& sb) {
  for (const XMLElement* e = sb.robot->FirstChildElement("link"); e; e = e->NextSiblingElement("link")) {
    const std::string n = reqString(sb.c, e, "name");
    if (sb.link_index.count(n))
      sb.c.fail(e->GetLineNum(), "duplicate link name " + squote(n) + " (first at line " +
                                   std::to_string(sb.linkLine(sb.link_index[n])) + ")");
    sb.link_index[n] = static_cast<int>(sb.links.size());
    LinkInfo li;
    li.name = n;
    li.elem = e;
    li.inertial = e->FirstChildElement("inertial") != nullptr;
    sb.links.push_back(li);
  }
}

// <joint>s: names unique, known types, parent and child links that exist, every
// link the child of one joint at most.
void readUrdfJoints(SceneBuild& sb) {
  for (const XMLElement* e = sb.robot->FirstChildElement("joint"); e; e = e->NextSiblingElement("joint")) {
    JointInfo j;
    j.name = reqString(sb.c, e, "name");
    j.elem = e;
    if (sb.joint_index.count(j.name))
      sb.c.fail(e->GetLineNum(), "duplicate joint name " + squote(j.name) + " (first at line " +
                                   std::to_string(sb.joints[sb.joint_index[j.name]].elem->GetLineNum()) + ")");
    j.type = reqString(sb.c, e, "type");
    if (!kUrdfJointTypes.count(j.type))
      sb.c.fail(e->GetLineNum(), "joint " + squote(j.name) + ": unknown joint type " + squote(j.type));
    if (j.type == "planar")
      sb.c.fail(e->GetLineNum(), "joint " + squote(j.name) + ": planar joints are not supported");
    const XMLElement* p = e->FirstChildElement("parent");
    const XMLElement* ch = e->FirstChildElement("child");
    if (!p || !has(p, "link")) sb.c.fail(e->GetLineNum(), "joint " + squote(j.name) + " has no <parent link=\"...\"/>");
    if (!ch || !has(ch, "link")) sb.c.fail(e->GetLineNum(), "joint " + squote(j.name) + " has no <child link=\"...\"/>");
    j.parent = sb.findLink(p, p->Attribute("link"));
    j.child = sb.findLink(ch, ch->Attribute("link"));
    if (j.parent == j.child) sb.c.fail(e->GetLineNum(), "joint " + squote(j.name) + " connects link " + squote(sb.links[j.child].name) + " to itself");
    LinkInfo& cl = sb.links[j.child];
    if (cl.parent_joint >= 0)
      sb.c.fail(e->GetLineNum(), "link " + squote(cl.name) + " is the child of two joints (" +
                                   squote(sb.joints[cl.parent_joint].name) + " and " + squote(j.name) + ")");
    cl.parent_joint = static_cast<int>(sb.joints.size());
    sb.links[j.parent].child_joints.push_back(static_cast<int>(sb.joints.size()));
    sb.joint_index[j.name] = static_cast<int>(sb.joints.size());
    sb.joints.push_back(j);
  }
}

// The one root link (no parent joint), from which every link is reached.
void findRootLink(SceneBuild& sb) {
  std::vector<int> roots;
  for (size_t i = 0; i < sb.links.size(); ++i)
    if (sb.links[i].parent_joint < 0) roots.push_back(static_cast<int>(i));
  if (roots.size() != 1) {
    std::string list;
    for (int r : roots) list += (list.empty() ? "" : ", ") + squote(sb.links[r].name);
    sb.c.fail(roots.empty() ? sb.robot->GetLineNum() : sb.linkLine(roots[1]),
            roots.empty() ? std::string("no root link (the joints form a cycle)")
                          : "more than one root link (" + list + "): every link but one needs a parent joint");
  }
  sb.root = roots[0];
  // Reachability from the root rules out cycles among the other links.
  std::vector<char> seen(sb.links.size(), 0);
  std::vector<int> stack{sb.root};
  while (!stack.empty()) {
    int l = stack.back();
    stack.pop_back();
    seen[l] = 1;
    for (int j : sb.links[l].child_joints) stack.push_back(sb.joints[j].child);
  }
  for (size_t i = 0; i < sb.links.size(); ++i)
    if (!seen[i]) sb.c.fail(sb.linkLine(static_cast<int>(i)), "link " + squote(sb.links[i].name) + " is not connected to the root link " + squote(sb.links[sb.root].name) + " (cycle of joints)");
}

void checkNscdPlacement(SceneBuild& sb) {
  // <nscd> belongs directly under <robot>.
  std::vector<const XMLElement*> todo{sb.robot};
  while (!todo.empty()) {
    const XMLElement* e = todo.back();
    todo.pop_back();
    for (const XMLElement* ch = e->FirstChildElement(); ch; ch = ch->NextSiblingElement()) {
      if (std::string(ch->Name()) == "nscd" && e != sb.robot)
        sb.c.fail(ch->GetLineNum(), "<nscd> must be directly under <robot>, not inside " + tag(e));
      if (std::string(ch->Name()) != "nscd") todo.push_back(ch);
    }
  }
}

}  // namespace

// Tree structure from tinyxml2, so every URDF-level error has a line.
void prepassUrdf(SceneBuild& sb) {
  if (!has(sb.robot, "name")) sb.c.fail(sb.robot->GetLineNum(), "<robot> is missing attribute 'name'");
  readUrdfLinks(sb);
  if (sb.links.empty()) sb.c.fail(sb.robot->GetLineNum(), "<robot> has no <link>");
  readUrdfJoints(sb);
  findRootLink(sb);
  for (const LinkInfo& l : sb.links) checkUrdfNumbers(sb.c, l.elem);
  for (const JointInfo& j : sb.joints) checkUrdfNumbers(sb.c, j.elem);
  checkNscdPlacement(sb);
}

namespace {

// urdfdom's model of the text; its messages captured and, when it fails, one
// message with the line of the first link or joint they name.
urdf::ModelInterfaceSharedPtr runUrdfdom(SceneBuild& sb) {
  urdf::ModelInterfaceSharedPtr model;
  std::vector<std::string> errors;
  {
    CaptureGuard guard;
    try {
      model = urdf::parseURDF(sb.text);
    } catch (const std::exception& ex) {
      guard.cap.errors.push_back(ex.what());
      model.reset();
    }
    errors = guard.cap.errors;
  }
  if (!model) {
    std::string msg;
    int line = sb.robot->GetLineNum();
    bool located = false;
    for (const std::string& er : errors) {
      msg += (msg.empty() ? "" : "; ") + er;
      for (size_t a = er.find('['); !located && a != std::string::npos; a = er.find('[', a + 1)) {
        const size_t b = er.find(']', a);
        if (b == std::string::npos) break;
        const std::string n = er.substr(a + 1, b - a - 1);
        if (sb.link_index.count(n)) line = sb.linkLine(sb.link_index[n]), located = true;
        else if (sb.joint_index.count(n)) line = sb.joints[sb.joint_index[n]].elem->GetLineNum(), located = true;
      }
    }
    for (char& ch : msg)
      if (ch == '\n' || ch == '\r') ch = ' ';
    sb.c.fail(line, "URDF error: " + (msg.empty() ? std::string("urdfdom rejected the file") : msg));
  }
  return model;
}

// The joints' origins and axes as urdfdom read them.
void readUrdfdomJoints(SceneBuild& sb, const urdf::ModelInterface& model) {
  for (JointInfo& j : sb.joints) {
    auto uj = model.getJoint(j.name);
    if (!uj) sb.c.fail(j.elem->GetLineNum(), "URDF error: joint " + squote(j.name) + " not found by urdfdom");
    j.origin = fromUrdf(uj->parent_to_joint_origin_transform);
    const int line = j.elem->FirstChildElement("axis") ? j.elem->FirstChildElement("axis")->GetLineNum()
                                                        : j.elem->GetLineNum();
    if (j.type == "revolute" || j.type == "continuous" || j.type == "prismatic") {
      const Vec3 a(uj->axis.x, uj->axis.y, uj->axis.z);
      if (!(a.allFinite() && a.norm() > 1e-12))
        sb.c.fail(line, "joint " + squote(j.name) + ": axis must be non-zero");
      j.axis = a.normalized();
    }
  }
}

// The body of a link with an <inertial>: its mass and inertia, checked, and the
// link's frame seen from the body frame.
void addLinkBody(SceneBuild& sb, LinkInfo& l, const urdf::Inertial& in) {
  const XMLElement* ie = l.elem->FirstChildElement("inertial");
  const XMLElement* me = ie ? ie->FirstChildElement("mass") : nullptr;
  const XMLElement* ne = ie ? ie->FirstChildElement("inertia") : nullptr;
  const int iline = ie ? ie->GetLineNum() : l.elem->GetLineNum();
  if (l.parent_joint < 0)
    sb.c.fail(iline, "root link " + squote(l.name) + " must be ground (no <inertial>)");
  Body b;
  b.name = l.name;
  b.mass = in.mass;
  const int mline = me ? me->GetLineNum() : iline;
  if (!std::isfinite(b.mass) || b.mass <= 0)
    sb.c.fail(mline, "link " + squote(l.name) + ": mass must be > 0, got " + num(b.mass));
  if (b.mass > kMaxMass)
    sb.c.fail(mline, "link " + squote(l.name) + ": mass " + num(b.mass) + " kg exceeds the limit of " + num(kMaxMass) + " kg");
  b.inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  const int nline = ne ? ne->GetLineNum() : iline;
  if (!b.inertia.allFinite())
    sb.c.fail(nline, "link " + squote(l.name) + ": inertia is not finite");
  Eigen::SelfAdjointEigenSolver<Mat3> es(b.inertia, Eigen::EigenvaluesOnly);
  const Vec3 ev = es.eigenvalues();
  if (!(ev.minCoeff() > 0))
    sb.c.fail(nline, "link " + squote(l.name) + ": inertia is not positive definite (eigenvalues " +
                       num(ev[0]) + ", " + num(ev[1]) + ", " + num(ev[2]) + ")");
  if (ev.maxCoeff() > kMaxInertia)
    sb.c.fail(nline, "link " + squote(l.name) + ": inertia " + num(ev.maxCoeff()) +
                       " kg m^2 exceeds the limit of " + num(kMaxInertia) + " kg m^2");
  // Body frame = inertial origin: the link frame seen from the body frame is its inverse.
  l.in_body = fromUrdf(in.origin).inverse();
  l.body = static_cast<int>(sb.m.bodies.size());
  sb.m.bodies.push_back(b);
}

}  // namespace

// urdfdom reads the values; its messages are captured and given a line when
// they name a link or joint.
void parseUrdfdom(SceneBuild& sb) {
  const urdf::ModelInterfaceSharedPtr model = runUrdfdom(sb);
  readUrdfdomJoints(sb, *model);
  for (LinkInfo& l : sb.links) {
    auto ul = model->getLink(l.name);
    if (!ul) sb.c.fail(l.elem->GetLineNum(), "URDF error: link " + squote(l.name) + " not found by urdfdom");
    if (!ul->inertial) {
      l.inertial = false;
      continue;
    }
    addLinkBody(sb, l, *ul->inertial);
  }
}

// ---------------------------------------------------------------- tree
// Which body each link rides on, in tree order from the root.
void buildBodies(SceneBuild& sb) {
  sb.m.world_frame = sb.links[sb.root].name;
  sb.links[sb.root].body = kGround;
  sb.links[sb.root].in_body = Pose{};
  std::vector<int> order{sb.root};
  for (size_t k = 0; k < order.size(); ++k) {
    for (int ji : sb.links[order[k]].child_joints) {
      const JointInfo& j = sb.joints[ji];
      LinkInfo& ch = sb.links[j.child];
      const LinkInfo& pa = sb.links[j.parent];
      if (!ch.inertial) {
        if (j.type != "fixed")
          sb.c.fail(j.elem->GetLineNum(), "link " + squote(ch.name) + " has no <inertial> but hangs on " +
                                            j.type + " joint " + squote(j.name) +
                                            ": a massless link must be attached by a fixed joint");
        ch.body = pa.body;
        ch.in_body = pa.in_body * j.origin;
      }
      order.push_back(j.child);
    }
  }
  for (const LinkInfo& l : sb.links) sb.m.links.push_back(Link{l.name, l.body, l.in_body});
}

void buildUrdfJoints(SceneBuild& sb) {
  for (JointInfo& j : sb.joints) {
    if (j.type == "floating" || !sb.links[j.child].inertial) continue;  // placement only
    const JointType t = j.type == "prismatic" ? JointType::Prismatic
                        : j.type == "fixed"   ? JointType::Fixed
                                              : JointType::Revolute;
    const Vec3 axis = t == JointType::Fixed ? Vec3::UnitX() : j.axis;
    j.model_joint = static_cast<int>(sb.m.joints.size());
    sb.model_joint_by_name[j.name] = j.model_joint;
    sb.m.joints.push_back(sb.makeJoint(j.name, t, j.parent, j.child, j.origin, axis, false, j.elem->GetLineNum()));
  }
}

// Initial placement: the tree from the root with the <initial> joint positions.
void placeBodies(SceneBuild& sb) {
  sb.links[sb.root].world = Pose{};
  std::vector<int> order{sb.root};
  for (size_t k = 0; k < order.size(); ++k) {
    for (int ji : sb.links[order[k]].child_joints) {
      const JointInfo& j = sb.joints[ji];
      sb.links[j.child].world = sb.links[j.parent].world * j.origin * jointMotion(j, j.initial);
      order.push_back(j.child);
    }
  }
  // Ground links hang on fixed joints only, so their in_body (set in buildBodies)
  // already is their world pose.
  for (const LinkInfo& l : sb.links)
    if (l.inertial) sb.m.bodies[l.body].initial_pose = l.world * l.in_body.inverse();
  // Initial velocity: <initial link> gives the world-frame velocity of the centre of
  // mass of the body the link rides on, and its world-frame angular velocity.
  for (const auto& v : sb.initial_v) sb.m.bodies[v.first].initial_velocity = v.second;
  for (const auto& w : sb.initial_w) sb.m.bodies[w.first].initial_angular_velocity = w.second;
}

}  // namespace nscd
