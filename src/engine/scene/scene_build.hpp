// What the readers of one scene share while it is loaded (scene_loader.cpp drives
// them): the XML, the URDF tree, and the Model being built, which is returned only
// when the whole scene is valid. Internal to the engine.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "nscd_sim/model.hpp"
#include "xml_reading.hpp"

namespace nscd {

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

struct SceneBuild {
  Ctx c;
  std::string text;
  XMLDocument doc;
  const XMLElement* robot = nullptr;
  std::vector<LinkInfo> links;
  std::vector<JointInfo> joints;
  std::map<std::string, int> link_index, joint_index;
  int root = -1;
  std::map<std::string, std::vector<const XMLElement*>> nscd;  // <nscd> children by name
  std::map<std::string, int> model_joint_by_name;  // URDF and loop joints in Model::joints
  std::map<std::string, int> loop_line;            // loop joint name -> line
  std::vector<std::pair<int, Vec3>> initial_v, initial_w;
  Model m;

  int linkLine(int i) const { return links[i].elem->GetLineNum(); }
  // The link named `name` (an error at e's line if there is none).
  int findLink(const XMLElement* e, const std::string& name) const;
  // A Joint between the bodies of two links; the joint frame is `origin` in the
  // parent link frame and coincides with the child link frame at zero.
  Joint makeJoint(const std::string& name, JointType type, int parent, int child,
                  const Pose& origin, const Vec3& axis, bool loop, int line);
  Pose bodyWorld(int b) const { return b == kGround ? Pose{} : m.bodies[b].initial_pose; }
  // Joint position at the initial placement (tree joints: the <initial> value).
  double initialPosition(int mj) const;
  // The Model joint named `name`; an error naming `what` if it imposes nothing.
  int modelJoint(const XMLElement* e, const std::string& name, const std::string& what) const;
  std::string jointTypeName(int mj) const;
};

// ---- the URDF (urdf_tree.cpp), in this order
void parseSceneXml(SceneBuild& sb);    // tinyxml2; XML errors with their line
void prepassUrdf(SceneBuild& sb);      // links, joints, the tree, with lines
void parseUrdfdom(SceneBuild& sb);     // urdfdom's values; bodies from the inertials
void buildBodies(SceneBuild& sb);      // which body each link rides on
void buildUrdfJoints(SceneBuild& sb);  // Model joints of the tree
void placeBodies(SceneBuild& sb);      // initial poses and velocities

// ---- one reader per <nscd> element (read_*.cpp)
void readSimulation(SceneBuild& sb, const std::vector<SettingOverride>& overrides);
void readLoopJoint(SceneBuild& sb, const XMLElement* e);
void readInitial(SceneBuild& sb, const XMLElement* e);
void readClearance(SceneBuild& sb, const XMLElement* e);
void readContact(SceneBuild& sb, const XMLElement* e);
void readSpring(SceneBuild& sb, const XMLElement* e);
void readActuator(SceneBuild& sb, const XMLElement* e);

}  // namespace nscd
