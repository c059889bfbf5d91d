// Scene loader: URDF + <nscd> annotations -> Model (docs/scene-format.md).
// The URDF first (urdf_tree.cpp), then one reader per <nscd> element (read_*.cpp),
// each checked against the scene vocabulary (scene_vocabulary.cpp). Everything is
// built into a local Model that is returned only when the whole scene is valid.
#include "nscd_sim/scene_loader.hpp"

#include "scene_build.hpp"
#include "text_file.hpp"

namespace nscd {
namespace {

// The <nscd> elements, by name, in file order.
void collectNscd(SceneBuild& sb) {
  const SceneElementVocabulary& v = vocabularyOf("nscd");
  for (const XMLElement* n = sb.robot->FirstChildElement("nscd"); n; n = n->NextSiblingElement("nscd")) {
    checkAttributes(sb.c, n, v.attributes);
    checkChildren(sb.c, n, v.children);
    for (const XMLElement* e = n->FirstChildElement(); e; e = e->NextSiblingElement())
      sb.nscd[e->Name()].push_back(e);
  }
}

Model load(const std::string& text, const std::string& name,
           const std::vector<SettingOverride>& overrides) {
  SceneBuild sb;
  sb.c = Ctx{name};
  sb.text = text;
  sb.m.source_file = name;
  parseSceneXml(sb);
  prepassUrdf(sb);
  parseUrdfdom(sb);
  collectNscd(sb);
  readSimulation(sb, overrides);
  buildBodies(sb);
  buildUrdfJoints(sb);
  for (const XMLElement* e : sb.nscd["joint"]) readLoopJoint(sb, e);
  for (const XMLElement* e : sb.nscd["initial"]) readInitial(sb, e);
  placeBodies(sb);
  for (size_t j = 0; j < sb.m.joints.size(); ++j)
    sb.m.joints[j].initial_position = sb.initialPosition(static_cast<int>(j));
  for (const XMLElement* e : sb.nscd["clearance"]) readClearance(sb, e);
  for (const XMLElement* e : sb.nscd["contact"]) readContact(sb, e);
  for (const XMLElement* e : sb.nscd["spring"]) readSpring(sb, e);
  for (const XMLElement* e : sb.nscd["actuator"]) readActuator(sb, e);
  return std::move(sb.m);
}

}  // namespace

Model loadSceneFromString(const std::string& urdf_xml, const std::string& name,
                          const std::vector<SettingOverride>& overrides) {
  if (blank(urdf_xml)) throw SceneError(name + ": empty scene");
  return load(urdf_xml, name, overrides);
}

Model loadScene(const std::string& path, const std::vector<SettingOverride>& overrides) {
  const std::string text = readTextFile(path);
  if (blank(text)) throw SceneError(path + ": empty file");
  return load(text, path, overrides);
}

}  // namespace nscd
