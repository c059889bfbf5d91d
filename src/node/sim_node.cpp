// The node proper: owns one nscd::Simulator, steps it at the real-time factor and
// publishes tf, contacts, key figures, markers, /clock and /diagnostics at
// ~publish_rate; serves ~reset, ~pause, ~step and the actuator command topics.
// Nothing physical is decided here.
//
// Threads: the caller's thread runs the stepping/publishing loop; one
// AsyncSpinner thread serves topics and services. `mutex_` guards the simulator
// and the counters; it is taken per step, so a callback waits at most one step.
#include "sim_node.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/master.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "contact_markers.hpp"
#include "nscd_sim/ContactArray.h"
#include "nscd_sim/KeyFigures.h"
#include "nscd_sim/key_figures.hpp"
#include "nscd_sim/Step.h"
#include "real_time_pacer.hpp"
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

class SimNode {
 public:
  SimNode(ros::NodeHandle& nh, ros::NodeHandle& pnh, std::unique_ptr<nscd::Simulator> sim,
          const NodeOptions& options, const std::vector<nscd::BoundSchedule>& schedules,
          const StatusOverlay& overlay)
      : nh_(nh), pnh_(pnh), sim_(std::move(sim)), opt_(options),
        pacer_(options.real_time_factor, sim_->model().settings.dt), overlay_(overlay),
        events_(eventTracker(pnh, options, sim_->model())) {
    for (const nscd::BoundSchedule& b : schedules) schedules_.push_back({b.actuator, b.schedule, true});
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
    for (const nscd::ContactPair& c : model.contacts) marker_names_.contacts.push_back(c.name);
    for (const nscd::ClearanceJoint& j : model.clearance_joints) marker_names_.clearance.push_back(j.name);
    for (const EventDefinition& d : events_.definitions())
      ROS_INFO("nscd_sim_node: event '%s' shown when its condition holds (%zu figure%s %s %g)",
               d.label.c_str(), d.figures.size(), d.figures.size() == 1 ? "" : "s",
               d.greater ? ">" : "<", d.threshold);

    // tf2_ros::TransformBroadcaster without its publisher hidden: a new /tf
    // subscriber gets the last transforms at once (see onTfSubscriber).
    tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>(
        "/tf", 100, [this](const ros::SingleSubscriberPublisher& p) { onTfSubscriber(p); });
    contacts_pub_ = pnh_.advertise<nscd_sim::ContactArray>("contacts", 2);
    key_figures_pub_ = pnh_.advertise<nscd_sim::KeyFigures>("key_figures", 10);
    key_figures_msg_.names = nscd::keyFigureNames(model);
    key_figures_msg_.values.reserve(key_figures_msg_.names.size());
    status_pub_ = pnh_.advertise<visualization_msgs::Marker>("status", 2);
    for (int f : overlay_.figures) status_names_.push_back(key_figures_msg_.names[f]);
    status_values_.resize(status_names_.size());
    joint_states_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_states", 10);
    for (size_t j = 0; j < model.joints.size(); ++j) {
      if (model.joints[j].type == nscd::JointType::Fixed) continue;
      joint_state_index_.push_back(static_cast<int>(j));
      joint_states_msg_.name.push_back(model.joints[j].name);
    }
    joint_states_msg_.position.resize(joint_state_index_.size());
    joint_states_msg_.velocity.resize(joint_state_index_.size());
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
    display_check_ = nh_.createWallTimer(ros::WallDuration(1.0), &SimNode::refreshDisplay, this);

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
    auto next_pub = SteadyClock::now();
    auto next_diag = next_pub + diag_period;
    window_start_ = next_pub;
    reanchor();

    while (ros::ok()) {
      if (reanchor_requested_.exchange(false)) reanchor();
      if (running_) {
        // Step up to where the wall clock says sim time should be, in batches that
        // end at the next publication; drop a backlog the engine cannot catch up.
        const auto start = SteadyClock::now();
        const double limit = pacer_.stepLimit(start);
        while (SteadyClock::now() < next_pub && stepOnce(limit)) {
        }
        if (pacer_.behind(start, simTime())) reanchor();
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
        if (!pacer_.paced()) continue;
        const auto next_step = pacer_.nextStepDue(now, simTime());
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

  void reanchor() { pacer_.reanchor(SteadyClock::now(), simTime()); }

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
    // As nscd_run: the command at the end of the step (planStep: t0 + dt, or the
    // end of the step the adaptive step control plans).
    const double t_end = sim_->planStep(INFINITY);
    for (const ScheduledCommand& c : schedules_)
      if (c.active) sim_->setCommand(c.actuator, c.schedule.value(t_end));
    const nscd::StepStatus status = sim_->step();
    const nscd::StepStats& st = sim_->stats();
    ++steps_;
    ++window_.window_steps;
    window_.sim_advanced += st.h;
    window_.iterations_sum += st.iterations;
    window_.iterations_max = std::max(window_.iterations_max, st.iterations);
    window_.residual_max = std::max(window_.residual_max, st.residual);
    window_.halved_total += st.substeps > 1;
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
      return;
    }
    if (!events_.empty())
      for (int e : events_.check(*sim_))
        ROS_INFO("nscd_sim_node: event '%s' at t=%.6f ms (step %llu)",
                 events_.definitions()[e].label.c_str(), 1e3 * sim_->state().t, steps_);
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
      events_.reset();
      restartSchedules();
      steps_ = 0;
      window_.unconverged_total = 0;
      window_.halved_total = 0;
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

  // The display parameters that may change while the node runs (rosparam set).
  void refreshDisplay(const ros::WallTimerEvent&) {
    MarkerStyle style;
    {
      const auto lock = callbackLock();
      style = opt_.markers;
    }
    std::vector<std::string> errors;
    readDisplayParams(pnh_, style, errors);
    std::string all;
    for (const std::string& e : errors) all += (all.empty() ? "" : "\n") + e;
    if (!all.empty() && all != display_error_) ROS_WARN("nscd_sim_node: %s", all.c_str());
    display_error_ = all;
    const auto lock = callbackLock();
    if (style.labels != opt_.markers.labels || style.force_scale != opt_.markers.force_scale ||
        style.ecc_scale != opt_.markers.ecc_scale) {
      ROS_INFO("nscd_sim_node: contact_labels %s, force_scale %g m/N, ecc_scale %g",
               style.labels ? "on" : "off", style.force_scale, style.ecc_scale);
      opt_.markers = style;
      publish_requested_ = true;
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
    const bool want_joint_states = joint_states_pub_.getNumSubscribers() > 0;
    const bool want_status = status_pub_.getNumSubscribers() > 0;
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
        const std::vector<nscd::ContactReport>& reports = sim_->contactPoints();
        contacts_msg_.header.stamp = stamp;
        contacts_msg_.header.frame_id = model.world_frame;
        contacts_msg_.sim_time = t;
        contacts_msg_.steps = steps_;
        contacts_msg_.contacts.resize(reports.size());
        for (size_t i = 0; i < reports.size(); ++i)
          toContactMsg(model, reports[i], contacts_msg_.contacts[i]);
      }
      if (want_joint_states) {
        joint_states_msg_.header.stamp = stamp;
        for (size_t k = 0; k < joint_state_index_.size(); ++k) {
          joint_states_msg_.position[k] = sim_->jointPosition(joint_state_index_[k]);
          joint_states_msg_.velocity[k] = sim_->jointVelocity(joint_state_index_[k]);
        }
      }
      if (want_key_figures || want_status) nscd::keyFigureValues(*sim_, figure_values_);
      if (want_status) {
        // rtf over the last publication period (sim time per wall time).
        const auto now = SteadyClock::now();
        const double wall = seconds(now - status_wall_);
        if (wall > 0 && status_have_) status_rtf_ = (t - status_sim_) / wall;
        status_wall_ = now;
        status_sim_ = t;
        status_have_ = true;
        for (size_t i = 0; i < overlay_.figures.size(); ++i) status_values_[i] = figure_values_[overlay_.figures[i]];
        StatusText text;
        text.position = overlay_.position;
        text.height = overlay_.height;
        buildStatusMarker(t, status_rtf_, opt_.markers, status_names_, status_values_, text, stamp, status_msg_);
      }
      if (want_key_figures) {
        key_figures_msg_.header.stamp = stamp;
        key_figures_msg_.sim_time = t;
        key_figures_msg_.steps = steps_;
        key_figures_msg_.values = figure_values_;
      }
      if (want_markers) {
        for (size_t i = 0; i < eccentricity_.size(); ++i)
          eccentricity_[i] = eccentricityView(*sim_, static_cast<int>(i));
        buildContactMarkers(sim_->contactPoints(), eccentricity_, opt_.markers, stamp, markers_msg_,
                            marker_names_);
        if (!events_.empty()) {
          StatusText text;
          text.position = overlay_.position;
          text.height = overlay_.height;
          appendEventMarkers(events_.happened(), opt_.markers, text, stamp, markers_msg_);
        }
      }
    }
    if (publish_tf) {
      tf_pub_.publish(tf_msg_);
      ++window_publishes_;
    }
    if (want_contacts) contacts_pub_.publish(contacts_msg_);
    if (want_key_figures) key_figures_pub_.publish(key_figures_msg_);
    if (want_joint_states) joint_states_pub_.publish(joint_states_msg_);
    if (want_status) status_pub_.publish(status_msg_);
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
      const unsigned long long halved = window_.halved_total;
      const unsigned long long failures = window_.step_failures;
      window_ = DiagnosticsWindow{};
      window_.unconverged_total = unconverged;
      window_.halved_total = halved;
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
  // An actuator command schedule the node follows until a topic command takes over.
  struct ScheduledCommand {
    int actuator = -1;
    nscd::CommandSchedule schedule;
    bool active = true;
  };
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

  RealTimePacer pacer_;  // loop thread only

  std::vector<int> tf_links_;
  tf2_msgs::TFMessage tf_msg_;  // written by the loop thread under mutex_
  ros::Time last_tf_stamp_;
  bool have_tf_stamp_ = false;
  nscd_sim::ContactArray contacts_msg_;
  nscd_sim::KeyFigures key_figures_msg_;  // names fixed at start, values per publication
  sensor_msgs::JointState joint_states_msg_;
  std::vector<double> figure_values_;  // nscd::keyFigureValues, per publication
  StatusOverlay overlay_;
  std::vector<std::string> status_names_;
  std::vector<double> status_values_;
  visualization_msgs::Marker status_msg_;
  SteadyClock::time_point status_wall_;  // last status publication (rtf)
  double status_sim_ = 0, status_rtf_ = 0;
  bool status_have_ = false;
  std::vector<int> joint_state_index_;  // the joints of joint_states_msg_ (not fixed)
  visualization_msgs::MarkerArray markers_msg_;
  std::vector<EccentricityView> eccentricity_;
  MarkerNames marker_names_;
  EventTracker events_;  // guarded by mutex_
  std::string display_error_;  // the last display-parameter warning (timer thread)

  ros::Publisher tf_pub_, contacts_pub_, key_figures_pub_, joint_states_pub_, status_pub_, markers_pub_, diagnostics_pub_, clock_pub_;
  std::vector<ros::Subscriber> command_subs_;
  std::set<std::string> actuator_names_;
  ros::ServiceServer reset_srv_, pause_srv_, step_srv_;
  ros::WallTimer topic_check_, display_check_;
  WallThrottle command_throttle_, unknown_topic_throttle_, unconverged_throttle_;
};

}  // namespace

void runSimNode(ros::NodeHandle& nh, ros::NodeHandle& pnh, std::unique_ptr<nscd::Simulator> sim,
                const NodeOptions& options, const std::vector<nscd::BoundSchedule>& schedules,
                const StatusOverlay& overlay) {
  SimNode node(nh, pnh, std::move(sim), options, schedules, overlay);
  ros::AsyncSpinner spinner(1);
  spinner.start();
  node.run();
  spinner.stop();
}

}  // namespace nscd_node
