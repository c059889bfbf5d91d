// nscd_actuator_markers: interactive markers for the actuators of the scene that
// nscd_sim_node runs (actuator_markers.hpp). Reads the scene as the node does
// (~scene, else robot_description) and its ~actuators, then serves until shutdown.
//
// Exit status: 0 at shutdown; 2 bad input (scene, parameters, an actuator without a
// handle), with one ROS_FATAL line.
#include <memory>
#include <vector>

#include <ros/ros.h>

#include "actuator_markers.hpp"
#include "node_params.hpp"

int main(int argc, char** argv) {
  // This node keeps the wall clock even under /use_sim_time (it stamps nothing): its
  // interactive-marker server refuses a client's feedback within 1 s of the last
  // feedback by another client, measured on ros::Time from 0, and the C-60's sim time
  // stays below 1 s (RViz's drags would all be refused). /clock is remapped away and
  // ros::Time set from the wall clock instead.
  std::vector<char*> args(argv, argv + argc);
  char no_clock[] = "/clock:=~unused_clock";
  args.push_back(no_clock);
  int args_count = static_cast<int>(args.size());
  ros::init(args_count, args.data(), "nscd_actuator_markers");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  const auto set_wall_time = [](const ros::WallTimerEvent&) {
    ros::Time::setNow(ros::Time(ros::WallTime::now().toSec()));
  };
  ros::WallTimer wall_time;
  if (ros::Time::isSimTime()) {
    set_wall_time(ros::WallTimerEvent());
    wall_time = nh.createWallTimer(ros::WallDuration(0.01), set_wall_time);
  }
  nscd::Model model;
  std::unique_ptr<nscd_node::ActuatorMarkers> markers;
  try {
    const nscd_node::ActuatorMarkersOptions options = nscd_node::readActuatorMarkersOptions(pnh);
    model = nscd_node::loadModel(nh, pnh);
    markers = std::make_unique<nscd_node::ActuatorMarkers>(nh, model, options);
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return 2;
  }
  // One thread: the feedback, command and key-figure callbacks and the refresh
  // timer never run at the same time.
  ros::spin();
  return 0;
}
