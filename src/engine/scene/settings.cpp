// Simulation settings: the key=value vocabulary shared by <simulation>, YAML
// configs, --set and ROS parameters, and its validation.
#include <yaml-cpp/yaml.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <set>
#include <sstream>

#include "nscd_sim/scene_loader.hpp"
#include "number_text.hpp"
#include "text_file.hpp"

namespace nscd {
namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

struct Bad {
  std::string what;
};

double finiteValue(const std::string& key, const std::string& v) {
  double x = 0;
  if (!parseNumber(v, x)) throw Bad{"setting '" + key + "': '" + v + "' is not a number"};
  if (!std::isfinite(x)) throw Bad{"setting '" + key + "': '" + v + "' is not finite"};
  return x;
}

int intValue(const std::string& key, const std::string& v, long lo, long hi) {
  const std::string s = trim(v);
  long x = 0;
  auto r = std::from_chars(s.data(), s.data() + s.size(), x);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size())
    throw Bad{"setting '" + key + "': '" + v + "' is not an integer"};
  if (x < lo || x > hi)
    throw Bad{"setting '" + key + "' must be in [" + std::to_string(lo) + ", " +
              std::to_string(hi) + "], got " + s};
  return static_cast<int>(x);
}

bool boolValue(const std::string& key, const std::string& v) {
  const std::string s = lower(trim(v));
  if (s == "true" || s == "1" || s == "yes" || s == "on") return true;
  if (s == "false" || s == "0" || s == "no" || s == "off") return false;
  throw Bad{"setting '" + key + "': '" + v + "' is not a boolean (true or false)"};
}

void requireIn(const std::string& key, double x, double lo, bool lo_open, double hi,
               bool hi_open) {
  const bool ok = (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  if (!ok)
    throw Bad{"setting '" + key + "' must be in " + (lo_open ? "(" : "[") + num(lo) + ", " +
              num(hi) + (hi_open ? ")" : "]") + ", got " + num(x)};
}

// Every setting: its key and how a value is read into Settings. The one list
// of keys (settingKeys(), the scene vocabulary of <simulation>, the docs test).
struct SettingRule {
  const char* key;
  void (*read)(Settings& st, const std::string& key, const std::string& v);
};

const std::vector<SettingRule>& settingRules() {
  static const std::vector<SettingRule> rules = {
      {"dt",
       [](Settings& st, const std::string& key, const std::string& v) {
         const double x = finiteValue(key, v);
         requireIn(key, x, 0, true, 0.1, false);
         st.dt = x;
       }},
      {"theta",
       [](Settings& st, const std::string& key, const std::string& v) {
         const double x = finiteValue(key, v);
         requireIn(key, x, 0.5, false, 1, false);
         st.theta = x;
       }},
      {"gravity",
       [](Settings& st, const std::string& key, const std::string& v) {
         // "0 0 -9.81", also "0, 0, -9.81" or "[0, 0, -9.81]" (ROS parameter strings).
         std::string s = v;
         for (char& c : s)
           if (c == ',' || c == '[' || c == ']') c = ' ';
         std::istringstream in(s);
         std::vector<std::string> parts;
         for (std::string w; in >> w;) parts.push_back(w);
         if (parts.size() != 3)
           throw Bad{"setting 'gravity': expected 3 numbers \"gx gy gz\", got '" + v + "'"};
         Vec3 g;
         for (int i = 0; i < 3; ++i) g[i] = finiteValue(key, parts[i]);
         st.gravity = g;
       }},
      {"tolerance",
       [](Settings& st, const std::string& key, const std::string& v) {
         const double x = finiteValue(key, v);
         requireIn(key, x, 0, true, 1, true);
         st.tolerance = x;
       }},
      {"max_iterations",
       [](Settings& st, const std::string& key, const std::string& v) {
         st.max_iterations = intValue(key, v, 1, 10000000);
       }},
      {"max_step_halvings",
       [](Settings& st, const std::string& key, const std::string& v) {
         st.max_step_halvings = intValue(key, v, 0, 20);
       }},
      {"projection",
       [](Settings& st, const std::string& key, const std::string& v) {
         st.projection = boolValue(key, v);
       }},
      {"projection_tolerance",
       [](Settings& st, const std::string& key, const std::string& v) {
         const double x = finiteValue(key, v);
         if (!(x > 0)) throw Bad{"setting 'projection_tolerance' must be > 0, got " + num(x)};
         st.projection_tolerance = x;
       }},
      {"projection_max_iterations",
       [](Settings& st, const std::string& key, const std::string& v) {
         st.projection_max_iterations = intValue(key, v, 0, 10000000);
       }},
      {"activation_gamma",
       [](Settings& st, const std::string& key, const std::string& v) {
         const double x = finiteValue(key, v);
         requireIn(key, x, 0, false, 1, false);
         st.activation_gamma = x;
       }},
      {"activation_margin",
       [](Settings& st, const std::string& key, const std::string& v) {
         const double x = finiteValue(key, v);
         if (!(x >= 0)) throw Bad{"setting 'activation_margin' must be >= 0, got " + num(x)};
         st.activation_margin = x;
       }},
      {"contact_prediction",
       [](Settings& st, const std::string& key, const std::string& v) {
         const double x = finiteValue(key, v);
         requireIn(key, x, 0, false, 1, false);
         st.contact_prediction = x;
       }},
      {"joint_work",
       [](Settings& st, const std::string&, const std::string& v) {
         const std::string w = lower(trim(v));
         if (w == "none") st.joint_work = JointWork::None;
         else if (w == "moreau") st.joint_work = JointWork::Moreau;
         else throw Bad{"setting 'joint_work': '" + v + "' is not one of none, moreau"};
       }},
      {"planar",
       [](Settings& st, const std::string&, const std::string& v) {
         const std::string s = lower(trim(v));
         if (s == "false" || s == "none" || s == "0" || s == "no") st.planar = PlanarMode::None;
         else if (s == "true" || s == "xy" || s == "1" || s == "yes") st.planar = PlanarMode::XY;
         else throw Bad{"setting 'planar': '" + v + "' is not one of false, none, true, xy"};
       }},
      {"step_control",
       [](Settings& st, const std::string&, const std::string& v) {
         const std::string s = lower(trim(v));
         if (s == "fixed") st.step_control = StepControl::Fixed;
         else if (s == "adaptive") st.step_control = StepControl::Adaptive;
         else throw Bad{"setting 'step_control': '" + v + "' is not one of fixed, adaptive"};
       }},
      {"rtol",
       [](Settings& st, const std::string& key, const std::string& v) {
         const double x = finiteValue(key, v);
         requireIn(key, x, 0, false, 1, true);
         st.rtol = x;
       }},
      {"atol",
       [](Settings& st, const std::string& key, const std::string& v) {
         const double x = finiteValue(key, v);
         if (!(x > 0)) throw Bad{"setting 'atol' must be > 0, got " + num(x)};
         st.atol = x;
       }},
      {"dt_min",
       [](Settings& st, const std::string& key, const std::string& v) {
         const double x = finiteValue(key, v);
         requireIn(key, x, 0, false, 0.1, false);
         st.dt_min = x;
       }},
      {"max_order",
       [](Settings& st, const std::string& key, const std::string& v) {
         st.max_order = intValue(key, v, 2, 12);
       }},
  };
  return rules;
}

std::string knownKeys() {
  std::string s;
  for (const auto& k : settingKeys()) s += (s.empty() ? "" : ", ") + k;
  return s;
}

void apply(Settings& st, const std::string& key, const std::string& v) {
  if (trim(v).empty()) throw Bad{"setting '" + key + "' has no value"};
  for (const SettingRule& r : settingRules())
    if (key == r.key) return r.read(st, key, v);
  throw Bad{"unknown setting '" + key + "' (known: " + knownKeys() + ")"};
}

std::string joinScalars(const YAML::Node& seq, const std::string& where, const std::string& key) {
  std::string s;
  for (const auto& item : seq) {
    if (!item.IsScalar())
      throw SceneError(where + ": setting '" + key + "': list items must be numbers");
    s += (s.empty() ? "" : " ") + item.Scalar();
  }
  return s;
}

}  // namespace

const std::vector<std::string>& settingKeys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k;
    for (const SettingRule& r : settingRules()) k.push_back(r.key);
    return k;
  }();
  return keys;
}

void applySetting(Settings& settings, const SettingOverride& o) {
  try {
    apply(settings, trim(o.key), o.value);
  } catch (const Bad& b) {
    throw SceneError((o.origin.empty() ? std::string("setting") : o.origin) + ": " + b.what);
  }
}

std::vector<SettingOverride> readSettingsYaml(const std::string& path) {
  const std::string text = readTextFile(path);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    const std::string line = e.mark.is_null() ? "" : ":" + std::to_string(e.mark.line + 1);
    throw SceneError(path + line + ": YAML error: " + e.msg);
  }
  std::vector<SettingOverride> out;
  if (root.IsNull()) return out;  // an empty config changes nothing
  auto at = [&](const YAML::Node& n) {
    return n.Mark().is_null() ? path : path + ":" + std::to_string(n.Mark().line + 1);
  };
  if (!root.IsMap())
    throw SceneError(at(root) + ": expected a mapping of settings (key: value)");

  std::set<std::string> seen;
  Settings scratch;  // validates each value now, so errors point at the YAML line
  auto take = [&](const YAML::Node& map, auto& self, bool nested) -> void {
    for (const auto& kv : map) {
      // Copies: yaml-cpp's iterator hands out temporaries.
      const YAML::Node k = kv.first;
      const YAML::Node v = kv.second;
      const std::string where = at(k);
      if (!k.IsScalar()) throw SceneError(where + ": setting names must be plain words");
      const std::string key = k.Scalar();
      if (key == "simulation" && !nested && v.IsMap()) {
        self(v, self, true);
        continue;
      }
      std::string value;
      if (v.IsScalar()) value = v.Scalar();
      else if (v.IsSequence()) value = joinScalars(v, where, key);
      else if (v.IsNull()) throw SceneError(where + ": setting '" + key + "' has no value");
      else throw SceneError(where + ": setting '" + key + "': expected a value, got a mapping");
      if (!seen.insert(key).second)
        throw SceneError(where + ": setting '" + key + "' given twice");
      SettingOverride o{key, value, where};
      applySetting(scratch, o);
      out.push_back(o);
    }
  };
  take(root, take, false);
  return out;
}

}  // namespace nscd
