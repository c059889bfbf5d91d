// The node's parameters: its own (pacing, publishing, markers, schedules) read
// and checked, the scene from ~scene or robot_description, and a warning for
// parameters nobody reads. Each error is one nscd::SceneError line.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <ros/ros.h>

#include "contact_markers.hpp"
#include "run_events.hpp"
#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/model.hpp"

namespace nscd_node {

// Node parameters other than the simulation settings.
struct NodeOptions {
  double real_time_factor = 1.0;  // 0 = as fast as possible
  double publish_rate = 30.0;     // Hz
  double diagnostics_rate = 1.0;  // Hz
  bool start_paused = false;
  bool use_sim_time = false;
  MarkerStyle markers;
  std::vector<std::string> schedules;  // "NAME=t0:v0,t1:v1,..." as for nscd_run --command
  // The status text in the 3D view (~status): key figures to show (default: the
  // actuators' efforts), where (world frame; default above the bodies) and how high.
  std::vector<std::string> overlay_figures;
  bool overlay_figures_set = false;
  std::vector<double> overlay_position;  // empty: default
  double overlay_size = 0;               // 0: default
  std::vector<std::string> events;       // ~events definitions (run_events.hpp)
  // ~command_rate_limit {NAME: RATE}: the fastest a topic command is followed
  // (command units per second of sim time).
  std::vector<std::pair<std::string, double>> command_rate_limits;
};

// The node's own parameter names (the simulation settings come on top).
const std::vector<std::string>& nodeParamKeys();

// Reads and checks the node's own parameters. Throws nscd::SceneError.
NodeOptions readNodeOptions(const ros::NodeHandle& pnh);

// ~scene (a file) if set, else robot_description, with the simulation settings
// among the private parameters as overrides. Throws nscd::SceneError.
nscd::Model loadModel(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);

// The status text's figures (indices into nscd::keyFigureNames), position and
// height for the model: the options' values, checked, or the defaults. Throws
// nscd::SceneError naming an unknown figure.
struct StatusOverlay {
  std::vector<int> figures;
  nscd::Vec3 position = nscd::Vec3::Zero();
  double height = 0.01;
};
StatusOverlay statusOverlay(const ros::NodeHandle& pnh, const NodeOptions& o, const nscd::Model& model);

// The ~events definitions parsed against the model's key figures. A definition
// that cannot be used gets one warning naming it and is left out: the node runs.
EventTracker eventTracker(const ros::NodeHandle& pnh, const NodeOptions& o, const nscd::Model& model);

// The display parameters that can change while the node runs (rosparam set):
// contact_labels, force_scale, ecc_scale. Reads those present into `style`; a bad
// value leaves its field as it was and adds one line to `errors`.
void readDisplayParams(const ros::NodeHandle& pnh, MarkerStyle& style, std::vector<std::string>& errors);

// The ~schedule texts bound to the model's actuators. Throws nscd::SceneError.
std::vector<nscd::BoundSchedule> bindSchedules(const ros::NodeHandle& pnh,
                                               const std::vector<std::string>& texts,
                                               const nscd::Model& model);

// A topic command followed at a bounded rate: each step the actuator's command
// moves towards the last topic command by at most rate * dt. (A command that
// jumps moves a prescribed body by the jump within one step, at jump / dt.)
struct CommandRateLimit {
  int actuator = -1;
  double rate = 0;  // command units per second of sim time, > 0
};

// The ~command_rate_limit entries bound to the model's actuators. Throws
// nscd::SceneError naming an unknown actuator.
std::vector<CommandRateLimit> bindCommandRateLimits(const ros::NodeHandle& pnh, const NodeOptions& o,
                                                    const nscd::Model& model);

// Typos in parameter names would otherwise pass silently: one warning each.
void warnUnknownParams(const ros::NodeHandle& pnh);

}  // namespace nscd_node
