// The node's parameters (node_params.hpp).
#include "node_params.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

#include "nscd_sim/key_figures.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "ros_conversions.hpp"

namespace nscd_node {
namespace {

// A finite number parameter, > 0 if `positive` else >= 0 (int, double or numeric
// string); `fallback` when absent. Throws nscd::SceneError.
double numberParam(const ros::NodeHandle& pnh, const std::string& key, double fallback,
                   bool positive) {
  XmlRpc::XmlRpcValue v;
  if (!pnh.getParam(key, v)) return fallback;
  std::string text;
  char* end = nullptr;
  double x = NAN;
  if (paramToString(v, text) && v.getType() != XmlRpc::XmlRpcValue::TypeArray &&
      v.getType() != XmlRpc::XmlRpcValue::TypeBoolean && !text.empty())
    x = std::strtod(text.c_str(), &end);
  const bool ok = end && *end == '\0' && std::isfinite(x) && (positive ? x > 0 : x >= 0);
  if (!ok)
    throw nscd::SceneError("parameter " + pnh.resolveName(key) + ": expected a " +
                           (positive ? "positive" : "non-negative") + " number");
  return x;
}

// A boolean parameter (true/false, or 0/1); false with a message if it is not one.
bool boolParam(const ros::NodeHandle& pnh, const std::string& key, bool& out, std::string& error) {
  XmlRpc::XmlRpcValue v;
  if (!pnh.getParam(key, v)) return true;
  if (v.getType() == XmlRpc::XmlRpcValue::TypeBoolean) {
    out = static_cast<bool>(v);
    return true;
  }
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt && (int(v) == 0 || int(v) == 1)) {
    out = int(v) == 1;
    return true;
  }
  std::string text;
  paramToString(v, text);
  error = "parameter " + pnh.resolveName(key) + ": expected true or false, got '" + text + "'";
  return false;
}

// numberParam without the throw: false and a message.
bool numberParamChecked(const ros::NodeHandle& pnh, const std::string& key, double& out, bool positive,
                        std::string& error) {
  try {
    out = numberParam(pnh, key, out, positive);
    return true;
  } catch (const nscd::SceneError& e) {
    error = e.what();
    return false;
  }
}

}  // namespace

void readDisplayParams(const ros::NodeHandle& pnh, MarkerStyle& style, std::vector<std::string>& errors) {
  std::string error;
  bool labels = style.labels;
  if (boolParam(pnh, "contact_labels", labels, error)) style.labels = labels;
  else errors.push_back(error + "; labels stay " + (style.labels ? "on" : "off"));
  double x = style.force_scale;
  if (numberParamChecked(pnh, "force_scale", x, false, error)) style.force_scale = x;
  else errors.push_back(error + " (m of arrow per N); kept " + std::to_string(style.force_scale));
  x = style.ecc_scale;
  if (numberParamChecked(pnh, "ecc_scale", x, false, error)) style.ecc_scale = x;
  else errors.push_back(error + " (the eccentricity magnification); kept " + std::to_string(style.ecc_scale));
}

EventTracker eventTracker(const ros::NodeHandle& pnh, const NodeOptions& o, const nscd::Model& model) {
  const std::vector<std::string> names = nscd::keyFigureNames(model);
  std::vector<EventDefinition> defs;
  for (const std::string& text : o.events) {
    EventDefinition d;
    std::string error;
    if (parseEventDefinition(text, names, d, error)) defs.push_back(d);
    else ROS_WARN("parameter %s: event %s; left out", pnh.resolveName("events").c_str(), error.c_str());
  }
  return EventTracker(defs);
}

const std::vector<std::string>& nodeParamKeys() {
  static const std::vector<std::string> keys = {
      "scene", "real_time_factor", "publish_rate", "diagnostics_rate", "start_paused",
      "force_scale", "marker_size", "ecc_scale", "schedule", "overlay_figures",
      "overlay_position", "overlay_size", "contact_labels", "label_size", "marker_z", "events",
      "command_rate_limit"};
  return keys;
}

namespace {

// label_size and marker_z: a bad value gets a warning and the default.
void readLabelPlacement(const ros::NodeHandle& pnh, MarkerStyle& markers) {
  std::string error;
  double x = 0;
  if (numberParamChecked(pnh, "label_size", x, true, error)) markers.label_size = x;
  else ROS_WARN("%s (text height, m); the default (3 marker_size) is used", error.c_str());
  if (pnh.hasParam("marker_z")) {
    XmlRpc::XmlRpcValue z;
    pnh.getParam("marker_z", z);
    if (paramNumber(z, markers.marker_z)) {
      markers.have_marker_z = true;
    } else {
      ROS_WARN("parameter %s: expected a number (m, world z of the eccentricity markers and labels); "
               "they stay at the bearings' own height", pnh.resolveName("marker_z").c_str());
    }
  }
}

// ~events: a string or a list of strings; a bad entry gets a warning and is left out.
void readEvents(const ros::NodeHandle& pnh, std::vector<std::string>& events) {
  XmlRpc::XmlRpcValue ev;
  if (!pnh.getParam("events", ev)) return;
  if (ev.getType() == XmlRpc::XmlRpcValue::TypeString) {
    events.push_back(static_cast<std::string>(ev));
  } else if (ev.getType() == XmlRpc::XmlRpcValue::TypeArray) {
    for (int i = 0; i < ev.size(); ++i) {
      if (ev[i].getType() == XmlRpc::XmlRpcValue::TypeString) events.push_back(static_cast<std::string>(ev[i]));
      else ROS_WARN("parameter %s: entry %d is not a string \"LABEL: FIGURE > VALUE\"; left out",
                    pnh.resolveName("events").c_str(), i);
    }
  } else {
    ROS_WARN("parameter %s: expected a list of strings \"LABEL: FIGURE > VALUE\"; no events shown",
             pnh.resolveName("events").c_str());
  }
}

// ~overlay_figures: a list of key-figure names (or its text); throws SceneError.
void readOverlayFigures(const ros::NodeHandle& pnh, NodeOptions& o) {
  XmlRpc::XmlRpcValue ov;
  if (!pnh.getParam("overlay_figures", ov)) return;
  o.overlay_figures_set = true;
  if (ov.getType() == XmlRpc::XmlRpcValue::TypeString) {
    // From the command line (_overlay_figures:=[a, b]) a list arrives as text.
    std::string text = static_cast<std::string>(ov);
    for (char& c : text)
      if (c == ',' || c == '[' || c == ']' || c == '"' || c == '\'') c = ' ';
    std::istringstream in(text);
    for (std::string w; in >> w;) o.overlay_figures.push_back(w);
  } else if (ov.getType() != XmlRpc::XmlRpcValue::TypeArray) {
    throw nscd::SceneError("parameter " + pnh.resolveName("overlay_figures") +
                           ": expected a list of key-figure names, e.g. [C7.fn, probe.effort]");
  }
  for (int i = 0; ov.getType() == XmlRpc::XmlRpcValue::TypeArray && i < ov.size(); ++i) {
    if (ov[i].getType() != XmlRpc::XmlRpcValue::TypeString)
      throw nscd::SceneError("parameter " + pnh.resolveName("overlay_figures") +
                             ": expected strings (key-figure names)");
    o.overlay_figures.push_back(static_cast<std::string>(ov[i]));
  }
}

// ~overlay_position: 3 numbers; throws SceneError.
void readOverlayPosition(const ros::NodeHandle& pnh, std::vector<double>& position) {
  XmlRpc::XmlRpcValue ov;
  if (!pnh.getParam("overlay_position", ov)) return;
  bool ok = ov.getType() == XmlRpc::XmlRpcValue::TypeArray && ov.size() == 3;
  for (int i = 0; ok && i < 3; ++i) {
    double x = 0;
    ok = paramNumber(ov[i], x);
    if (ok) position.push_back(x);
  }
  if (!ok)
    throw nscd::SceneError("parameter " + pnh.resolveName("overlay_position") +
                           ": expected 3 numbers [x, y, z] (m, world frame)");
}

// ~command_rate_limit: {ACTUATOR: RATE, ...}; throws SceneError.
void readCommandRateLimits(const ros::NodeHandle& pnh, NodeOptions& o) {
  XmlRpc::XmlRpcValue v;
  if (!pnh.getParam("command_rate_limit", v)) return;
  const std::string where = "parameter " + pnh.resolveName("command_rate_limit");
  if (v.getType() != XmlRpc::XmlRpcValue::TypeStruct)
    throw nscd::SceneError(where + ": expected {ACTUATOR: RATE, ...} (command units per second)");
  for (auto it = v.begin(); it != v.end(); ++it) {
    XmlRpc::XmlRpcValue& r = it->second;
    double rate = NAN;
    if (!(paramNumber(r, rate) && rate > 0))
      throw nscd::SceneError(where + "/" + it->first + ": expected a positive number (command units per second)");
    o.command_rate_limits.emplace_back(it->first, rate);
  }
}

// ~schedule: a string or a list of strings; throws SceneError.
void readSchedules(const ros::NodeHandle& pnh, std::vector<std::string>& schedules) {
  XmlRpc::XmlRpcValue v;
  if (!pnh.getParam("schedule", v)) return;
  const std::string where = "parameter " + pnh.resolveName("schedule");
  if (v.getType() == XmlRpc::XmlRpcValue::TypeString) {
    schedules.push_back(static_cast<std::string>(v));
  } else if (v.getType() == XmlRpc::XmlRpcValue::TypeArray) {
    for (int i = 0; i < v.size(); ++i) {
      if (v[i].getType() != XmlRpc::XmlRpcValue::TypeString)
        throw nscd::SceneError(where + ": expected strings \"NAME=t0:v0,t1:v1,...\"");
      schedules.push_back(static_cast<std::string>(v[i]));
    }
  } else {
    throw nscd::SceneError(where + ": expected a string or a list of strings " +
                           "\"NAME=t0:v0,t1:v1,...\"");
  }
}

}  // namespace

NodeOptions readNodeOptions(const ros::NodeHandle& pnh) {
  NodeOptions o;
  o.real_time_factor = numberParam(pnh, "real_time_factor", o.real_time_factor, false);
  o.publish_rate = numberParam(pnh, "publish_rate", o.publish_rate, true);
  o.diagnostics_rate = numberParam(pnh, "diagnostics_rate", o.diagnostics_rate, true);
  o.markers.force_scale = numberParam(pnh, "force_scale", o.markers.force_scale, false);
  o.markers.size = numberParam(pnh, "marker_size", o.markers.size, true);
  o.markers.ecc_scale = numberParam(pnh, "ecc_scale", o.markers.ecc_scale, false);
  // The labels, their size, the marker plane and the events only change what is
  // drawn: a bad value gets a warning and the default, and the node runs.
  std::vector<std::string> display_errors;
  readDisplayParams(pnh, o.markers, display_errors);
  for (const std::string& e : display_errors) ROS_WARN("%s", e.c_str());
  readLabelPlacement(pnh, o.markers);
  readEvents(pnh, o.events);
  pnh.param("start_paused", o.start_paused, o.start_paused);
  ros::param::param("/use_sim_time", o.use_sim_time, false);
  o.overlay_size = numberParam(pnh, "overlay_size", 0.0, false);
  readOverlayFigures(pnh, o);
  readOverlayPosition(pnh, o.overlay_position);
  readCommandRateLimits(pnh, o);
  readSchedules(pnh, o.schedules);
  return o;
}

StatusOverlay statusOverlay(const ros::NodeHandle& pnh, const NodeOptions& o, const nscd::Model& model) {
  StatusOverlay s;
  const std::vector<std::string> names = nscd::keyFigureNames(model);
  std::vector<std::string> wanted = o.overlay_figures;
  if (!o.overlay_figures_set)
    for (const nscd::Actuator& a : model.actuators) wanted.push_back(a.name + ".effort");
  for (const std::string& w : wanted) {
    const auto it = std::find(names.begin(), names.end(), w);
    if (it == names.end()) {
      std::string all;
      for (const std::string& n : names) all += (all.empty() ? "" : ", ") + n;
      throw nscd::SceneError("parameter " + pnh.resolveName("overlay_figures") + ": unknown figure '" +
                             w + "' (figures: " + (all.empty() ? "none" : all) + ")");
    }
    s.figures.push_back(static_cast<int>(it - names.begin()));
  }
  // Default: beside the bodies' initial centres of mass (a third of their extent,
  // at least 25 mm, below the lowest in y), a text height of 1/25 of that extent.
  nscd::Vec3 lo = nscd::Vec3::Constant(1e300), hi = nscd::Vec3::Constant(-1e300);
  for (const nscd::Body& b : model.bodies) {
    lo = lo.cwiseMin(b.initial_pose.p);
    hi = hi.cwiseMax(b.initial_pose.p);
  }
  if (model.bodies.empty()) lo = hi = nscd::Vec3::Zero();
  const double extent = std::max(0.025, (hi - lo).norm());
  s.height = o.overlay_size > 0 ? o.overlay_size : extent / 25;
  s.position = o.overlay_position.size() == 3
                   ? nscd::Vec3(o.overlay_position[0], o.overlay_position[1], o.overlay_position[2])
                   : nscd::Vec3(0.5 * (lo.x() + hi.x()), lo.y() - 0.35 * extent, hi.z());
  return s;
}

std::vector<nscd::BoundSchedule> bindSchedules(const ros::NodeHandle& pnh,
                                               const std::vector<std::string>& texts,
                                               const nscd::Model& model) {
  try {
    return nscd::bindCommandSchedules(texts, model);
  } catch (const std::invalid_argument& e) {
    throw nscd::SceneError("parameter " + pnh.resolveName("schedule") + ": " + e.what());
  }
}

std::vector<CommandRateLimit> bindCommandRateLimits(const ros::NodeHandle& pnh, const NodeOptions& o,
                                                    const nscd::Model& model) {
  std::vector<CommandRateLimit> limits;
  for (const auto& [name, rate] : o.command_rate_limits) {
    const int a = model.findActuator(name);
    if (a < 0)
      throw nscd::SceneError("parameter " + pnh.resolveName("command_rate_limit") + ": no actuator '" +
                             name + "' in " + model.source_file);
    limits.push_back({a, rate});
  }
  return limits;
}

void warnUnknownParams(const ros::NodeHandle& pnh) {
  std::set<std::string> known(nodeParamKeys().begin(), nodeParamKeys().end());
  known.insert(nscd::settingKeys().begin(), nscd::settingKeys().end());
  std::vector<std::string> names;
  if (!ros::param::getParamNames(names)) return;
  const std::string prefix = pnh.getNamespace() + "/";
  for (const std::string& n : names) {
    if (n.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string key = n.substr(prefix.size());
    if (known.count(key.substr(0, key.find('/')))) continue;
    std::string node_keys;
    for (const std::string& k : nodeParamKeys()) node_keys += (node_keys.empty() ? "" : ", ") + k;
    ROS_WARN("unknown parameter %s ignored (known: the simulation settings and %s)", n.c_str(),
             node_keys.c_str());
  }
}

nscd::Model loadModel(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) {
  const std::vector<nscd::SettingOverride> overrides = settingOverridesFromParams(pnh);
  XmlRpc::XmlRpcValue scene;
  if (pnh.getParam("scene", scene)) {
    if (scene.getType() != XmlRpc::XmlRpcValue::TypeString)
      throw nscd::SceneError("parameter " + pnh.resolveName("scene") +
                             ": expected a string (the scene file's path), got " +
                             paramTypeName(scene));
    const std::string path = static_cast<std::string>(scene);
    if (!path.empty()) return nscd::loadScene(path, overrides);
  }
  std::string xml;
  if (nh.getParam("robot_description", xml) && !xml.empty())
    return nscd::loadSceneFromString(xml, nh.resolveName("robot_description"), overrides);
  throw nscd::SceneError(pnh.resolveName("scene") + ": no scene: set ~scene to a file or " +
                         nh.resolveName("robot_description") + " to the URDF text");
}

}  // namespace nscd_node
