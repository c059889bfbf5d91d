// The node proper, in the shape of robot_state_publisher: the parts do the work,
// this file only wires them.
//   SimSession (sim_session.hpp): the simulator and its lock; stepping with the
//     schedules, run events and statistics; commands, reset, pause.
//   StatePublishers (state_publishers.hpp): tf, contacts, key figures, joint
//     states, status text, markers, /clock. DiagnosticsPublisher: /diagnostics.
//   NodeServices (node_services.hpp): command topics, ~reset/~pause/~step, the
//     command-topic check and the display parameters re-read while running.
//   SteppingLoop (stepping_loop.hpp): pacing, stepping and the publication periods.
// Threads: the caller's thread runs the loop; one AsyncSpinner thread serves
// topics and services. Nothing physical is decided here.
#include "sim_node.hpp"

#include <utility>

#include "diagnostics_publisher.hpp"
#include "node_services.hpp"
#include "run_events.hpp"
#include "sim_session.hpp"
#include "state_publishers.hpp"
#include "stepping_loop.hpp"

namespace nscd_node {

void runSimNode(ros::NodeHandle& nh, ros::NodeHandle& pnh, std::unique_ptr<nscd::Simulator> sim,
                const NodeOptions& options, const std::vector<nscd::BoundSchedule>& schedules,
                const std::vector<CommandRateLimit>& rate_limits, const StatusOverlay& overlay) {
  EventTracker events = eventTracker(pnh, options, sim->model());
  SimSession session(std::move(sim), schedules, rate_limits, std::move(events), options.start_paused);
  const nscd::Model& model = session.sim().model();
  for (const EventDefinition& d : session.events().definitions())
    ROS_INFO("nscd_sim_node: event '%s' shown when its condition holds (%zu figure%s %s %g)",
             d.label.c_str(), d.figures.size(), d.figures.size() == 1 ? "" : "s",
             d.greater ? ">" : "<", d.threshold);

  StatePublishers publishers(nh, pnh, session, options, overlay);
  DiagnosticsPublisher diagnostics(nh, session, options.use_sim_time);
  NodeServices services(nh, pnh, session, publishers.markerStyle());
  SteppingLoop loop(session, publishers, diagnostics, options);

  ROS_INFO("nscd_sim_node: %s: %zu bodies, %zu links, %zu actuators, dt=%g s, "
           "real_time_factor=%g, publish_rate=%g Hz%s",
           model.source_file.c_str(), model.bodies.size(), model.links.size(),
           model.actuators.size(), model.settings.dt, options.real_time_factor,
           options.publish_rate, session.paused() ? ", paused" : "");
  for (const nscd::BoundSchedule& b : schedules)
    ROS_INFO("nscd_sim_node: actuator '%s' follows a schedule of %zu points until a command "
             "arrives on %s",
             b.schedule.actuator.c_str(), b.schedule.points.size(),
             pnh.resolveName(b.schedule.actuator + "/command").c_str());
  for (const CommandRateLimit& l : rate_limits)
    ROS_INFO("nscd_sim_node: actuator '%s' follows its topic commands at most %g per second of sim time",
             model.actuators[l.actuator].name.c_str(), l.rate);

  ros::AsyncSpinner spinner(1);
  spinner.start();
  loop.run();
  spinner.stop();
}

}  // namespace nscd_node
