#include "ros_conversions.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace nscd_node {
namespace {

template <class Msg>
Msg xyzMsg(const nscd::Vec3& v) {
  Msg m;
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
  return m;
}

}  // namespace

geometry_msgs::Point toPoint(const nscd::Vec3& v) { return xyzMsg<geometry_msgs::Point>(v); }
geometry_msgs::Vector3 toVector3(const nscd::Vec3& v) { return xyzMsg<geometry_msgs::Vector3>(v); }

geometry_msgs::Quaternion toQuaternion(const nscd::Quat& q) {
  geometry_msgs::Quaternion o;
  o.w = q.w();
  o.x = q.x();
  o.y = q.y();
  o.z = q.z();
  return o;
}

geometry_msgs::Pose toPose(const nscd::Pose& pose) {
  geometry_msgs::Pose o;
  o.position = toPoint(pose.p);
  o.orientation = toQuaternion(pose.q);
  return o;
}

geometry_msgs::Transform toTransform(const nscd::Pose& pose) {
  geometry_msgs::Transform t;
  t.translation = toVector3(pose.p);
  t.rotation = toQuaternion(pose.q.normalized());
  return t;
}

nscd::Pose fromPose(const geometry_msgs::Pose& pose) {
  nscd::Pose o;
  o.p = nscd::Vec3(pose.position.x, pose.position.y, pose.position.z);
  o.q = nscd::Quat(pose.orientation.w, pose.orientation.x, pose.orientation.y, pose.orientation.z);
  if (!(o.q.norm() > 0) || !std::isfinite(o.q.norm())) o.q = nscd::Quat::Identity();
  o.q.normalize();
  return o;
}

std_msgs::ColorRGBA rgba(float r, float g, float b, float a) {
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

bool paramNumber(const XmlRpc::XmlRpcValue& v, double& out) {
  double x = NAN;
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) x = static_cast<const double&>(v);
  else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) x = static_cast<const int&>(v);
  if (!std::isfinite(x)) return false;
  out = x;
  return true;
}

const std::string& bodyLinkName(const nscd::Model& model, int body) {
  if (body < 0 || body >= static_cast<int>(model.bodies.size())) return model.world_frame;
  return model.bodies[body].name;
}

const std::string& contactSourceName(const nscd::Model& model, const nscd::ContactReport& c) {
  static const std::string unknown = "?";
  if (c.clearance) {
    if (c.source >= 0 && c.source < static_cast<int>(model.clearance_joints.size()))
      return model.clearance_joints[c.source].name;
  } else if (c.source >= 0 && c.source < static_cast<int>(model.contacts.size())) {
    return model.contacts[c.source].name;
  }
  return unknown;
}

void toContactMsg(const nscd::Model& model, const nscd::ContactReport& c, nscd_sim::Contact& out) {
  out.name = contactSourceName(model, c);
  out.clearance = c.clearance;
  out.feature = static_cast<uint32_t>(c.feature);
  out.link_a = bodyLinkName(model, c.body_a);
  out.link_b = bodyLinkName(model, c.body_b);
  out.point = toPoint(c.point);
  out.normal = toVector3(c.normal);
  out.normal_force = c.fn;
  out.tangential_force = toVector3(c.ft);
  out.gap = c.gap;
  out.sliding = c.sliding;
}

// Shortest decimal form that reads back to the same double.
static std::string formatDouble(double v) {
  char buf[40];
  for (int prec = 15; prec <= 17; ++prec) {
    std::snprintf(buf, sizeof buf, "%.*g", prec, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

std::string paramTypeName(const XmlRpc::XmlRpcValue& value) {
  switch (value.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean: return "a boolean";
    case XmlRpc::XmlRpcValue::TypeInt: return "an integer";
    case XmlRpc::XmlRpcValue::TypeDouble: return "a number";
    case XmlRpc::XmlRpcValue::TypeString: return "a string";
    case XmlRpc::XmlRpcValue::TypeDateTime: return "a date";
    case XmlRpc::XmlRpcValue::TypeBase64: return "binary data";
    case XmlRpc::XmlRpcValue::TypeArray: return "a list";
    case XmlRpc::XmlRpcValue::TypeStruct: return "a dictionary";
    default: return "no value";
  }
}

bool paramToString(const XmlRpc::XmlRpcValue& value, std::string& out) {
  XmlRpc::XmlRpcValue v = value;  // the accessors are non-const
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      out = static_cast<bool>(v) ? "true" : "false";
      return true;
    case XmlRpc::XmlRpcValue::TypeInt:
      out = std::to_string(static_cast<int>(v));
      return true;
    case XmlRpc::XmlRpcValue::TypeDouble:
      out = formatDouble(static_cast<double>(v));
      return true;
    case XmlRpc::XmlRpcValue::TypeString:
      out = static_cast<std::string>(v);
      return true;
    case XmlRpc::XmlRpcValue::TypeArray: {
      std::string joined, item;
      for (int i = 0; i < v.size(); ++i) {
        if (v[i].getType() == XmlRpc::XmlRpcValue::TypeArray || !paramToString(v[i], item))
          return false;
        if (i) joined += ' ';
        joined += item;
      }
      out = joined;
      return true;
    }
    default:
      return false;
  }
}

std::vector<nscd::SettingOverride> settingOverridesFromParams(const ros::NodeHandle& pnh) {
  std::vector<nscd::SettingOverride> overrides;
  for (const std::string& key : nscd::settingKeys()) {
    XmlRpc::XmlRpcValue value;
    if (!pnh.getParam(key, value)) continue;
    const std::string origin = "parameter " + pnh.resolveName(key);
    std::string text;
    if (!paramToString(value, text))
      throw nscd::SceneError(origin + ": expected a number, boolean, string or list");
    overrides.push_back({key, text, origin});
  }
  return overrides;
}

diagnostic_msgs::DiagnosticStatus toDiagnosticStatus(const DiagnosticsWindow& w,
                                                     const std::string& scene_name) {
  diagnostic_msgs::DiagnosticStatus s;
  s.name = "nscd_sim: simulator";
  s.hardware_id = scene_name;
  if (w.failed) {
    s.level = diagnostic_msgs::DiagnosticStatus::ERROR;
    s.message = "step failed at " + w.failure + "; stepping paused until ~reset";
  } else if (w.unconverged_window > 0) {
    s.level = diagnostic_msgs::DiagnosticStatus::WARN;
    s.message = std::to_string(w.unconverged_window) + " of " + std::to_string(w.window_steps) +
                " steps did not converge";
  } else {
    s.level = diagnostic_msgs::DiagnosticStatus::OK;
    s.message = w.paused ? "paused" : "running";
  }
  const double wall = w.wall_seconds > 0 ? w.wall_seconds : 1.0;
  auto add = [&s](const char* key, const std::string& value) {
    diagnostic_msgs::KeyValue kv;
    kv.key = key;
    kv.value = value;
    s.values.push_back(kv);
  };
  add("sim_time", formatDouble(w.sim_time));
  add("steps", std::to_string(w.steps));
  add("rtf", formatDouble(w.sim_advanced / wall));
  add("steps_per_second", formatDouble(w.window_steps / wall));
  add("publish_rate", formatDouble(w.publishes / wall));
  add("iterations", std::to_string(w.last_iterations));
  add("iterations_mean",
      formatDouble(w.window_steps ? double(w.iterations_sum) / double(w.window_steps) : 0.0));
  add("iterations_max", std::to_string(w.iterations_max));
  add("residual", formatDouble(w.last_residual));
  add("residual_max", formatDouble(w.residual_max));
  add("active_contacts", std::to_string(w.active_contacts));
  add("max_penetration", formatDouble(w.max_penetration));
  add("unconverged_steps", std::to_string(w.unconverged_total));
  add("halved_steps", std::to_string(w.halved_total));
  add("step_failures", std::to_string(w.step_failures));
  add("paused", w.paused ? "true" : "false");
  return s;
}

}  // namespace nscd_node
