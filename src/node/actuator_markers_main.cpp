// nscd_actuator_markers: interactive markers for the actuators of the scene that
// nscd_sim_node runs (actuator_markers.hpp). Reads the scene as the node does
// (~scene, else robot_description) and its ~actuators, then serves until shutdown.
//
// Exit status: 0 at shutdown; 2 bad input (scene, parameters, an actuator without a
// handle), with one ROS_FATAL line.
#include <memory>

#include <ros/ros.h>

#include "actuator_markers.hpp"
#include "node_params.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "nscd_actuator_markers");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
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
