// The shared simulator of the node: stepping, commands, reset, pause (sim_session.hpp).
#include "sim_session.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <thread>

#include <ros/console.h>

namespace nscd_node {

SimSession::SimSession(std::unique_ptr<nscd::Simulator> sim,
                       const std::vector<nscd::BoundSchedule>& schedules,
                       const std::vector<CommandRateLimit>& rate_limits, EventTracker events,
                       bool start_paused)
    : sim_(std::move(sim)), events_(std::move(events)) {
  for (const nscd::BoundSchedule& b : schedules) schedules_.push_back({b.actuator, b.schedule, true});
  for (const CommandRateLimit& l : rate_limits) slewed_.push_back({l, false, 0.0});
  paused_ = start_paused;
  updateRunning();
  restartSchedules();
}

std::unique_lock<std::mutex> SimSession::callbackLock() {
  ++callbacks_waiting_;
  std::unique_lock<std::mutex> lock(mutex_);
  --callbacks_waiting_;
  return lock;
}

bool SimSession::stepOnce(double until) {
  while (callbacks_waiting_ > 0) std::this_thread::yield();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_ || sim_->state().t >= until) return false;
  step();
  return running_;
}

double SimSession::simTime() {
  std::lock_guard<std::mutex> lock(mutex_);
  return sim_->state().t;
}

// Schedules start again from their first value (sim time 0).
void SimSession::restartSchedules() {
  for (ScheduledCommand& c : schedules_) {
    c.active = true;
    sim_->setCommand(c.actuator, c.schedule.value(sim_->state().t));
  }
}

void SimSession::step() {
  const double t0 = sim_->state().t;
  // As nscd_run: the command at the end of the step (planStep: t0 + dt, or the end of
  // the step the adaptive step control plans).
  const double t_end = sim_->planStep(INFINITY);
  for (const ScheduledCommand& c : schedules_)
    if (c.active) sim_->setCommand(c.actuator, c.schedule.value(t_end));
  for (const SlewedCommand& c : slewed_)
    if (c.active) {
      const double now = sim_->command(c.limit.actuator);
      // The step's length: dt itself on fixed steps (bit for bit as before).
      const nscd::Settings& set = sim_->model().settings;
      const double h = set.step_control == nscd::StepControl::Fixed ? set.dt : t_end - t0;
      const double most = c.limit.rate * h;
      sim_->setCommand(c.limit.actuator, now + std::clamp(c.target - now, -most, most));
    }
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
    requests.diagnostics = true;
    return;
  }
  if (!events_.empty())
    for (int e : events_.check(*sim_))
      ROS_INFO("nscd_sim_node: event '%s' at t=%.6f ms (step %llu)",
               events_.definitions()[e].label.c_str(), 1e3 * sim_->state().t, steps_);
}

SimSession::CommandResult SimSession::command(int actuator, double value) {
  CommandResult r;
  SlewedCommand* slewed = nullptr;
  for (SlewedCommand& c : slewed_)
    if (c.limit.actuator == actuator) slewed = &c;
  if (slewed) {
    r.accepted = std::isfinite(value);
    if (r.accepted) {
      slewed->active = true;
      slewed->target = value;
    }
  } else {
    r.accepted = sim_->setCommand(actuator, value);
  }
  if (!r.accepted) return r;
  for (ScheduledCommand& c : schedules_)
    if (c.actuator == actuator && c.active) {
      c.active = false;
      r.took_over = true;
    }
  return r;
}

void SimSession::reset() {
  sim_->reset();
  events_.reset();
  restartSchedules();
  for (SlewedCommand& c : slewed_) c.active = false;
  steps_ = 0;
  window_.unconverged_total = 0;
  window_.halved_total = 0;
  window_.step_failures = 0;
  failed_ = false;
  failure_.clear();
  updateRunning();
}

void SimSession::setPaused(bool paused) {
  paused_ = paused;
  updateRunning();
}

DiagnosticsWindow SimSession::closeDiagnosticsWindow() {
  DiagnosticsWindow w = window_;
  w.sim_time = sim_->state().t;
  w.steps = steps_;
  w.last_iterations = sim_->stats().iterations;
  w.last_residual = sim_->stats().residual;
  w.active_contacts = sim_->stats().active_contacts;
  w.max_penetration = sim_->stats().max_penetration;
  w.paused = paused_;
  w.failed = failed_;
  w.failure = failure_;
  // Totals carry over; the rest starts a new window.
  const unsigned long long unconverged = window_.unconverged_total;
  const unsigned long long halved = window_.halved_total;
  const unsigned long long failures = window_.step_failures;
  window_ = DiagnosticsWindow{};
  window_.unconverged_total = unconverged;
  window_.halved_total = halved;
  window_.step_failures = failures;
  return w;
}

}  // namespace nscd_node
