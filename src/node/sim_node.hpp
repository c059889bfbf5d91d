// The ROS node around one simulator (sim_node.cpp): wires the session (the shared
// simulator), its publishers, its services and its stepping loop.
#pragma once

#include <memory>
#include <vector>

#include <ros/ros.h>

#include "node_params.hpp"
#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/simulator.hpp"

namespace nscd_node {

// Advertises the node's topics and services and runs its stepping and
// publishing loop until ROS shuts down.
void runSimNode(ros::NodeHandle& nh, ros::NodeHandle& pnh, std::unique_ptr<nscd::Simulator> sim,
                const NodeOptions& options, const std::vector<nscd::BoundSchedule>& schedules,
                const std::vector<CommandRateLimit>& rate_limits, const StatusOverlay& overlay);

}  // namespace nscd_node
