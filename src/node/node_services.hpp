// What comes into the node: the actuator command topics (~<actuator>/command),
// the services ~reset, ~pause and ~step, a check for command topics with no
// actuator, and the display parameters re-read while the node runs. Served on
// the spinner thread; each callback takes the session's lock. Each cause of a
// warning is warned about on its own: a non-finite command per actuator, an
// unknown command topic once per name.
#pragma once

#include <cstdint>
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

// One ~step call takes at most this many steps (the Step panel's largest count):
// they are taken on the callback thread under the session's lock, so nothing else
// is served meanwhile. A larger count is refused.
constexpr uint32_t kMaxStepsPerCall = 100000;
// How many unknown command topics are named in warnings (once each); past them one
// warning says that more are not named, and the node remembers no more names.
constexpr size_t kMaxUnknownTopicsNamed = 32;

// The refusal of a ~step count above kMaxStepsPerCall (its response message and
// warning), or "" when the count is served.
std::string stepCountRefusal(uint32_t count);

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
  std::set<std::string> unknown_topics_warned_;  // at most kMaxUnknownTopicsNamed
  bool unknown_topics_overflowed_ = false;
  std::string display_error_;  // the last display-parameter warning (timer thread)
  std::vector<ros::Subscriber> command_subs_;
  ros::ServiceServer reset_srv_, pause_srv_, step_srv_;
  ros::WallTimer topic_check_, display_check_;
  std::vector<WallThrottle> command_throttles_;  // one per actuator
  WallThrottle step_refusal_throttle_;
};

}  // namespace nscd_node
