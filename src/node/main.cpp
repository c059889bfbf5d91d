// nscd_sim_node: the ROS 1 front end of the engine. Reads its parameters and the
// scene, then runs the node (sim_node.cpp) until shutdown.
//
// Exit status: 0 at shutdown; 2 bad input (scene or parameters), with one
// ROS_FATAL line naming the file and line, or the parameter.
#include <memory>
#include <vector>

#include <ros/ros.h>

#include "node_params.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "sim_node.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "nscd_sim_node");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");

  std::unique_ptr<nscd::Simulator> sim;
  nscd_node::NodeOptions options;
  std::vector<nscd::BoundSchedule> schedules;
  std::vector<nscd_node::CommandRateLimit> rate_limits;
  nscd_node::StatusOverlay overlay;
  try {
    options = nscd_node::readNodeOptions(pnh);
    nscd::Model model = nscd_node::loadModel(nh, pnh);
    // The engine's assembly errors already name the scene file.
    sim = std::make_unique<nscd::Simulator>(std::move(model));
    schedules = nscd_node::bindSchedules(pnh, options.schedules, sim->model());
    rate_limits = nscd_node::bindCommandRateLimits(pnh, options, sim->model());
    overlay = nscd_node::statusOverlay(pnh, options, sim->model());
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return 2;
  }
  nscd_node::warnUnknownParams(pnh);
  nscd_node::runSimNode(nh, pnh, std::move(sim), options, schedules, rate_limits, overlay);
  return 0;
}
