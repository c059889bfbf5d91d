// nscd_actuator_markers: interactive markers that let a user drive the scene's
// actuators from RViz. Per configured actuator a marker stands at its handle
// (actuator_handle.hpp): a ring about a revolute joint's axis, arrows along a
// slide's axis. Dragging it publishes the command it asks for on the simulation
// node's ~<actuator>/command topic, clipped to the actuator's range (one warning
// per excursion out of the range). The marker's text shows the command and the
// effort it takes (and chosen key figures) from the node's ~key_figures, while
// dragging too. No physics here: the node simulates, this only translates.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <interactive_markers/interactive_marker_server.h>
#include <ros/ros.h>
#include <std_msgs/Float64.h>
#include <visualization_msgs/InteractiveMarker.h>
#include <visualization_msgs/InteractiveMarkerFeedback.h>

#include "actuator_handle.hpp"
#include "nscd_sim/KeyFigures.h"

namespace nscd_node {

// One actuator's marker, as the parameters give it.
struct ActuatorMarkerConfig {
  std::string actuator;
  CommandRange range;
  double scale = 0;                  // marker size (m); 0: from the scene
  std::vector<std::string> figures;  // key figures shown under the command and effort
  // Where the text's first line is centred, from the marker on the screen (m, right
  // and up); empty: above the marker.
  std::vector<double> text_offset;
};

// The node's parameters (~actuators, ~sim_node, ~text_size). Throws nscd::SceneError.
struct ActuatorMarkersOptions {
  std::string sim_node = "/nscd_sim_node";  // the simulation node: its topics' namespace
  std::vector<ActuatorMarkerConfig> actuators;
  double text_size = 0;  // m; 0: 0.12 of each marker's scale
};
ActuatorMarkersOptions readActuatorMarkersOptions(const ros::NodeHandle& pnh);

class ActuatorMarkers {
 public:
  // Throws nscd::SceneError for an actuator without a handle or a bad figure name.
  ActuatorMarkers(ros::NodeHandle& nh, const nscd::Model& model, const ActuatorMarkersOptions& options);

 private:
  struct Marker {
    ActuatorMarkerConfig config;
    ActuatorHandle handle;
    std::string unit, effort_unit;
    double display = 1;  // the command's display factor (1e3: m shown in mm)
    ros::Publisher command_pub;
    ros::Subscriber command_sub;  // the commands anyone sends (the marker stands there)
    double target = NAN;    // the last command sent on the topic; NaN: none since start or reset
    double applied = NAN;   // A.cmd of ~key_figures: the command the node applies now
    double effort = NAN;    // A.effort
    std::vector<double> figure_values;
    bool dragging = false;
    bool out_of_range = false;  // in an excursion out of the range (warned once)
    std::string shown_text;
    double shown_command = NAN;
  };

  void onFeedback(size_t i, const visualization_msgs::InteractiveMarkerFeedbackConstPtr& f);
  void onCommand(size_t i, const std_msgs::Float64ConstPtr& msg);
  void onKeyFigures(const nscd_sim::KeyFiguresConstPtr& msg);
  // Rebuilds changed markers (text; pose unless dragged) and sends them.
  void refresh(const ros::WallTimerEvent&);
  visualization_msgs::InteractiveMarker build(const Marker& m, double command) const;
  std::string text(const Marker& m) const;
  double shownCommand(const Marker& m) const;

  const nscd::Model& model_;
  double text_size_;
  std::vector<Marker> markers_;
  double last_sim_time_ = -1;
  interactive_markers::InteractiveMarkerServer server_;
  ros::Subscriber figures_sub_;
  ros::WallTimer refresh_timer_;
};

}  // namespace nscd_node
