// The scene vocabulary: every element of <nscd> (and the <origin>/<axis> they
// share) with the attributes and child elements the loader accepts, in the
// order its messages list them. The element readers check against this table
// only, and a test checks docs/scene-format.md against it.
#include <stdexcept>

#include "xml_reading.hpp"

namespace nscd {

const std::vector<SceneElementVocabulary>& sceneVocabulary() {
  static const std::vector<SceneElementVocabulary> table = [] {
    std::vector<SceneElementVocabulary> t = {
        {"nscd", "", "robot", {}, {"joint", "initial", "clearance", "contact", "spring", "actuator", "simulation"}},
        {"joint", "", "nscd", {"name", "type", "parent", "child"}, {"origin", "axis"}},
        {"origin", "", "joint", {"xyz", "rpy"}, {}},
        {"axis", "", "joint", {"xyz"}, {}},
        {"initial", "joint", "nscd", {"joint", "position"}, {}},
        {"initial", "link", "nscd", {"link", "vx", "vy", "vz", "wx", "wy", "wz"}, {}},
        {"clearance", "", "nscd",
         {"joint", "journal", "radius", "radial", "length", "axial", "bumps", "bump_radius", "bump_at", "mu", "e",
          "initial_offset"},
         {}},
        {"contact", "", "nscd", {"name", "mu", "e"}, {"shape"}},
        {"shape", "sphere", "contact", {"link", "type", "radius"}, {"origin"}},
        {"shape", "capsule", "contact", {"link", "type", "radius", "length"}, {"origin"}},
        {"shape", "cylinder", "contact", {"link", "type", "radius", "length", "start", "span", "hollow"}, {"origin"}},
        {"shape", "box", "contact", {"link", "type", "size"}, {"origin"}},
        {"shape", "plane", "contact", {"link", "type"}, {"origin"}},
        {"shape", "ring", "contact", {"link", "type", "radius", "start", "span"}, {"origin"}},
        {"shape", "face", "contact", {"link", "type", "size"}, {"origin"}},
        {"spring", "linear", "nscd", {"name", "type", "stiffness", "rest_length", "damping"}, {"end", "force", "couple"}},
        {"end", "", "spring", {"link", "xyz"}, {}},
        {"spring", "torsion", "nscd", {"name", "type", "joint", "stiffness", "rest_angle", "damping"},
         {"angle", "force", "couple"}},
        {"angle", "", "spring", {"link_a", "link_b", "axis"}, {}},
        {"force", "", "spring", {"link", "xyz", "direction", "scale"}, {}},
        {"couple", "", "spring", {"link", "axis", "scale"}, {}},
        {"actuator", "position", "nscd", {"name", "type", "joint", "kp", "kd", "max_effort", "command", "schedule"}, {}},
        {"actuator", "prescribed", "nscd", {"name", "type", "link", "joint", "axis", "constrain", "command", "schedule"}, {}},
        {"actuator", "force", "nscd", {"name", "type", "link", "xyz", "direction", "command", "schedule"}, {}},
        {"actuator", "torque", "nscd", {"name", "type", "link", "axis", "command", "schedule"}, {}},
        {"simulation", "", "nscd", settingKeys(), {}},
    };
    return t;
  }();
  return table;
}

const SceneElementVocabulary& vocabularyOf(const std::string& element, const std::string& variant) {
  for (const SceneElementVocabulary& v : sceneVocabulary())
    if (v.element == element && v.variant == variant) return v;
  throw std::logic_error("scene vocabulary has no <" + element + "> " + variant);
}

}  // namespace nscd
