// Helpers of the node's rostest test nodes: wait for messages and services in
// wall time (the tests must not depend on /clock), and call services.
#pragma once

#include <functional>
#include <map>
#include <mutex>
#include <string>

#include <geometry_msgs/Quaternion.h>
#include <gtest/gtest.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <tf2_msgs/TFMessage.h>

#include "nscd_sim/ContactArray.h"
#include "nscd_sim/KeyFigures.h"

namespace nscd_test {

// main() of a rostest test node: initialises gtest and ROS as node `name`,
// keeps a NodeHandle and a 2-thread AsyncSpinner for the whole run, runs
// `run` (default: RUN_ALL_TESTS(); a test node that needs objects alive
// during its tests, as a tf listener, creates them in `run`), then shuts ROS
// down. Returns the result of `run`.
int runRosTestNode(int argc, char** argv, const char* name,
                   const std::function<int()>& run = {});

// The node under test (its name in the .test files).
extern const char* const kNode;  // "/nscd_sim_node"
std::string nodeTopic(const std::string& name);  // "/nscd_sim_node/<name>"

// The test node's private parameter ~scene (the scene both nodes load).
std::string sceneParam();

// Rotation angle about z of a quaternion (rad, in (-pi, pi]).
double yawOf(const geometry_msgs::Quaternion& q);

// Waits up to `timeout` wall seconds for a message on `topic` that satisfies
// `pred`; returns it, or null on timeout. Needs a running AsyncSpinner.
template <class M>
boost::shared_ptr<const M> waitForMessage(const std::string& topic,
                                          const std::function<bool(const M&)>& pred,
                                          double timeout) {
  ros::NodeHandle nh;
  std::mutex mutex;
  boost::shared_ptr<const M> found;
  ros::Subscriber sub = nh.subscribe<M>(topic, 10, [&](const boost::shared_ptr<const M>& msg) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!found && pred(*msg)) found = msg;
  });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (found) break;
    }
    ros::WallDuration(0.002).sleep();
  }
  sub.shutdown();
  std::lock_guard<std::mutex> lock(mutex);
  return found;
}

template <class M>
boost::shared_ptr<const M> waitForMessage(const std::string& topic, double timeout) {
  return waitForMessage<M>(topic, [](const M&) { return true; }, timeout);
}

// The persistent client of service `name` with `md5sum` (its type), made after
// waiting up to `timeout` wall seconds for the service, and made again when the
// node closed its connection. Its failure says which.
::testing::AssertionResult persistentServiceClient(
    const std::string& name, const std::string& md5sum, double timeout,
    const std::function<ros::ServiceClient()>& make, ros::ServiceClient& client);
// Forgets the client of `name` and `md5sum` (the next call connects again).
void dropServiceClient(const std::string& name, const std::string& md5sum);
// Closes every persistent client (runRosTestNode does, before ros::shutdown).
void closeServiceClients();

// Waits for the service (wall time) and calls it; a failure says which of the two
// failed and after how long. Over one persistent connection per service, not
// ros::service::call: roscpp's one-call client drops the connection when the
// server's close arrives together with the answer (POLLRDHUP, ros/ros_comm#1976),
// so a call the node did serve fails now and then (about 1 in 1000 on a loaded
// machine), and a ~step cannot be called again (the node took the steps).
template <class S>
::testing::AssertionResult callService(const std::string& name, S& srv, double timeout = 10.0) {
  ros::ServiceClient client;
  ::testing::AssertionResult made = persistentServiceClient(
      name, ros::service_traits::md5sum<S>(), timeout,
      [&name] { return ros::NodeHandle().serviceClient<S>(name, true); }, client);
  if (!made) return made;
  const ros::WallTime start = ros::WallTime::now();
  if (client.call(srv)) return ::testing::AssertionSuccess();
  dropServiceClient(name, ros::service_traits::md5sum<S>());
  return ::testing::AssertionFailure() << "call of " << name << " failed after "
                                       << (ros::WallTime::now() - start).toSec()
                                       << " s (connection to the node lost)";
}

// Publishes one message once a subscriber is connected (wall timeout).
template <class M>
bool publishWhenConnected(ros::Publisher& pub, const M& msg, double timeout = 10.0) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (pub.getNumSubscribers() == 0) {
    if (ros::WallTime::now() > end) return false;
    ros::WallDuration(0.01).sleep();
  }
  pub.publish(msg);
  return true;
}

// Drives the node under test deterministically in sim time: pause it, land a
// command (~key_figures shows it), take N steps with ~step, then read the state
// published after exactly those steps (~contacts, /tf, ~key_figures). Nothing
// depends on how fast the machine is. Keeps the latest message of each topic.
class SteppedNode {
 public:
  SteppedNode();
  // Shuts the subscriptions down first: a callback still running must not
  // write into members already destroyed.
  ~SteppedNode();
  SteppedNode(const SteppedNode&) = delete;
  SteppedNode& operator=(const SteppedNode&) = delete;
  bool setPaused(bool paused);
  // ~step(count); waits until ~contacts and /tf show the state after it. Returns
  // that state's ~contacts (null if the call failed, took fewer steps, or timed out).
  nscd_sim::ContactArrayConstPtr step(uint32_t count, double timeout = 30.0);
  // The response of the last ~step call.
  uint32_t lastStepsTaken() const { return last_steps_taken_; }
  bool lastStepSucceeded() const { return last_step_success_; }
  // Publishes `value` on ~<actuator>/command and waits until ~key_figures shows
  // it as <actuator>.cmd (false on timeout).
  bool command(const std::string& actuator, double value, double timeout = 10.0);
  // Publishes `value` without waiting (for values the node must ignore).
  void publishCommand(const std::string& actuator, double value);
  // The latest ~key_figures value of `name` (NaN if none).
  double keyFigure(const std::string& name) const;
  // Yaw (rotation about z) of `child` in the latest /tf (NaN if none).
  double yaw(const std::string& child) const;
  // The latest transform of `child` (false if none).
  bool transform(const std::string& child, geometry_msgs::TransformStamped& out) const;
  // Waits until a ~contacts message satisfies `pred` (wall timeout); the latest one.
  nscd_sim::ContactArrayConstPtr waitForContacts(
      const std::function<bool(const nscd_sim::ContactArray&)>& pred, double timeout = 10.0);

 private:
  ros::Publisher& commandPublisher(const std::string& actuator);
  mutable std::mutex mutex_;
  ros::NodeHandle nh_;
  ros::Subscriber tf_sub_, contacts_sub_, figures_sub_;
  std::map<std::string, geometry_msgs::TransformStamped> tf_;
  nscd_sim::ContactArrayConstPtr contacts_;
  nscd_sim::KeyFiguresConstPtr figures_;
  std::map<std::string, ros::Publisher> command_pubs_;
  uint32_t last_steps_taken_ = 0;
  bool last_step_success_ = false;
};

}  // namespace nscd_test
