// nscd_sim_node: the ROS 1 front end of the engine. It owns one nscd::Simulator,
// steps it at ~real_time_factor and publishes tf, contacts, markers, /clock and
// /diagnostics at ~publish_rate. Nothing physical is decided here.
//
// Threads: the main thread runs the stepping/publishing loop; one AsyncSpinner
// thread serves topics and services. `mutex_` guards the simulator and the
// counters; it is taken per step, so a callback waits at most one step.
//
// Exit status: 0 at shutdown; 2 bad input (scene or parameters), with one
// ROS_FATAL line naming the file and line.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/master.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <std_msgs/Float64.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "contact_markers.hpp"
#include "nscd_sim/ContactArray.h"
#include "nscd_sim/KeyFigures.h"
#include "nscd_sim/Step.h"
#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "ros_conversions.hpp"

namespace nscd_node {
namespace {

using SteadyClock = std::chrono::steady_clock;

double seconds(SteadyClock::duration d) { return std::chrono::duration<double>(d).count(); }
SteadyClock::duration wallDuration(double s) {
  return std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(s));
}

// At most one message per period of wall time. (ROS_*_THROTTLE follows ros::Time,
// which stands still while a paused simulation drives /clock.)
class WallThrottle {
 public:
  bool ready(double period) {
    const auto now = SteadyClock::now();
    if (fired_ && seconds(now - last_) < period) return false;
    fired_ = true;
    last_ = now;
    return true;
  }

 private:
  bool fired_ = false;
  SteadyClock::time_point last_;
};

// Node parameters other than the simulation settings.
struct NodeOptions {
  double real_time_factor = 1.0;  // 0 = as fast as possible
  double publish_rate = 30.0;     // Hz
  double diagnostics_rate = 1.0;  // Hz
  bool start_paused = false;
  bool use_sim_time = false;
  MarkerStyle markers;
  std::vector<std::string> schedules;  // "NAME=t0:v0,t1:v1,..." as for nscd_run --command
};

const std::vector<std::string>& nodeParamKeys() {
  static const std::vector<std::string> keys = {
      "scene", "real_time_factor", "publish_rate", "diagnostics_rate", "start_paused",
      "force_scale", "marker_size", "ecc_scale", "schedule"};
  return keys;
}

// A finite number parameter, > 0 if `positive` else >= 0 (int, double or numeric
// string); `fallback` when absent. Throws nscd::SceneError.
double numberParam(const ros::NodeHandle& pnh, const std::string& key, double fallback,
                   bool positive) {
  XmlRpc::XmlRpcValue v;
  if (!pnh.getParam(key, v)) return fallback;
  std::string text;
  char* end = nullptr;
  double x = NAN;
  if (paramToString(v, text) && v.getType() != XmlRpc::XmlRpcValue::TypeArray &&
      v.getType() != XmlRpc::XmlRpcValue::TypeBoolean && !text.empty())
    x = std::strtod(text.c_str(), &end);
  const bool ok = end && *end == '\0' && std::isfinite(x) && (positive ? x > 0 : x >= 0);
  if (!ok)
    throw nscd::SceneError("parameter " + pnh.resolveName(key) + ": expected a " +
                           (positive ? "positive" : "non-negative") + " number");
  return x;
}

NodeOptions readNodeOptions(const ros::NodeHandle& pnh) {
  NodeOptions o;
  o.real_time_factor = numberParam(pnh, "real_time_factor", o.real_time_factor, false);
  o.publish_rate = numberParam(pnh, "publish_rate", o.publish_rate, true);
  o.diagnostics_rate = numberParam(pnh, "diagnostics_rate", o.diagnostics_rate, true);
  o.markers.force_scale = numberParam(pnh, "force_scale", o.markers.force_scale, false);
  o.markers.size = numberParam(pnh, "marker_size", o.markers.size, true);
  o.markers.ecc_scale = numberParam(pnh, "ecc_scale", o.markers.ecc_scale, false);
  pnh.param("start_paused", o.start_paused, o.start_paused);
  ros::param::param("/use_sim_time", o.use_sim_time, false);
  XmlRpc::XmlRpcValue v;
  if (pnh.getParam("schedule", v)) {
    const std::string where = "parameter " + pnh.resolveName("schedule");
    if (v.getType() == XmlRpc::XmlRpcValue::TypeString) {
      o.schedules.push_back(static_cast<std::string>(v));
    } else if (v.getType() == XmlRpc::XmlRpcValue::TypeArray) {
      for (int i = 0; i < v.size(); ++i) {
        if (v[i].getType() != XmlRpc::XmlRpcValue::TypeString)
          throw nscd::SceneError(where + ": expected strings \"NAME=t0:v0,t1:v1,...\"");
        o.schedules.push_back(static_cast<std::string>(v[i]));
      }
    } else {
      throw nscd::SceneError(where + ": expected a string or a list of strings " +
                             "\"NAME=t0:v0,t1:v1,...\"");
    }
  }
  return o;
}

// An actuator command schedule the node follows until a topic command takes over.
struct ScheduledCommand {
  int actuator = -1;
  nscd::CommandSchedule schedule;
  bool active = true;
};

// Parses ~schedule against the scene's actuators. Throws nscd::SceneError.
std::vector<ScheduledCommand> parseSchedules(const ros::NodeHandle& pnh,
                                             const std::vector<std::string>& texts,
                                             const nscd::Model& model) {
  std::vector<ScheduledCommand> out;
  const std::string where = "parameter " + pnh.resolveName("schedule");
  for (const std::string& text : texts) {
    ScheduledCommand c;
    try {
      c.schedule = nscd::parseCommandSchedule(text);
    } catch (const std::exception& e) {
      throw nscd::SceneError(where + ": " + e.what());
    }
    for (size_t i = 0; i < model.actuators.size(); ++i)
      if (model.actuators[i].name == c.schedule.actuator) c.actuator = static_cast<int>(i);
    if (c.actuator < 0) {
      std::string names;
      for (const nscd::Actuator& a : model.actuators) names += (names.empty() ? "" : ", ") + a.name;
      throw nscd::SceneError(where + ": the scene has no actuator '" + c.schedule.actuator +
                             "' (actuators: " + (names.empty() ? "none" : names) + ")");
    }
    for (const ScheduledCommand& other : out)
      if (other.actuator == c.actuator)
        throw nscd::SceneError(where + ": two schedules for actuator '" + c.schedule.actuator +
                               "'");
    out.push_back(std::move(c));
  }
  return out;
}

// Typos in parameter names would otherwise pass silently.
void warnUnknownParams(const ros::NodeHandle& pnh) {
  std::set<std::string> known(nodeParamKeys().begin(), nodeParamKeys().end());
  known.insert(nscd::settingKeys().begin(), nscd::settingKeys().end());
  std::vector<std::string> names;
  if (!ros::param::getParamNames(names)) return;
  const std::string prefix = pnh.getNamespace() + "/";
  for (const std::string& n : names) {
    if (n.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string key = n.substr(prefix.size());
    if (known.count(key.substr(0, key.find('/')))) continue;
    std::string node_keys;
    for (const std::string& k : nodeParamKeys()) node_keys += (node_keys.empty() ? "" : ", ") + k;
    ROS_WARN("unknown parameter %s ignored (known: the simulation settings and %s)", n.c_str(),
             node_keys.c_str());
  }
}

// ~scene (a file) if set, else robot_description. Throws nscd::SceneError.
nscd::Model loadModel(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) {
  const std::vector<nscd::SettingOverride> overrides = settingOverridesFromParams(pnh);
  XmlRpc::XmlRpcValue scene;
  if (pnh.getParam("scene", scene)) {
    if (scene.getType() != XmlRpc::XmlRpcValue::TypeString)
      throw nscd::SceneError("parameter " + pnh.resolveName("scene") +
                             ": expected a string (the scene file's path), got " +
                             paramTypeName(scene));
    const std::string path = static_cast<std::string>(scene);
    if (!path.empty()) return nscd::loadScene(path, overrides);
  }
  std::string xml;
  if (nh.getParam("robot_description", xml) && !xml.empty())
    return nscd::loadSceneFromString(xml, nh.resolveName("robot_description"), overrides);
  throw nscd::SceneError(pnh.resolveName("scene") + ": no scene: set ~scene to a file or " +
                         nh.resolveName("robot_description") + " to the URDF text");
}

class SimNode {
 public:
  SimNode(ros::NodeHandle& nh, ros::NodeHandle& pnh, std::unique_ptr<nscd::Simulator> sim,
          const NodeOptions& options, std::vector<ScheduledCommand> schedules)
      : nh_(nh), pnh_(pnh), sim_(std::move(sim)), opt_(options),
        schedules_(std::move(schedules)) {
    const nscd::Model& model = sim_->model();
    scene_name_ = model.source_file;
    opt_.markers.frame = model.world_frame;
    paused_ = opt_.start_paused;
    updateRunning();
    restartSchedules();

    for (size_t i = 0; i < model.links.size(); ++i) {
      if (model.links[i].name == model.world_frame) continue;
      tf_links_.push_back(static_cast<int>(i));
      geometry_msgs::TransformStamped t;
      t.header.frame_id = model.world_frame;
      t.child_frame_id = model.links[i].name;
      tf_msg_.transforms.push_back(t);
    }
    for (size_t i = 0; i < model.clearance_joints.size(); ++i)
      eccentricity_.push_back(eccentricityView(*sim_, static_cast<int>(i)));

    // tf2_ros::TransformBroadcaster without its publisher hidden: a new /tf
    // subscriber gets the last transforms at once (see onTfSubscriber).
    tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>(
        "/tf", 100, [this](const ros::SingleSubscriberPublisher& p) { onTfSubscriber(p); });
    contacts_pub_ = pnh_.advertise<nscd_sim::ContactArray>("contacts", 2);
    key_figures_pub_ = pnh_.advertise<nscd_sim::KeyFigures>("key_figures", 10);
    for (const nscd::Actuator& a : model.actuators) {
      key_figures_msg_.names.push_back(a.name + ".cmd");
      key_figures_msg_.names.push_back(a.name + ".effort");
    }
    key_figures_msg_.values.resize(key_figures_msg_.names.size());
    markers_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("contact_markers", 2);
    diagnostics_pub_ = nh_.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 2);
    if (opt_.use_sim_time) clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 2);

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

    reset_srv_ = pnh_.advertiseService("reset", &SimNode::onReset, this);
    pause_srv_ = pnh_.advertiseService("pause", &SimNode::onPause, this);
    step_srv_ = pnh_.advertiseService("step", &SimNode::onStep, this);
    topic_check_ = nh_.createWallTimer(ros::WallDuration(2.0), &SimNode::checkCommandTopics, this);

    ROS_INFO("nscd_sim_node: %s: %zu bodies, %zu links, %zu actuators, dt=%g s, "
             "real_time_factor=%g, publish_rate=%g Hz%s",
             scene_name_.c_str(), model.bodies.size(), model.links.size(),
             model.actuators.size(), model.settings.dt, opt_.real_time_factor,
             opt_.publish_rate, paused_ ? ", paused" : "");
    for (const ScheduledCommand& c : schedules_)
      ROS_INFO("nscd_sim_node: actuator '%s' follows a schedule of %zu points until a command "
               "arrives on %s",
               c.schedule.actuator.c_str(), c.schedule.points.size(),
               pnh_.resolveName(c.schedule.actuator + "/command").c_str());
  }

  // The stepping and publishing loop; returns when ROS shuts down.
  void run() {
    const auto pub_period = wallDuration(1.0 / opt_.publish_rate);
    const auto diag_period = wallDuration(1.0 / opt_.diagnostics_rate);
    const double dt = sim_->model().settings.dt;
    auto next_pub = SteadyClock::now();
    auto next_diag = next_pub + diag_period;
    window_start_ = next_pub;
    reanchor();

    while (ros::ok()) {
      if (reanchor_requested_.exchange(false)) reanchor();
      if (running_) {
        if (opt_.real_time_factor > 0) {
          // Step up to where the wall clock says sim time should be, in batches that
          // end at the next publication; drop a backlog the engine cannot catch up.
          const double target =
              anchor_sim_ + opt_.real_time_factor * seconds(SteadyClock::now() - anchor_wall_);
          while (SteadyClock::now() < next_pub && stepOnce(target - 0.5 * dt)) {
          }
          if ((target - simTime()) / opt_.real_time_factor > 0.25) reanchor();
        } else {
          while (SteadyClock::now() < next_pub && stepOnce(INFINITY)) {
          }
        }
      }

      auto now = SteadyClock::now();
      const bool requested = publish_requested_.exchange(false);
      if (now >= next_pub || requested) {
        publishState();
        if (now >= next_pub) {
          next_pub += pub_period;
          if (next_pub <= now) next_pub = now + pub_period;
        }
      }
      if (now >= next_diag || diagnostics_requested_.exchange(false)) {
        publishDiagnostics(now);
        if (now >= next_diag) next_diag = now + diag_period;
      }

      // Sleep only when no step is due: until the next step, publication or
      // diagnostics, and at most 5 ms (pause and reset requests set flags).
      now = SteadyClock::now();
      auto wake = std::min({next_pub, next_diag, now + std::chrono::milliseconds(5)});
      if (running_) {
        if (opt_.real_time_factor == 0) continue;
        const double ahead = simTime() + 0.5 * dt - anchor_sim_;  // sim s past the anchor
        const auto next_step = anchor_wall_ + wallDuration(ahead / opt_.real_time_factor);
        if (next_step <= now) continue;
        wake = std::min(wake, next_step);
      }
      std::this_thread::sleep_until(wake);
    }
  }

 private:
  double simTime() {
    std::lock_guard<std::mutex> lock(mutex_);
    return sim_->state().t;
  }

  void reanchor() {
    anchor_wall_ = SteadyClock::now();
    anchor_sim_ = simTime();
  }

  // Callbacks lock through this: the stepping loop, which retakes mutex_ after
  // every step, lets a waiting callback in first (std::mutex is not fair).
  std::unique_lock<std::mutex> callbackLock() {
    ++callbacks_waiting_;
    std::unique_lock<std::mutex> lock(mutex_);
    --callbacks_waiting_;
    return lock;
  }

  // One step if running and sim time is before `until`; false otherwise.
  bool stepOnce(double until) {
    while (callbacks_waiting_ > 0) std::this_thread::yield();
    std::lock_guard<std::mutex> lock(mutex_);
    if (!running_ || sim_->state().t >= until) return false;
    stepLocked();
    return running_;
  }

  // Requires mutex_. Schedules start again from their first value (sim time 0).
  void restartSchedules() {
    for (ScheduledCommand& c : schedules_) {
      c.active = true;
      sim_->setCommand(c.actuator, c.schedule.value(sim_->state().t));
    }
  }

  // Requires mutex_.
  void stepLocked() {
    const double t0 = sim_->state().t;
    // As nscd_run: the command at the end of the step.
    for (const ScheduledCommand& c : schedules_)
      if (c.active) sim_->setCommand(c.actuator, c.schedule.value(t0 + sim_->model().settings.dt));
    const nscd::StepStatus status = sim_->step();
    const nscd::StepStats& st = sim_->stats();
    ++steps_;
    ++window_.window_steps;
    window_.sim_advanced += sim_->model().settings.dt;
    window_.iterations_sum += st.iterations;
    window_.iterations_max = std::max(window_.iterations_max, st.iterations);
    window_.residual_max = std::max(window_.residual_max, st.residual);
    if (status == nscd::StepStatus::NotConverged) {
      ++window_.unconverged_total;
      ++window_.unconverged_window;
      if (unconverged_throttle_.ready(10.0))
        ROS_WARN("nscd_sim_node: step at t=%.9g s did not converge (%d iterations, residual "
                 "%.3g); continuing (%llu such steps so far)",
                 t0, st.iterations, st.residual, window_.unconverged_total);
    } else if (status == nscd::StepStatus::NonFinite) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "t=%.9g s: non-finite state after the step (solver: %d iterations, "
                    "residual %.3g)",
                    t0, st.iterations, st.residual);
      failure_ = buf;
      failed_ = true;
      running_ = false;
      ++window_.step_failures;
      ROS_ERROR("nscd_sim_node: step failed at %s; stepping paused until ~reset", buf);
      diagnostics_requested_ = true;
    }
  }

  void updateRunning() { running_ = !paused_ && !failed_; }

  void onCommand(int actuator, double value) {
    const std::string& name = sim_->model().actuators[actuator].name;
    bool accepted = false;
    if (std::isfinite(value)) {
      const auto lock = callbackLock();
      accepted = sim_->setCommand(actuator, value);
      if (accepted) publish_requested_ = true;  // ~key_figures shows the new command
      for (ScheduledCommand& c : schedules_)
        if (accepted && c.actuator == actuator && c.active) {
          c.active = false;
          ROS_INFO("nscd_sim_node: %s/command takes over from the schedule of '%s' (until ~reset)",
                   pnh_.resolveName(name).c_str(), name.c_str());
        }
    }
    if (!accepted && command_throttle_.ready(1.0))
      ROS_WARN("nscd_sim_node: ignored command %g on %s/command (not a finite number)", value,
               pnh_.resolveName(name).c_str());
  }

  bool onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
    {
      const auto lock = callbackLock();
      sim_->reset();
      restartSchedules();
      steps_ = 0;
      window_.unconverged_total = 0;
      window_.step_failures = 0;
      failed_ = false;
      failure_.clear();
      updateRunning();
    }
    reanchor_requested_ = true;
    publish_requested_ = true;
    diagnostics_requested_ = true;
    ROS_INFO("nscd_sim_node: reset to the initial state");
    return true;
  }

  bool onPause(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) {
    const auto lock = callbackLock();
    paused_ = req.data;
    updateRunning();
    reanchor_requested_ = true;
    diagnostics_requested_ = true;
    char buf[120];
    std::snprintf(buf, sizeof buf, "%s at t=%.9g s", paused_ ? "paused" : "running",
                  sim_->state().t);
    res.success = !failed_ || paused_;
    res.message = failed_ ? "step failed at " + failure_ + "; call ~reset" : std::string(buf);
    return true;
  }

  bool onStep(nscd_sim::Step::Request& req, nscd_sim::Step::Response& res) {
    const uint32_t count = std::max<uint32_t>(1, req.count);
    {
      const auto lock = callbackLock();
      while (res.steps_taken < count && !failed_) {
        stepLocked();
        ++res.steps_taken;
      }
      res.sim_time = sim_->state().t;
      res.success = !failed_;
      res.message = failed_ ? "step failed at " + failure_ + "; call ~reset" : "ok";
    }
    reanchor_requested_ = true;
    publish_requested_ = true;
    return true;
  }

  // Warns about <node>/X/command topics with no actuator X (a typo goes nowhere).
  void checkCommandTopics(const ros::WallTimerEvent&) {
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
      if (!actuator_names_.count(name) && unknown_topic_throttle_.ready(10.0))
        ROS_WARN("nscd_sim_node: %s is published but the scene has no actuator '%s'", n.c_str(),
                 name.c_str());
    }
  }

  // A listener that connects while a paused sim-time node sends no tf (e.g. RViz
  // started after the pause) would see no links: send it the last transforms.
  void onTfSubscriber(const ros::SingleSubscriberPublisher& pub) {
    tf2_msgs::TFMessage msg;
    {
      const auto lock = callbackLock();
      if (!have_tf_stamp_) return;
      msg = tf_msg_;
    }
    pub.publish(msg);
  }

  ros::Time stampFor(double sim_t) const {
    return opt_.use_sim_time ? ros::Time(sim_t) : ros::Time::now();
  }

  // Copies what is published out of the simulator under the lock, sends it after.
  void publishState() {
    const bool want_contacts = contacts_pub_.getNumSubscribers() > 0;
    const bool want_markers = markers_pub_.getNumSubscribers() > 0;
    const bool want_key_figures = key_figures_pub_.getNumSubscribers() > 0;
    double t;
    bool publish_tf;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (failed_) return;  // the state may hold NaN: keep the last good picture
      const nscd::Model& model = sim_->model();
      t = sim_->state().t;
      const ros::Time stamp = stampFor(t);
      // With sim time, a repeated stamp (paused) would make tf listeners complain
      // (TF_REPEATED_DATA); late subscribers get the transforms from onTfSubscriber.
      publish_tf = !(opt_.use_sim_time && stamp == last_tf_stamp_ && have_tf_stamp_);
      if (publish_tf) {
        for (size_t i = 0; i < tf_links_.size(); ++i) {
          tf_msg_.transforms[i].header.stamp = stamp;
          tf_msg_.transforms[i].transform = toTransform(sim_->linkPose(tf_links_[i]));
        }
        last_tf_stamp_ = stamp;
        have_tf_stamp_ = true;
      }
      if (want_contacts) {
        const std::vector<nscd::ContactReport>& reports = sim_->contacts();
        contacts_msg_.header.stamp = stamp;
        contacts_msg_.header.frame_id = model.world_frame;
        contacts_msg_.sim_time = t;
        contacts_msg_.steps = steps_;
        contacts_msg_.contacts.resize(reports.size());
        for (size_t i = 0; i < reports.size(); ++i)
          toContactMsg(model, reports[i], contacts_msg_.contacts[i]);
      }
      if (want_key_figures) {
        key_figures_msg_.header.stamp = stamp;
        key_figures_msg_.sim_time = t;
        key_figures_msg_.steps = steps_;
        for (size_t i = 0; i < model.actuators.size(); ++i) {
          key_figures_msg_.values[2 * i] = sim_->command(static_cast<int>(i));
          key_figures_msg_.values[2 * i + 1] = sim_->actuatorEffort(static_cast<int>(i));
        }
      }
      if (want_markers) {
        for (size_t i = 0; i < eccentricity_.size(); ++i)
          eccentricity_[i] = eccentricityView(*sim_, static_cast<int>(i));
        buildContactMarkers(sim_->contacts(), eccentricity_, opt_.markers, stamp, markers_msg_);
      }
    }
    if (publish_tf) {
      tf_pub_.publish(tf_msg_);
      ++window_publishes_;
    }
    if (want_contacts) contacts_pub_.publish(contacts_msg_);
    if (want_key_figures) key_figures_pub_.publish(key_figures_msg_);
    if (want_markers) markers_pub_.publish(markers_msg_);
    if (opt_.use_sim_time) {
      rosgraph_msgs::Clock clock;
      clock.clock = ros::Time(t);
      clock_pub_.publish(clock);
    }
  }

  void publishDiagnostics(SteadyClock::time_point now) {
    diagnostic_msgs::DiagnosticArray msg;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      window_.wall_seconds = seconds(now - window_start_);
      window_.publishes = window_publishes_;
      window_.sim_time = sim_->state().t;
      window_.steps = steps_;
      window_.last_iterations = sim_->stats().iterations;
      window_.last_residual = sim_->stats().residual;
      window_.active_contacts = sim_->stats().active_contacts;
      window_.max_penetration = sim_->stats().max_penetration;
      window_.paused = paused_;
      window_.failed = failed_;
      window_.failure = failure_;
      msg.header.stamp = stampFor(window_.sim_time);
      msg.status.push_back(toDiagnosticStatus(window_, scene_name_));
      // Totals carry over; the rest starts a new window.
      const unsigned long long unconverged = window_.unconverged_total;
      const unsigned long long failures = window_.step_failures;
      window_ = DiagnosticsWindow{};
      window_.unconverged_total = unconverged;
      window_.step_failures = failures;
      window_publishes_ = 0;
      window_start_ = now;
    }
    diagnostics_pub_.publish(msg);
  }

  ros::NodeHandle& nh_;
  ros::NodeHandle& pnh_;
  std::unique_ptr<nscd::Simulator> sim_;
  NodeOptions opt_;
  std::vector<ScheduledCommand> schedules_;  // guarded by mutex_
  std::string scene_name_;

  std::mutex mutex_;  // guards sim_, steps_, window_, failure_, paused_/failed_ writes
  std::atomic<bool> paused_{false};
  std::atomic<bool> failed_{false};
  std::atomic<bool> running_{true};
  std::atomic<bool> publish_requested_{false};
  std::atomic<bool> diagnostics_requested_{false};
  std::atomic<bool> reanchor_requested_{false};
  std::atomic<int> callbacks_waiting_{0};
  std::string failure_;
  unsigned long long steps_ = 0;
  DiagnosticsWindow window_;
  int window_publishes_ = 0;  // loop thread only
  SteadyClock::time_point window_start_;

  // Pacing (loop thread only): sim time anchor_sim_ was reached at anchor_wall_.
  SteadyClock::time_point anchor_wall_;
  double anchor_sim_ = 0;

  std::vector<int> tf_links_;
  tf2_msgs::TFMessage tf_msg_;  // written by the loop thread under mutex_
  ros::Time last_tf_stamp_;
  bool have_tf_stamp_ = false;
  nscd_sim::ContactArray contacts_msg_;
  nscd_sim::KeyFigures key_figures_msg_;  // names fixed at start, values per publication
  visualization_msgs::MarkerArray markers_msg_;
  std::vector<EccentricityView> eccentricity_;

  ros::Publisher tf_pub_, contacts_pub_, key_figures_pub_, markers_pub_, diagnostics_pub_, clock_pub_;
  std::vector<ros::Subscriber> command_subs_;
  std::set<std::string> actuator_names_;
  ros::ServiceServer reset_srv_, pause_srv_, step_srv_;
  ros::WallTimer topic_check_;
  WallThrottle command_throttle_, unknown_topic_throttle_, unconverged_throttle_;
};

}  // namespace
}  // namespace nscd_node

int main(int argc, char** argv) {
  ros::init(argc, argv, "nscd_sim_node");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");

  std::unique_ptr<nscd::Simulator> sim;
  nscd_node::NodeOptions options;
  std::vector<nscd_node::ScheduledCommand> schedules;
  try {
    options = nscd_node::readNodeOptions(pnh);
    nscd::Model model = nscd_node::loadModel(nh, pnh);
    // The engine's assembly errors already name the scene file.
    sim = std::make_unique<nscd::Simulator>(std::move(model));
    schedules = nscd_node::parseSchedules(pnh, options.schedules, sim->model());
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return 2;
  }
  nscd_node::warnUnknownParams(pnh);

  nscd_node::SimNode node(nh, pnh, std::move(sim), options, std::move(schedules));
  ros::AsyncSpinner spinner(1);
  spinner.start();
  node.run();
  spinner.stop();
  return 0;
}
