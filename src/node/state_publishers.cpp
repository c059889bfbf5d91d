// The state publications of the node (state_publishers.hpp).
#include "state_publishers.hpp"

#include <geometry_msgs/TransformStamped.h>
#include <rosgraph_msgs/Clock.h>

#include "nscd_sim/key_figures.hpp"
#include "ros_conversions.hpp"

namespace nscd_node {

StatePublishers::StatePublishers(ros::NodeHandle& nh, ros::NodeHandle& pnh, SimSession& session,
                                 const NodeOptions& options, const StatusOverlay& overlay)
    : session_(session), use_sim_time_(options.use_sim_time), style_(options.markers),
      overlay_(overlay) {
  const nscd::Model& model = session_.sim().model();
  style_.frame = model.world_frame;
  for (size_t i = 0; i < model.links.size(); ++i) {
    if (model.links[i].name == model.world_frame) continue;
    tf_links_.push_back(static_cast<int>(i));
    geometry_msgs::TransformStamped t;
    t.header.frame_id = model.world_frame;
    t.child_frame_id = model.links[i].name;
    tf_msg_.transforms.push_back(t);
  }
  for (size_t i = 0; i < model.clearance_joints.size(); ++i)
    eccentricity_.push_back(eccentricityView(session_.sim(), static_cast<int>(i)));
  for (const nscd::ContactPair& c : model.contacts) marker_names_.contacts.push_back(c.name);
  for (const nscd::ClearanceJoint& j : model.clearance_joints) marker_names_.clearance.push_back(j.name);

  // tf2_ros::TransformBroadcaster without its publisher hidden: a new /tf
  // subscriber gets the last transforms at once (see onTfSubscriber).
  tf_pub_ = nh.advertise<tf2_msgs::TFMessage>(
      "/tf", 100, [this](const ros::SingleSubscriberPublisher& p) { onTfSubscriber(p); });
  contacts_pub_ = pnh.advertise<nscd_sim::ContactArray>("contacts", 2);
  key_figures_pub_ = pnh.advertise<nscd_sim::KeyFigures>("key_figures", 10);
  key_figures_msg_.names = nscd::keyFigureNames(model);
  key_figures_msg_.values.reserve(key_figures_msg_.names.size());
  status_pub_ = pnh.advertise<visualization_msgs::Marker>("status", 2);
  for (int f : overlay_.figures) status_names_.push_back(key_figures_msg_.names[f]);
  status_values_.resize(status_names_.size());
  joint_states_pub_ = nh.advertise<sensor_msgs::JointState>("joint_states", 10);
  for (size_t j = 0; j < model.joints.size(); ++j) {
    if (model.joints[j].type == nscd::JointType::Fixed) continue;
    joint_state_index_.push_back(static_cast<int>(j));
    joint_states_msg_.name.push_back(model.joints[j].name);
  }
  joint_states_msg_.position.resize(joint_state_index_.size());
  joint_states_msg_.velocity.resize(joint_state_index_.size());
  markers_pub_ = pnh.advertise<visualization_msgs::MarkerArray>("contact_markers", 2);
  if (use_sim_time_) clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 2);
}

int StatePublishers::takeTfPublications() {
  const int n = tf_publications_;
  tf_publications_ = 0;
  return n;
}

// A listener that connects while a paused sim-time node sends no tf (e.g. RViz
// started after the pause) would see no links: send it the last transforms.
void StatePublishers::onTfSubscriber(const ros::SingleSubscriberPublisher& pub) {
  tf2_msgs::TFMessage msg;
  {
    const auto lock = session_.callbackLock();
    if (!have_tf_stamp_) return;
    msg = tf_msg_;
  }
  pub.publish(msg);
}

void StatePublishers::fillTf(const nscd::Simulator& sim, const ros::Time& stamp) {
  for (size_t i = 0; i < tf_links_.size(); ++i) {
    tf_msg_.transforms[i].header.stamp = stamp;
    tf_msg_.transforms[i].transform = toTransform(sim.linkPose(tf_links_[i]));
  }
  last_tf_stamp_ = stamp;
  have_tf_stamp_ = true;
}

void StatePublishers::fillContacts(const nscd::Simulator& sim, const ros::Time& stamp) {
  const nscd::Model& model = sim.model();
  const std::vector<nscd::ContactReport>& reports = sim.contactPoints();
  contacts_msg_.header.stamp = stamp;
  contacts_msg_.header.frame_id = model.world_frame;
  contacts_msg_.sim_time = sim.state().t;
  contacts_msg_.steps = session_.steps();
  contacts_msg_.contacts.resize(reports.size());
  for (size_t i = 0; i < reports.size(); ++i) toContactMsg(model, reports[i], contacts_msg_.contacts[i]);
}

void StatePublishers::fillJointStates(const nscd::Simulator& sim, const ros::Time& stamp) {
  joint_states_msg_.header.stamp = stamp;
  for (size_t k = 0; k < joint_state_index_.size(); ++k) {
    joint_states_msg_.position[k] = sim.jointPosition(joint_state_index_[k]);
    joint_states_msg_.velocity[k] = sim.jointVelocity(joint_state_index_[k]);
  }
}

// Needs figure_values_ up to date.
void StatePublishers::fillStatus(double t, const ros::Time& stamp) {
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
  buildStatusMarker(t, status_rtf_, session_.paused(), style_, status_names_, status_values_, text,
                    stamp, status_msg_);
}

// Needs figure_values_ up to date.
void StatePublishers::fillKeyFigures(double t, const ros::Time& stamp) {
  key_figures_msg_.header.stamp = stamp;
  key_figures_msg_.sim_time = t;
  key_figures_msg_.steps = session_.steps();
  key_figures_msg_.values = figure_values_;
}

void StatePublishers::fillMarkers(const nscd::Simulator& sim, const ros::Time& stamp) {
  for (size_t i = 0; i < eccentricity_.size(); ++i) eccentricity_[i] = eccentricityView(sim, static_cast<int>(i));
  buildContactMarkers(sim.contactPoints(), eccentricity_, style_, stamp, markers_msg_, marker_names_);
  const EventTracker& events = session_.events();
  if (!events.empty()) {
    StatusText text;
    text.position = overlay_.position;
    text.height = overlay_.height;
    appendEventMarkers(events.happened(), style_, text, stamp, markers_msg_);
  }
}

// Fills, under the loop lock, only the messages someone subscribes to (tf always),
// then publishes them.
void StatePublishers::publish() {
  const bool want_contacts = contacts_pub_.getNumSubscribers() > 0;
  const bool want_markers = markers_pub_.getNumSubscribers() > 0;
  const bool want_key_figures = key_figures_pub_.getNumSubscribers() > 0;
  const bool want_joint_states = joint_states_pub_.getNumSubscribers() > 0;
  const bool want_status = status_pub_.getNumSubscribers() > 0;
  double t;
  bool publish_tf;
  {
    const auto lock = session_.loopLock();
    if (session_.failed()) return;  // the state may hold NaN: keep the last good picture
    const nscd::Simulator& sim = session_.sim();
    t = sim.state().t;
    const ros::Time stamp = stampFor(use_sim_time_, t);
    // With sim time, a repeated stamp (paused) would make tf listeners complain
    // (TF_REPEATED_DATA); late subscribers get the transforms from onTfSubscriber.
    publish_tf = !(use_sim_time_ && stamp == last_tf_stamp_ && have_tf_stamp_);
    if (publish_tf) fillTf(sim, stamp);
    if (want_contacts) fillContacts(sim, stamp);
    if (want_joint_states) fillJointStates(sim, stamp);
    if (want_key_figures || want_status) nscd::keyFigureValues(sim, figure_values_);
    if (want_status) fillStatus(t, stamp);
    if (want_key_figures) fillKeyFigures(t, stamp);
    if (want_markers) fillMarkers(sim, stamp);
  }
  if (publish_tf) {
    tf_pub_.publish(tf_msg_);
    ++tf_publications_;
  }
  if (want_contacts) contacts_pub_.publish(contacts_msg_);
  if (want_key_figures) key_figures_pub_.publish(key_figures_msg_);
  if (want_joint_states) joint_states_pub_.publish(joint_states_msg_);
  if (want_status) status_pub_.publish(status_msg_);
  if (want_markers) markers_pub_.publish(markers_msg_);
  if (use_sim_time_) {
    rosgraph_msgs::Clock clock;
    clock.clock = ros::Time(t);
    clock_pub_.publish(clock);
  }
}

}  // namespace nscd_node
