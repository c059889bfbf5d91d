// Fuzz target: the node's YAML config (the private parameters roslaunch loads
// from config/*.yaml) read by nscd_sim_node's own code. The YAML is turned into
// parameter values as rosparam would (PyYAML's YAML 1.1 types: `1e-3` without a
// dot is a string, `yes` a boolean; an integer beyond 32 bits or a null cannot be
// sent, so rosparam refuses the file), set under the node's private namespace on
// a ROS master (scripts/fuzz.sh starts a private one), and read as
// src/node/main.cpp reads them: readNodeOptions, loadModel (~scene is replaced by
// the actuated pendulum when it is a string), bindSchedules, statusOverlay,
// eventTracker, warnUnknownParams. Every refusal is one line; a config the node
// accepts is stepped 3 times (fuzz_support.hpp).
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <regex>
#include <string>

#include <ros/ros.h>
#include <yaml-cpp/yaml.h>

#include "fuzz_support.hpp"
#include "node_params.hpp"
#include "nscd_sim/scene_loader.hpp"

namespace {

struct Refused {};  // rosparam could not load the file

XmlRpc::XmlRpcValue toParam(const YAML::Node& n) {
  XmlRpc::XmlRpcValue v;
  if (n.IsSequence()) {
    v.setSize(static_cast<int>(n.size()));
    for (size_t i = 0; i < n.size(); ++i) v[static_cast<int>(i)] = toParam(n[i]);
    return v;
  }
  if (n.IsMap()) {
    int offset = 0;  // an empty struct (XmlRpcValue has no constructor for one)
    v = XmlRpc::XmlRpcValue("<value><struct></struct></value>", &offset);
    for (const auto& kv : n) {
      if (!kv.first.IsScalar()) throw Refused{};
      v[kv.first.Scalar()] = toParam(kv.second);
    }
    return v;
  }
  if (!n.IsScalar()) throw Refused{};  // null
  const std::string s = n.Scalar();
  if (n.Tag() != "?") return XmlRpc::XmlRpcValue(s);  // quoted or tagged: a string
  static const std::regex null_re("~|null|Null|NULL|");
  static const std::regex true_re("yes|Yes|YES|true|True|TRUE|on|On|ON");
  static const std::regex false_re("no|No|NO|false|False|FALSE|off|Off|OFF");
  static const std::regex int_re("[-+]?(0|[1-9][0-9_]*)");
  static const std::regex float_re(
      "[-+]?([0-9][0-9_]*)?\\.[0-9_]*([eE][-+][0-9]+)?|[-+]?\\.(inf|Inf|INF)|\\.(nan|NaN|NAN)");
  if (std::regex_match(s, null_re)) throw Refused{};
  if (std::regex_match(s, true_re)) return XmlRpc::XmlRpcValue(true);
  if (std::regex_match(s, false_re)) return XmlRpc::XmlRpcValue(false);
  std::string digits;
  for (char c : s)
    if (c != '_') digits += c;
  if (std::regex_match(s, int_re)) {
    errno = 0;
    const long long x = std::strtoll(digits.c_str(), nullptr, 10);
    if (x < INT32_MIN || x > INT32_MAX || errno == ERANGE) throw Refused{};  // XML-RPC has 32-bit ints
    return XmlRpc::XmlRpcValue(static_cast<int>(x));
  }
  if (std::regex_match(s, float_re)) {
    if (s.find("inf") != std::string::npos || s.find("Inf") != std::string::npos || s.find("INF") != std::string::npos)
      return XmlRpc::XmlRpcValue(s[0] == '-' ? -HUGE_VAL : HUGE_VAL);
    if (s.find('.') == 0 && (s.find("nan") != std::string::npos || s.find("NaN") != std::string::npos ||
                             s.find("NAN") != std::string::npos))
      return XmlRpc::XmlRpcValue(std::nan(""));
    return XmlRpc::XmlRpcValue(std::strtod(digits.c_str(), nullptr));
  }
  return XmlRpc::XmlRpcValue(s);
}

ros::NodeHandle* g_nh = nullptr;
ros::NodeHandle* g_pnh = nullptr;
std::string g_scene;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  ros::init(*argc, *argv, "nscd_fuzz_node_config",
            ros::init_options::NoSigintHandler | ros::init_options::NoRosout | ros::init_options::AnonymousName);
  if (!ros::master::check()) nscd_fuzz::fail("no ROS master (ROS_MASTER_URI): scripts/fuzz.sh starts one");
  g_nh = new ros::NodeHandle;
  g_pnh = new ros::NodeHandle("~");
  g_scene = std::string(NSCD_SOURCE_DIR) + "/test/ros/actuated_pendulum.urdf";
  // The node's warnings are part of what is fuzzed, not of the log.
  ros::console::set_logger_level(ROSCONSOLE_DEFAULT_NAME, ros::console::levels::Error);
  ros::console::notifyLoggerLevelsChanged();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  XmlRpc::XmlRpcValue params;
  try {
    const YAML::Node root = YAML::Load(std::string(reinterpret_cast<const char*>(data), size));
    if (!root.IsMap()) return 0;  // rosparam loads a mapping into a namespace
    params = toParam(root);
  } catch (const YAML::Exception&) {
    return 0;  // rosparam refuses the file
  } catch (const Refused&) {
    return 0;
  }
  if (params.hasMember("scene") && params["scene"].getType() == XmlRpc::XmlRpcValue::TypeString)
    params["scene"] = g_scene;
  else if (!params.hasMember("scene"))
    params["scene"] = g_scene;
  ros::param::set(g_pnh->getNamespace(), params);

  nscd_node::NodeOptions options;
  nscd::Model model;
  try {
    options = nscd_node::readNodeOptions(*g_pnh);
    model = nscd_node::loadModel(*g_nh, *g_pnh);
    nscd_node::bindSchedules(*g_pnh, options.schedules, model);
    nscd_node::statusOverlay(*g_pnh, options, model);
  } catch (const std::exception& e) {  // main(): ROS_FATAL, exit status 2
    nscd_fuzz::expectOneLine(e.what(), "");
    return 0;
  }
  nscd_node::eventTracker(*g_pnh, options, model);
  nscd_node::warnUnknownParams(*g_pnh);
  // A config may raise the budgets (max_iterations up to 1e7): bounded, as in scene_loader.
  nscd_fuzz::boundBudget(model.settings);
  nscd_fuzz::stepAndCheck(std::move(model), 3, {}, options.schedules, {}, /*stop_when_unsolved=*/true);
  return 0;
}
