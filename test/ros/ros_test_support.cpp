#include "ros_test_support.hpp"

#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <std_msgs/Float64.h>
#include <std_srvs/SetBool.h>

#include "nscd_sim/Step.h"

namespace nscd_test {

int runRosTestNode(int argc, char** argv, const char* name, const std::function<int()>& run) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, name);
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = run ? run() : RUN_ALL_TESTS();
  closeServiceClients();
  spinner.stop();
  ros::shutdown();
  return result;
}

namespace {
std::mutex g_clients_mutex;
std::map<std::string, ros::ServiceClient> g_clients;  // by "<service> <md5sum>"
}  // namespace

::testing::AssertionResult persistentServiceClient(
    const std::string& name, const std::string& md5sum, double timeout,
    const std::function<ros::ServiceClient()>& make, ros::ServiceClient& client) {
  {
    std::lock_guard<std::mutex> lock(g_clients_mutex);
    auto it = g_clients.find(name + " " + md5sum);
    if (it != g_clients.end() && it->second.isValid()) {
      client = it->second;
      return ::testing::AssertionSuccess();
    }
  }
  const ros::WallTime start = ros::WallTime::now();
  if (!ros::service::waitForService(name, static_cast<int>(timeout * 1000)))
    return ::testing::AssertionFailure() << "service " << name << " not available after "
                                         << (ros::WallTime::now() - start).toSec() << " s";
  client = make();
  if (!client.isValid())
    return ::testing::AssertionFailure() << "no connection to service " << name << " (type md5sum "
                                         << md5sum << ") after "
                                         << (ros::WallTime::now() - start).toSec() << " s";
  std::lock_guard<std::mutex> lock(g_clients_mutex);
  g_clients[name + " " + md5sum] = client;
  return ::testing::AssertionSuccess();
}

void dropServiceClient(const std::string& name, const std::string& md5sum) {
  std::lock_guard<std::mutex> lock(g_clients_mutex);
  g_clients.erase(name + " " + md5sum);
}

void closeServiceClients() {
  std::lock_guard<std::mutex> lock(g_clients_mutex);
  for (auto& kv : g_clients) kv.second.shutdown();
  g_clients.clear();
}

const char* const kNode = "/nscd_sim_node";

std::string nodeTopic(const std::string& name) { return std::string(kNode) + "/" + name; }

std::string sceneParam() {
  std::string scene;
  ros::param::get("~scene", scene);
  return scene;
}

double yawOf(const geometry_msgs::Quaternion& q) {
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

SteppedNode::SteppedNode() {
  tf_sub_ = nh_.subscribe<tf2_msgs::TFMessage>(
      "/tf", 100, [this](const tf2_msgs::TFMessageConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex_);
        for (const auto& t : m->transforms) tf_[t.child_frame_id] = t;
      });
  contacts_sub_ = nh_.subscribe<nscd_sim::ContactArray>(
      nodeTopic("contacts"), 10, [this](const nscd_sim::ContactArrayConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex_);
        contacts_ = m;
      });
  figures_sub_ = nh_.subscribe<nscd_sim::KeyFigures>(
      nodeTopic("key_figures"), 10, [this](const nscd_sim::KeyFiguresConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex_);
        figures_ = m;
      });
}

SteppedNode::~SteppedNode() {
  // Subscriber::shutdown waits for a callback in progress to return.
  tf_sub_.shutdown();
  contacts_sub_.shutdown();
  figures_sub_.shutdown();
}

bool SteppedNode::setPaused(bool paused) {
  std_srvs::SetBool srv;
  srv.request.data = paused;
  return callService(nodeTopic("pause"), srv) && srv.response.success;
}

nscd_sim::ContactArrayConstPtr SteppedNode::waitForContacts(
    const std::function<bool(const nscd_sim::ContactArray&)>& pred, double timeout) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (contacts_ && pred(*contacts_)) return contacts_;
    }
    ros::WallDuration(0.002).sleep();
  }
  return {};
}

// A step the node refuses (success false) returns null quietly (tests expect some);
// a lost call or a state that does not show up is a failure that says what it saw.
nscd_sim::ContactArrayConstPtr SteppedNode::step(uint32_t count, double timeout) {
  nscd_sim::Step srv;
  srv.request.count = count;
  last_steps_taken_ = 0;
  last_step_success_ = false;
  const ::testing::AssertionResult called = callService(nodeTopic("step"), srv, timeout);
  if (!called) {
    ADD_FAILURE() << "~step(" << count << "): " << called.message();
    return {};
  }
  last_steps_taken_ = srv.response.steps_taken;
  last_step_success_ = srv.response.success;
  if (!srv.response.success || srv.response.steps_taken != std::max<uint32_t>(count, 1)) return {};
  const double t = srv.response.sim_time;
  auto contacts =
      waitForContacts([t](const nscd_sim::ContactArray& m) { return m.sim_time == t; }, timeout);
  if (!contacts) {
    std::lock_guard<std::mutex> lock(mutex_);
    ADD_FAILURE() << "~step(" << count << ") answered sim_time " << t << " s but no ~contacts of it within "
                  << timeout << " s (latest: "
                  << (contacts_ ? std::to_string(contacts_->sim_time) + " s" : std::string("none")) << ")";
    return {};
  }
  // /tf of the same publication (same stamp) or a later one: the same poses.
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      bool all = !tf_.empty();
      for (const auto& kv : tf_) all = all && kv.second.header.stamp >= contacts->header.stamp;
      if (all) return contacts;
    }
    ros::WallDuration(0.002).sleep();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ADD_FAILURE() << "~step(" << count << "): /tf of the ~contacts stamped " << contacts->header.stamp
                << " not received within " << timeout << " s (" << tf_.size() << " frames seen)";
  return {};
}

ros::Publisher& SteppedNode::commandPublisher(const std::string& actuator) {
  auto it = command_pubs_.find(actuator);
  if (it == command_pubs_.end())
    it = command_pubs_
             .emplace(actuator, nh_.advertise<std_msgs::Float64>(
                                    nodeTopic(actuator + "/command"), 10))
             .first;
  return it->second;
}

void SteppedNode::publishCommand(const std::string& actuator, double value) {
  std_msgs::Float64 msg;
  msg.data = value;
  if (!publishWhenConnected(commandPublisher(actuator), msg))
    ADD_FAILURE() << "the node did not subscribe to " << nodeTopic(actuator + "/command")
                  << " within 10 s; command " << value << " not sent";
}

bool SteppedNode::command(const std::string& actuator, double value, double timeout) {
  publishCommand(actuator, value);
  const std::string name = actuator + ".cmd";
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end) {
    if (keyFigure(name) == value) return true;
    ros::WallDuration(0.002).sleep();
  }
  ADD_FAILURE() << "command " << value << " on " << nodeTopic(actuator + "/command") << ": ~key_figures "
                << name << " still " << keyFigure(name) << " after " << timeout << " s";
  return false;
}

double SteppedNode::keyFigure(const std::string& name) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!figures_) return NAN;
  for (size_t i = 0; i < figures_->names.size() && i < figures_->values.size(); ++i)
    if (figures_->names[i] == name) return figures_->values[i];
  return NAN;
}

bool SteppedNode::transform(const std::string& child, geometry_msgs::TransformStamped& out) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = tf_.find(child);
  if (it == tf_.end()) return false;
  out = it->second;
  return true;
}

double SteppedNode::yaw(const std::string& child) const {
  geometry_msgs::TransformStamped t;
  return transform(child, t) ? yawOf(t.transform.rotation) : NAN;
}

}  // namespace nscd_test
