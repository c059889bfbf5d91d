// /diagnostics of the node: per period, the solver statistics of the steps taken,
// the rates reached and the run state (status "nscd_sim: simulator").
#pragma once

#include <string>

#include <ros/ros.h>

#include "sim_session.hpp"
#include "wall_clock.hpp"

namespace nscd_node {

class DiagnosticsPublisher {
 public:
  DiagnosticsPublisher(ros::NodeHandle& nh, SimSession& session, bool use_sim_time);
  // Loop thread: the period started at `start`.
  void start(SteadyClock::time_point start) { window_start_ = start; }
  // Loop thread: ends the period at `now` (`tf_publications` in it) and publishes it.
  void publish(SteadyClock::time_point now, int tf_publications);

 private:
  SimSession& session_;
  const bool use_sim_time_;
  std::string scene_name_;
  SteadyClock::time_point window_start_;
  ros::Publisher pub_;
};

}  // namespace nscd_node
