// The node's /diagnostics (diagnostics_publisher.hpp).
#include "diagnostics_publisher.hpp"

#include <diagnostic_msgs/DiagnosticArray.h>

#include "ros_conversions.hpp"

namespace nscd_node {

DiagnosticsPublisher::DiagnosticsPublisher(ros::NodeHandle& nh, SimSession& session,
                                           bool use_sim_time)
    : session_(session), use_sim_time_(use_sim_time),
      scene_name_(session.sim().model().source_file) {
  pub_ = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 2);
}

void DiagnosticsPublisher::publish(SteadyClock::time_point now, int tf_publications) {
  diagnostic_msgs::DiagnosticArray msg;
  {
    const auto lock = session_.loopLock();
    DiagnosticsWindow w = session_.closeDiagnosticsWindow();
    w.wall_seconds = seconds(now - window_start_);
    w.publishes = tf_publications;
    msg.header.stamp = stampFor(use_sim_time_, w.sim_time);
    msg.status.push_back(toDiagnosticStatus(w, scene_name_));
  }
  window_start_ = now;
  pub_.publish(msg);
}

}  // namespace nscd_node
