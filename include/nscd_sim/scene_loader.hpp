// Scene file (URDF + <nscd> annotations) -> Model. The format: docs/scene-format.md.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nscd_sim/model.hpp"

namespace nscd {

// Bad input: what() is the single line "FILE:LINE: what is wrong"
// (LINE omitted when there is no line to point at, e.g. a missing file). Control
// characters in it (the input it quotes may hold a line break) become C escapes
// such as \n.
class SceneError : public std::runtime_error {
 public:
  explicit SceneError(const std::string& what);
};

// A settings override "key=value" (from --set, YAML or ROS parameters).
struct SettingOverride {
  std::string key;
  std::string value;
  std::string origin;  // for messages, e.g. "--set" or "config.yaml"
};

// Loads and validates a scene. Throws SceneError; never returns a half-loaded model.
// Overrides are applied after the <simulation> element, in order.
Model loadScene(const std::string& path, const std::vector<SettingOverride>& overrides = {});

// Same, from an in-memory URDF string (robot_description); `name` is used in messages.
Model loadSceneFromString(const std::string& urdf_xml, const std::string& name,
                          const std::vector<SettingOverride>& overrides = {});

// Applies one override to settings; throws SceneError "ORIGIN: what" on an unknown
// key or a bad value (dt <= 0, theta outside [0.5, 1], negative tolerance, NaN ...).
void applySetting(Settings& settings, const SettingOverride& o);

// Reads a flat YAML mapping of settings (key: value) into overrides.
// Throws SceneError "FILE:LINE: what" on malformed YAML.
std::vector<SettingOverride> readSettingsYaml(const std::string& path);

// Names of the setting keys, for --help and error messages.
const std::vector<std::string>& settingKeys();

// What the loader accepts, element by element: the single table its checks use
// (so docs/scene-format.md can be checked against it). `variant` names the
// type attribute's value for elements whose attributes depend on it (a
// <shape type="box">, a <spring type="torsion">, ...); `parent` the element it
// belongs in. <simulation> takes every setting key as an attribute.
struct SceneElementVocabulary {
  std::string element;
  std::string variant;
  std::string parent;
  std::vector<std::string> attributes;
  std::vector<std::string> children;
};
const std::vector<SceneElementVocabulary>& sceneVocabulary();

}  // namespace nscd
