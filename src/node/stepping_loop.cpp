// The node's stepping and publishing loop (stepping_loop.hpp).
#include "stepping_loop.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include <ros/ros.h>

namespace nscd_node {

SteppingLoop::SteppingLoop(SimSession& session, StatePublishers& publishers,
                           DiagnosticsPublisher& diagnostics, const NodeOptions& options)
    : session_(session), publishers_(publishers), diagnostics_(diagnostics),
      publish_rate_(options.publish_rate), diagnostics_rate_(options.diagnostics_rate),
      pacer_(options.real_time_factor, session.sim().model().settings.dt) {}

void SteppingLoop::run() {
  LoopRequests& requests = session_.requests;
  const auto pub_period = wallDuration(1.0 / publish_rate_);
  const auto diag_period = wallDuration(1.0 / diagnostics_rate_);
  auto next_pub = SteadyClock::now();
  auto next_diag = next_pub + diag_period;
  diagnostics_.start(next_pub);
  reanchor();

  while (ros::ok()) {
    if (requests.reanchor.exchange(false)) reanchor();
    if (session_.running()) {
      // Step up to where the wall clock says sim time should be, in batches that
      // end at the next publication; drop a backlog the engine cannot catch up.
      const auto start = SteadyClock::now();
      const double limit = pacer_.stepLimit(start);
      while (SteadyClock::now() < next_pub && session_.stepOnce(limit)) {
      }
      if (pacer_.behind(start, session_.simTime())) reanchor();
    }

    auto now = SteadyClock::now();
    const bool requested = requests.publish.exchange(false);
    if (now >= next_pub || requested) {
      publishers_.publish();
      if (now >= next_pub) {
        next_pub += pub_period;
        if (next_pub <= now) next_pub = now + pub_period;
      }
    }
    if (now >= next_diag || requests.diagnostics.exchange(false)) {
      diagnostics_.publish(now, publishers_.takeTfPublications());
      if (now >= next_diag) next_diag = now + diag_period;
    }

    // Sleep only when no step is due: until the next step, publication or
    // diagnostics, and at most 5 ms (pause and reset requests set flags).
    now = SteadyClock::now();
    auto wake = std::min({next_pub, next_diag, now + std::chrono::milliseconds(5)});
    if (session_.running()) {
      if (!pacer_.paced()) continue;
      const auto next_step = pacer_.nextStepDue(now, session_.simTime());
      if (next_step <= now) continue;
      wake = std::min(wake, next_step);
    }
    std::this_thread::sleep_until(wake);
  }
}

}  // namespace nscd_node
