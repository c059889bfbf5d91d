// What comes into the node: the actuator command topics (~<actuator>/command),
// the services ~reset, ~pause and ~step, a check for command topics with no
// actuator, and the display parameters re-read while the node runs. Served on
// the spinner thread; each callback takes the session's lock.
#pragma once

#include <set>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>

#include "contact_markers.hpp"
#include "nscd_sim/Step.h"
#include "sim_session.hpp"
#include "wall_clock.hpp"

namespace nscd_node {

class NodeServices {
 public:
  // `style`: the publishers' marker style, guarded by the session's lock.
  NodeServices(ros::NodeHandle& nh, ros::NodeHandle& pnh, SimSession& session, MarkerStyle& style);

 private:
  void onCommand(int actuator, double value);
  bool onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&);
  bool onPause(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res);
  bool onStep(nscd_sim::Step::Request& req, nscd_sim::Step::Response& res);
  void checkCommandTopics(const ros::WallTimerEvent&);
  void refreshDisplay(const ros::WallTimerEvent&);

  ros::NodeHandle& pnh_;
  SimSession& session_;
  MarkerStyle& style_;
  std::set<std::string> actuator_names_;
  std::string display_error_;  // the last display-parameter warning (timer thread)
  std::vector<ros::Subscriber> command_subs_;
  ros::ServiceServer reset_srv_, pause_srv_, step_srv_;
  ros::WallTimer topic_check_, display_check_;
  WallThrottle command_throttle_, unknown_topic_throttle_;
};

}  // namespace nscd_node
