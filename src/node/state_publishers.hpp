// The node's view of the state, published at each publication of the loop: /tf,
// ~contacts, ~key_figures, /joint_states, ~status, ~contact_markers and /clock.
// Everything is copied out of the session under its lock and sent after; a
// topic nobody subscribes to (but /tf and /clock) is not built.
#pragma once

#include <string>
#include <vector>

#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/Marker.h>
#include <visualization_msgs/MarkerArray.h>

#include "contact_markers.hpp"
#include "node_params.hpp"
#include "nscd_sim/ContactArray.h"
#include "nscd_sim/KeyFigures.h"
#include "sim_session.hpp"
#include "wall_clock.hpp"

namespace nscd_node {

class StatePublishers {
 public:
  StatePublishers(ros::NodeHandle& nh, ros::NodeHandle& pnh, SimSession& session,
                  const NodeOptions& options, const StatusOverlay& overlay);

  // Loop thread: publishes the current state (nothing after a failed step: the
  // state may hold NaN, the last good picture stays).
  void publish();
  // Loop thread: the /tf publications since the last call.
  int takeTfPublications();
  // The marker style; guarded by the session's lock (the display parameters
  // change it while the node runs).
  MarkerStyle& markerStyle() { return style_; }

 private:
  void onTfSubscriber(const ros::SingleSubscriberPublisher& pub);
  // Each fills its message from the simulator (under the loop lock) for publish().
  void fillTf(const nscd::Simulator& sim, const ros::Time& stamp);
  void fillContacts(const nscd::Simulator& sim, const ros::Time& stamp);
  void fillJointStates(const nscd::Simulator& sim, const ros::Time& stamp);
  void fillStatus(double t, const ros::Time& stamp);
  void fillKeyFigures(double t, const ros::Time& stamp);
  void fillMarkers(const nscd::Simulator& sim, const ros::Time& stamp);

  SimSession& session_;
  const bool use_sim_time_;
  MarkerStyle style_;
  const StatusOverlay overlay_;

  std::vector<int> tf_links_;
  tf2_msgs::TFMessage tf_msg_;  // written by the loop thread under the session's lock
  ros::Time last_tf_stamp_;
  bool have_tf_stamp_ = false;
  int tf_publications_ = 0;  // loop thread only
  nscd_sim::ContactArray contacts_msg_;
  nscd_sim::KeyFigures key_figures_msg_;  // names fixed at start, values per publication
  sensor_msgs::JointState joint_states_msg_;
  std::vector<int> joint_state_index_;  // the joints of joint_states_msg_ (not fixed)
  std::vector<double> figure_values_;   // nscd::keyFigureValues, per publication
  std::vector<std::string> status_names_;
  std::vector<double> status_values_;
  visualization_msgs::Marker status_msg_;
  SteadyClock::time_point status_wall_;  // last status publication (rtf)
  double status_sim_ = 0, status_rtf_ = 0;
  bool status_have_ = false;
  visualization_msgs::MarkerArray markers_msg_;
  std::vector<EccentricityView> eccentricity_;
  MarkerNames marker_names_;

  ros::Publisher tf_pub_, contacts_pub_, key_figures_pub_, joint_states_pub_, status_pub_,
      markers_pub_, clock_pub_;
};

}  // namespace nscd_node
