// Engine types <-> ROS messages and parameters. No physics here: only copying
// and renaming, so the node shows exactly what the engine computed.
#pragma once

#include <string>
#include <vector>

#include <diagnostic_msgs/DiagnosticStatus.h>
#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Transform.h>
#include <geometry_msgs/Vector3.h>
#include <ros/node_handle.h>
#include <std_msgs/ColorRGBA.h>

#include "nscd_sim/Contact.h"
#include "nscd_sim/model.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"

namespace nscd_node {

geometry_msgs::Point toPoint(const nscd::Vec3& v);
geometry_msgs::Vector3 toVector3(const nscd::Vec3& v);
geometry_msgs::Quaternion toQuaternion(const nscd::Quat& q);  // as it is (not normalised)
geometry_msgs::Pose toPose(const nscd::Pose& pose);           // as it is (not normalised)
geometry_msgs::Transform toTransform(const nscd::Pose& pose); // the rotation normalised
// A pose from ROS (an interactive marker's feedback): the quaternion normalised, the
// identity if it has no finite length above 0.
nscd::Pose fromPose(const geometry_msgs::Pose& pose);

// A marker colour (components 0..1).
std_msgs::ColorRGBA rgba(float r, float g, float b, float a = 1.0f);

// The stamp of a message about sim time `sim_t`: that time with /use_sim_time,
// else the wall clock's now.
inline ros::Time stampFor(bool use_sim_time, double sim_t) {
  return use_sim_time ? ros::Time(sim_t) : ros::Time::now();
}

// Link (tf frame) name of a body; the world frame for ground.
const std::string& bodyLinkName(const nscd::Model& model, int body);
// The named contact or clearance joint a report belongs to.
const std::string& contactSourceName(const nscd::Model& model, const nscd::ContactReport& c);
void toContactMsg(const nscd::Model& model, const nscd::ContactReport& c, nscd_sim::Contact& out);

// The string form of a parameter value as nscd_run --set would take it
// (lists become space-separated, e.g. gravity: [0, 0, -9.81] -> "0 0 -9.81").
// False if the value has a type no setting can take (struct, binary, ...).
bool paramToString(const XmlRpc::XmlRpcValue& value, std::string& out);

// A parameter value that is an integer or a finite double, as a double; false for
// anything else (a string, a boolean, NaN, +-inf, ...).
bool paramNumber(const XmlRpc::XmlRpcValue& value, double& out);

// "an integer", "a string", ...: a parameter value's type, for error messages.
std::string paramTypeName(const XmlRpc::XmlRpcValue& value);

// Every private parameter whose name is a simulation setting key (nscd::settingKeys()),
// as overrides in key order. Throws nscd::SceneError on a value of unusable type.
std::vector<nscd::SettingOverride> settingOverridesFromParams(const ros::NodeHandle& pnh);

// What one diagnostics period saw (filled by the node, turned into a status here).
struct DiagnosticsWindow {
  double sim_time = 0;
  unsigned long long steps = 0;        // since start or reset
  unsigned long long window_steps = 0;  // in this period
  double wall_seconds = 0;              // length of this period
  double sim_advanced = 0;              // simulated seconds stepped in this period
  int publishes = 0;                    // tf publications in this period
  long long iterations_sum = 0;         // solver iterations summed over the period
  int iterations_max = 0;
  double residual_max = 0;
  int last_iterations = 0;
  double last_residual = 0;
  int active_contacts = 0;              // of the last step
  double max_penetration = 0;           // of the last step
  unsigned long long unconverged_total = 0;
  unsigned long long unconverged_window = 0;
  unsigned long long halved_total = 0;  // steps taken again in halves (max_step_halvings)
  unsigned long long step_failures = 0;
  bool paused = false;
  bool failed = false;
  std::string failure;                  // "t=..: cause" when failed
};

diagnostic_msgs::DiagnosticStatus toDiagnosticStatus(const DiagnosticsWindow& w,
                                                     const std::string& scene_name);

}  // namespace nscd_node
