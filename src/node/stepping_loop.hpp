// The node's loop, on the caller's thread until ROS shuts down: steps the session
// at the real-time factor (RealTimePacer) in batches that end at the next
// publication, publishes the state at ~publish_rate and /diagnostics at
// ~diagnostics_rate, and answers the callbacks' requests (LoopRequests) at once.
#pragma once

#include "diagnostics_publisher.hpp"
#include "node_params.hpp"
#include "real_time_pacer.hpp"
#include "sim_session.hpp"
#include "state_publishers.hpp"

namespace nscd_node {

class SteppingLoop {
 public:
  SteppingLoop(SimSession& session, StatePublishers& publishers, DiagnosticsPublisher& diagnostics,
               const NodeOptions& options);
  // Returns when ROS shuts down.
  void run();

 private:
  void reanchor() { pacer_.reanchor(SteadyClock::now(), session_.simTime()); }

  SimSession& session_;
  StatePublishers& publishers_;
  DiagnosticsPublisher& diagnostics_;
  const double publish_rate_, diagnostics_rate_;
  RealTimePacer pacer_;
};

}  // namespace nscd_node
