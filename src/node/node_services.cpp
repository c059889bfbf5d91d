// The node's command topics, services and parameter watch (node_services.hpp).
#include "node_services.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <ros/master.h>
#include <std_msgs/Float64.h>

#include "node_params.hpp"

namespace nscd_node {

std::string stepCountRefusal(uint32_t count) {
  if (count <= kMaxStepsPerCall) return "";
  return "~step with count " + std::to_string(count) + " refused: at most " + std::to_string(kMaxStepsPerCall) +
         " steps a call may take (the node serves nothing else while it steps); call again for more";
}

NodeServices::NodeServices(ros::NodeHandle& nh, ros::NodeHandle& pnh, SimSession& session,
                           MarkerStyle& style)
    : pnh_(pnh), session_(session), style_(style) {
  const nscd::Model& model = session_.sim().model();
  command_throttles_.resize(model.actuators.size());
  for (size_t i = 0; i < model.actuators.size(); ++i) {
    const std::string& name = model.actuators[i].name;
    std::string why;
    if (!ros::names::validate(name, why)) {
      ROS_ERROR("actuator '%s' gets no command topic: not a valid ROS name (%s)", name.c_str(),
                why.c_str());
      continue;
    }
    const int index = static_cast<int>(i);
    command_subs_.push_back(pnh_.subscribe<std_msgs::Float64>(
        name + "/command", 1,
        [this, index](const std_msgs::Float64ConstPtr& msg) { onCommand(index, msg->data); }));
    actuator_names_.insert(name);
  }

  reset_srv_ = pnh_.advertiseService("reset", &NodeServices::onReset, this);
  pause_srv_ = pnh_.advertiseService("pause", &NodeServices::onPause, this);
  step_srv_ = pnh_.advertiseService("step", &NodeServices::onStep, this);
  topic_check_ = nh.createWallTimer(ros::WallDuration(2.0), &NodeServices::checkCommandTopics, this);
  display_check_ = nh.createWallTimer(ros::WallDuration(1.0), &NodeServices::refreshDisplay, this);
}

void NodeServices::onCommand(int actuator, double value) {
  const std::string& name = session_.sim().model().actuators[actuator].name;
  bool accepted = false;
  if (std::isfinite(value)) {
    const auto lock = session_.callbackLock();
    const SimSession::CommandResult r = session_.command(actuator, value);
    accepted = r.accepted;
    if (accepted) session_.requests.publish = true;  // ~key_figures shows the new command
    if (r.took_over)
      ROS_INFO("nscd_sim_node: %s/command takes over from the schedule of '%s' (until ~reset)",
               pnh_.resolveName(name).c_str(), name.c_str());
  }
  if (!accepted && command_throttles_[actuator].ready(1.0))
    ROS_WARN("nscd_sim_node: ignored command %g on %s/command (not a finite number)", value,
             pnh_.resolveName(name).c_str());
}

bool NodeServices::onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  {
    const auto lock = session_.callbackLock();
    session_.reset();
  }
  session_.requests.reanchor = true;
  session_.requests.publish = true;
  session_.requests.diagnostics = true;
  ROS_INFO("nscd_sim_node: reset to the initial state");
  return true;
}

bool NodeServices::onPause(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) {
  const auto lock = session_.callbackLock();
  session_.setPaused(req.data);
  session_.requests.reanchor = true;
  session_.requests.diagnostics = true;
  const bool paused = session_.paused(), failed = session_.failed();
  char buf[120];
  std::snprintf(buf, sizeof buf, "%s at t=%.9g s", paused ? "paused" : "running",
                session_.sim().state().t);
  res.success = !failed || paused;
  res.message = failed ? "step failed at " + session_.failure() + "; call ~reset" : std::string(buf);
  return true;
}

bool NodeServices::onStep(nscd_sim::Step::Request& req, nscd_sim::Step::Response& res) {
  const std::string refusal = stepCountRefusal(req.count);
  if (!refusal.empty()) {
    {
      const auto lock = session_.callbackLock();
      res.sim_time = session_.sim().state().t;
    }
    res.success = false;
    res.steps_taken = 0;
    res.message = refusal;
    if (step_refusal_throttle_.ready(10.0)) ROS_WARN("nscd_sim_node: %s", refusal.c_str());
    return true;
  }
  const uint32_t count = std::max<uint32_t>(1, req.count);
  {
    const auto lock = session_.callbackLock();
    while (res.steps_taken < count && !session_.failed()) {
      session_.step();
      ++res.steps_taken;
    }
    res.sim_time = session_.sim().state().t;
    res.success = !session_.failed();
    res.message = session_.failed() ? "step failed at " + session_.failure() + "; call ~reset" : "ok";
  }
  session_.requests.reanchor = true;
  session_.requests.publish = true;
  return true;
}

// Warns about <node>/X/command topics with no actuator X (a typo goes nowhere),
// once per name, naming at most kMaxUnknownTopicsNamed of them.
void NodeServices::checkCommandTopics(const ros::WallTimerEvent&) {
  ros::master::V_TopicInfo topics;
  if (!ros::master::getTopics(topics)) return;
  const std::string prefix = pnh_.getNamespace() + "/";
  const std::string suffix = "/command";
  for (const ros::master::TopicInfo& t : topics) {
    const std::string& n = t.name;
    if (n.size() <= prefix.size() + suffix.size() || n.compare(0, prefix.size(), prefix) ||
        n.compare(n.size() - suffix.size(), suffix.size(), suffix))
      continue;
    const std::string name = n.substr(prefix.size(), n.size() - prefix.size() - suffix.size());
    if (actuator_names_.count(name) || unknown_topics_warned_.count(name)) continue;
    if (unknown_topics_warned_.size() < kMaxUnknownTopicsNamed) {
      unknown_topics_warned_.insert(name);
      ROS_WARN("nscd_sim_node: %s is published but the scene has no actuator '%s'", n.c_str(),
               name.c_str());
    } else if (!unknown_topics_overflowed_) {
      unknown_topics_overflowed_ = true;
      ROS_WARN("nscd_sim_node: %zu command topics without an actuator named so far; more command "
               "topics without an actuator (as %s) are not named",
               kMaxUnknownTopicsNamed, n.c_str());
    }
  }
}

// The display parameters that may change while the node runs (rosparam set).
void NodeServices::refreshDisplay(const ros::WallTimerEvent&) {
  MarkerStyle style;
  {
    const auto lock = session_.callbackLock();
    style = style_;
  }
  std::vector<std::string> errors;
  readDisplayParams(pnh_, style, errors);
  std::string all;
  for (const std::string& e : errors) all += (all.empty() ? "" : "\n") + e;
  if (!all.empty() && all != display_error_) ROS_WARN("nscd_sim_node: %s", all.c_str());
  display_error_ = all;
  const auto lock = session_.callbackLock();
  if (style.labels != style_.labels || style.force_scale != style_.force_scale ||
      style.ecc_scale != style_.ecc_scale) {
    ROS_INFO("nscd_sim_node: contact_labels %s, force_scale %g m/N, ecc_scale %g",
             style.labels ? "on" : "off", style.force_scale, style.ecc_scale);
    style_ = style;
    session_.requests.publish = true;
  }
}

}  // namespace nscd_node
