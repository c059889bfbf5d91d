// The simulator the node's two threads share: the loop thread (stepping_loop.hpp)
// steps and publishes, one spinner thread serves topics and services
// (node_services.hpp). The session owns the simulator and its lock, and steps it:
// command schedules before a step, statistics and run events after, a failed step
// stopping the stepping. Nothing physical is decided here.
//
// `mutex_` guards the simulator, the schedules, the events, the counters and the
// failure text; it is taken per step, so a callback waits at most one step.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "node_params.hpp"
#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/simulator.hpp"
#include "ros_conversions.hpp"
#include "run_events.hpp"
#include "wall_clock.hpp"

namespace nscd_node {

// What the loop should do at once instead of at its next period; set by the
// callbacks (and a failed step), taken by the loop thread.
struct LoopRequests {
  std::atomic<bool> publish{false};      // publish the state now (a command landed, a step)
  std::atomic<bool> diagnostics{false};  // publish /diagnostics now (pause, reset, failure)
  std::atomic<bool> reanchor{false};     // the pacing restarts from the current sim time
};

class SimSession {
 public:
  SimSession(std::unique_ptr<nscd::Simulator> sim, const std::vector<nscd::BoundSchedule>& schedules,
             const std::vector<CommandRateLimit>& rate_limits, EventTracker events, bool start_paused);

  // Callbacks lock through this: the stepping loop, which retakes the lock after
  // every step, lets a waiting callback in first (std::mutex is not fair).
  std::unique_lock<std::mutex> callbackLock();
  // The loop thread's lock (publication, diagnostics).
  std::unique_lock<std::mutex> loopLock() { return std::unique_lock<std::mutex>(mutex_); }

  // Loop thread, without the lock: one step if running and sim time is before
  // `until`; false otherwise.
  bool stepOnce(double until);
  // Takes the lock.
  double simTime();

  // ---- The rest requires the lock.
  const nscd::Simulator& sim() const { return *sim_; }
  // One step, paused or not (~step): the schedules' commands at the step's end and
  // the rate-limited ones moved towards their targets first. A failed step (non-finite state) stops the
  // stepping until reset() and asks for diagnostics.
  void step();
  // A topic command. `accepted`: a finite value, which the simulator takes at once,
  // or, for a rate-limited actuator, the target its command moves to from the next
  // step on; `took_over`: it ended the actuator's schedule (until reset()).
  struct CommandResult {
    bool accepted = false;
    bool took_over = false;
  };
  CommandResult command(int actuator, double value);
  // The initial state, schedules from their start, counters and failure cleared;
  // the pause state is kept.
  void reset();
  void setPaused(bool paused);
  const std::string& failure() const { return failure_; }
  unsigned long long steps() const { return steps_; }
  const EventTracker& events() const { return events_; }
  // Ends a diagnostics period: its statistics with the last step's figures and the
  // run state; the totals carry over into the next period. The caller adds the
  // wall-clock length and the publications.
  DiagnosticsWindow closeDiagnosticsWindow();

  // ---- Readable without the lock.
  bool paused() const { return paused_; }
  bool failed() const { return failed_; }
  bool running() const { return running_; }

  LoopRequests requests;

 private:
  void restartSchedules();
  void updateRunning() { running_ = !paused_ && !failed_; }

  // An actuator command schedule followed until a topic command takes over.
  struct ScheduledCommand {
    int actuator = -1;
    nscd::CommandSchedule schedule;
    bool active = true;
  };

  // A rate-limited actuator and the topic command it moves towards.
  struct SlewedCommand {
    CommandRateLimit limit;
    bool active = false;  // a topic command arrived since start or reset
    double target = 0;
  };

  std::unique_ptr<nscd::Simulator> sim_;
  std::mutex mutex_;
  std::vector<ScheduledCommand> schedules_;
  std::vector<SlewedCommand> slewed_;
  EventTracker events_;
  std::atomic<bool> paused_{false};
  std::atomic<bool> failed_{false};
  std::atomic<bool> running_{true};
  std::atomic<int> callbacks_waiting_{0};
  std::string failure_;
  unsigned long long steps_ = 0;
  DiagnosticsWindow window_;
  WallThrottle unconverged_throttle_;
};

}  // namespace nscd_node
