// rostest: nscd_sim_node under malformed traffic (test/ros/malformed_traffic.test,
// issue 31), on test/ros/actuated_pendulum.urdf (actuators hinge_motor, push).
// Every topic and service the node serves (docs/interfaces.md, docs/node.md) gets
// NaN, +-inf, huge values, unknown and empty actuator names, wrong message and
// service types, and bursts. Asserted: the node stays up and answers every call
// in bounded wall time, never publishes a non-finite key figure or pose, and
// each cause gets its warning once (docs/node.md, "Errors": a non-finite command
// at most once per second per actuator, an unknown command topic once per name
// (names bounded), a failed step once until ~reset, a bad display parameter once
// until its text changes, a refused ~step count at most every 10 s).
#include <atomic>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <std_msgs/Float64.h>
#include <std_msgs/String.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>
#include <tf2_msgs/TFMessage.h>

#include "nscd_sim/KeyFigures.h"
#include "nscd_sim/Step.h"
#include "ros_test_support.hpp"

using nscd_test::nodeTopic;
using rosgraph_msgs::Log;

namespace {

// The node's log lines (/rosout) and whether anything it published was not finite.
class NodeWatch {
 public:
  NodeWatch() {
    log_sub_ = nh_.subscribe<Log>("/rosout", 1000, [this](const rosgraph_msgs::LogConstPtr& m) {
      if (m->name != nscd_test::kNode) return;
      std::lock_guard<std::mutex> lock(mutex_);
      lines_.push_back(*m);
    });
    figures_sub_ = nh_.subscribe<nscd_sim::KeyFigures>(
        nodeTopic("key_figures"), 100, [this](const nscd_sim::KeyFiguresConstPtr& m) {
          bool finite = std::isfinite(m->sim_time);
          for (double v : m->values) finite = finite && std::isfinite(v);
          std::lock_guard<std::mutex> lock(mutex_);
          ++figures_seen_;
          if (!finite) ++non_finite_;
        });
    tf_sub_ = nh_.subscribe<tf2_msgs::TFMessage>("/tf", 100, [this](const tf2_msgs::TFMessageConstPtr& m) {
      bool finite = true;
      for (const auto& t : m->transforms) {
        const auto& p = t.transform.translation;
        const auto& q = t.transform.rotation;
        finite = finite && std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(q.w) &&
                 std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
      }
      std::lock_guard<std::mutex> lock(mutex_);
      if (!finite) ++non_finite_;
    });
  }
  ~NodeWatch() {
    log_sub_.shutdown();
    figures_sub_.shutdown();
    tf_sub_.shutdown();
  }
  // Lines at `level` whose text contains `text`.
  int count(uint8_t level, const std::string& text) const {
    std::lock_guard<std::mutex> lock(mutex_);
    int n = 0;
    for (const Log& l : lines_) n += l.level == level && l.msg.find(text) != std::string::npos;
    return n;
  }
  // Waits up to `timeout` wall seconds until count(level, text) >= n; the count.
  int waitFor(uint8_t level, const std::string& text, int n, double timeout) const {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
    while (count(level, text) < n && ros::ok() && ros::WallTime::now() < end) ros::WallDuration(0.01).sleep();
    return count(level, text);
  }
  int nonFinitePublished() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return non_finite_;
  }
  int figuresSeen() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return figures_seen_;
  }

 private:
  ros::NodeHandle nh_;
  ros::Subscriber log_sub_, figures_sub_, tf_sub_;
  mutable std::mutex mutex_;
  std::vector<Log> lines_;
  int non_finite_ = 0;
  int figures_seen_ = 0;
};

std::unique_ptr<nscd_test::SteppedNode> g_node;
std::unique_ptr<NodeWatch> g_watch;

// A publisher of Float64 commands with room for a burst, once connected.
ros::Publisher burstPublisher(const std::string& topic) {
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<std_msgs::Float64>(topic, 1000);
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(10.0);
  while (pub.getNumSubscribers() == 0 && ros::WallTime::now() < end) ros::WallDuration(0.01).sleep();
  return pub;
}

void publish(ros::Publisher& pub, double value) {
  std_msgs::Float64 m;
  m.data = value;
  pub.publish(m);
}

// ~step(count) answers within `seconds` of wall time; its response. The call runs
// on a thread of its own, left behind if the node does not answer (a held node
// would otherwise hold the test until rostest's time limit).
::testing::AssertionResult stepAnswers(uint32_t count, double seconds, nscd_sim::Step& srv) {
  struct Call {
    std::mutex mutex;
    std::condition_variable done_cv;
    bool done = false, called = false;
    std::string why;  // of a failed call
    nscd_sim::Step srv;
  };
  auto call = std::make_shared<Call>();
  call->srv.request.count = count;
  const ros::WallTime start = ros::WallTime::now();
  std::thread([call, seconds] {
    nscd_sim::Step s;
    {
      std::lock_guard<std::mutex> lock(call->mutex);
      s = call->srv;
    }
    const ::testing::AssertionResult called = nscd_test::callService(nodeTopic("step"), s, seconds);
    std::lock_guard<std::mutex> lock(call->mutex);
    call->srv = s;
    call->called = called;
    call->why = called.message();
    call->done = true;
    call->done_cv.notify_all();
  }).detach();
  std::unique_lock<std::mutex> lock(call->mutex);
  call->done_cv.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return call->done; });
  const double took = (ros::WallTime::now() - start).toSec();
  if (!call->done) return ::testing::AssertionFailure() << "~step(" << count << ") no answer after " << took << " s";
  if (!call->called) return ::testing::AssertionFailure() << "~step(" << count << "): " << call->why;
  srv = call->srv;
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult resetAnswers() {
  std_srvs::Empty reset;
  return nscd_test::callService(nodeTopic("reset"), reset, 10.0);
}

}  // namespace

// A message of the wrong type on a command topic, and services called with the
// wrong service type: refused by ROS (md5sum mismatch), the node unaffected. (First:
// later tests give this process a Float64 publisher on push/command.)
TEST(MalformedTraffic, WrongMessageAndServiceTypes) {
  {
    ros::NodeHandle nh;
    ros::Publisher text = nh.advertise<std_msgs::String>(nodeTopic("push/command"), 10);
    ASSERT_TRUE(text) << "this process has a Float64 publisher on push/command already";
    std_msgs::String m;
    m.data = "1e308";
    for (int i = 0; i < 50; ++i) {
      text.publish(m);
      ros::WallDuration(0.002).sleep();
    }
    text.shutdown();
  }
  std_srvs::Empty wrong_step;
  EXPECT_FALSE(ros::service::call(nodeTopic("step"), wrong_step)) << "~step took a std_srvs/Empty";
  std_srvs::SetBool wrong_reset;
  EXPECT_FALSE(ros::service::call(nodeTopic("reset"), wrong_reset)) << "~reset took a std_srvs/SetBool";
  nscd_sim::Step srv;
  ASSERT_TRUE(stepAnswers(5, 10.0, srv));
  EXPECT_TRUE(srv.response.success);
  EXPECT_EQ(g_node->keyFigure("push.cmd"), 0.0);
}

// NaN and +-inf in bursts on both command topics: ignored (the commands keep their
// last good values), one warning for the burst per topic (one topic's flood does
// not hide the other's), and stepping goes on.
TEST(MalformedTraffic, NonFiniteCommandBurstIsIgnoredWithOneWarning) {
  ASSERT_TRUE(g_node->command("hinge_motor", 0.25));
  const int before = g_watch->count(Log::WARN, "ignored command");
  // Counted before the burst: the first warning can reach /rosout while it lasts.
  const int hinge_before = g_watch->count(Log::WARN, "hinge_motor/command (not a finite");
  const int push_before = g_watch->count(Log::WARN, "push/command (not a finite");
  ros::Publisher hinge = burstPublisher(nodeTopic("hinge_motor/command"));
  ros::Publisher push = burstPublisher(nodeTopic("push/command"));
  ASSERT_GT(hinge.getNumSubscribers(), 0u);
  ASSERT_GT(push.getNumSubscribers(), 0u);
  const ros::WallTime start = ros::WallTime::now();
  for (int i = 0; i < 100; ++i) {
    for (double bad : {NAN, INFINITY, -INFINITY}) {
      publish(hinge, bad);
      publish(push, bad);
    }
  }
  const double burst = (ros::WallTime::now() - start).toSec();
  EXPECT_GE(g_watch->waitFor(Log::WARN, "ignored command", before + 2, 10.0), before + 2)
      << "not a warning for each topic's 300 non-finite commands";
  ros::WallDuration(1.5).sleep();  // any later warning of the same burst would be here by now
  const int hinge_warnings = g_watch->count(Log::WARN, "hinge_motor/command (not a finite") - hinge_before;
  const int push_warnings = g_watch->count(Log::WARN, "push/command (not a finite") - push_before;
  if (burst < 0.5) {
    EXPECT_EQ(hinge_warnings, 1) << "a burst of " << burst << " s";
    EXPECT_EQ(push_warnings, 1) << "a burst of " << burst << " s";
  } else {
    EXPECT_GE(hinge_warnings, 1);
    EXPECT_GE(push_warnings, 1);
    EXPECT_LE(hinge_warnings, 2 + static_cast<int>(burst)) << "a burst of " << burst << " s";
    EXPECT_LE(push_warnings, 2 + static_cast<int>(burst)) << "a burst of " << burst << " s";
  }
  nscd_sim::Step srv;
  ASSERT_TRUE(stepAnswers(100, 10.0, srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.steps_taken, 100u);
  ASSERT_TRUE(g_node->command("hinge_motor", 0.3));  // a finite command still lands
  EXPECT_EQ(g_node->keyFigure("push.cmd"), 0.0);
}

// Huge finite commands are passed on (the scene format sets no range). Each either
// steps to a finite state or fails the step: one ERROR per failure however often
// ~step is called again, ~step answers "failed", nothing non-finite is published,
// and ~reset recovers.
TEST(MalformedTraffic, HugeCommandsStepOrFailOnce) {
  const double huge[] = {1e300, -1e300, DBL_MAX, -DBL_MAX, 1e308, 4.9e-324, -0.0};
  int failures = 0;
  for (const char* actuator : {"hinge_motor", "push"}) {
    for (const double value : huge) {
      SCOPED_TRACE(std::string(actuator) + " = " + std::to_string(value));
      ASSERT_TRUE(g_node->command(actuator, value));
      const int errors_before = g_watch->count(Log::ERROR, "step failed");
      nscd_sim::Step srv;
      ASSERT_TRUE(stepAnswers(20, 10.0, srv));
      if (srv.response.success) {
        EXPECT_EQ(srv.response.steps_taken, 20u);
        EXPECT_TRUE(std::isfinite(srv.response.sim_time));
      } else {
        ++failures;
        EXPECT_NE(srv.response.message.find("step failed at t="), std::string::npos) << srv.response.message;
        for (int k = 0; k < 5; ++k) {
          nscd_sim::Step again;
          ASSERT_TRUE(stepAnswers(10, 10.0, again));
          EXPECT_FALSE(again.response.success);
          EXPECT_EQ(again.response.steps_taken, 0u);
        }
        EXPECT_EQ(g_watch->waitFor(Log::ERROR, "step failed", errors_before + 1, 10.0), errors_before + 1);
        ros::WallDuration(0.5).sleep();
        EXPECT_EQ(g_watch->count(Log::ERROR, "step failed"), errors_before + 1) << "one failure, one ERROR";
      }
      ASSERT_TRUE(resetAnswers());
      ASSERT_TRUE(g_node->step(10)) << "stepping did not resume after ~reset";
    }
  }
  EXPECT_GE(failures, 1) << "1e308 N on the arm should overflow the state";
  EXPECT_EQ(g_watch->nonFinitePublished(), 0);
  EXPECT_GT(g_watch->figuresSeen(), 0);
}

// Commands on a topic with no actuator (a typo), on ~command (no actuator name) and
// nested below an actuator's topic, NaN, 1e308, -inf and 7 flooded at 1 kHz for 5 s
// while the node is stepped: every ~step answered within 5 s, the actuators'
// commands untouched, one warning for each misnamed topic (however long it stays).
TEST(MalformedTraffic, UnknownActuatorTopicFloodWarnsOnce) {
  ASSERT_TRUE(g_node->command("hinge_motor", 0.2));
  ASSERT_TRUE(g_node->command("push", 0.0));
  const int before = g_watch->count(Log::WARN, "but the scene has no actuator");
  ros::NodeHandle nh;
  std::vector<ros::Publisher> pubs = {nh.advertise<std_msgs::Float64>(nodeTopic("hinge_motr/command"), 10),
                                      nh.advertise<std_msgs::Float64>(nodeTopic("command"), 10),
                                      nh.advertise<std_msgs::Float64>(nodeTopic("hinge_motor/x/command"), 10)};
  std::atomic<bool> flooding{true};
  std::thread flood([&] {
    std_msgs::Float64 m;
    for (int i = 0; flooding; ++i) {
      m.data = (i % 4 == 0) ? NAN : i % 4 == 1 ? 1e308 : i % 4 == 2 ? -INFINITY : 7.0;
      for (ros::Publisher& p : pubs) p.publish(m);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(5.0);
  int calls = 0;
  while (ros::WallTime::now() < end) {
    nscd_sim::Step srv;
    EXPECT_TRUE(stepAnswers(10, 5.0, srv)) << "call " << calls;
    EXPECT_TRUE(srv.response.success) << srv.response.message;
    ++calls;
  }
  flooding = false;
  flood.join();
  EXPECT_GT(calls, 10);
  EXPECT_EQ(g_node->keyFigure("hinge_motor.cmd"), 0.2);
  EXPECT_EQ(g_node->keyFigure("push.cmd"), 0.0);
  // Checked every 2 s, each name warned once (docs/node.md): a warning for each of
  // the two typos, not repeated (~command is no actuator's topic: nothing to name).
  EXPECT_EQ(g_watch->waitFor(Log::WARN, "but the scene has no actuator", before + 2, 5.0) - before, 2);
  ros::WallDuration(4.5).sleep();  // two more checks, the topics still advertised
  EXPECT_EQ(g_watch->count(Log::WARN, "no actuator 'hinge_motr'"), 1);
  EXPECT_EQ(g_watch->count(Log::WARN, "no actuator 'hinge_motor/x'"), 1);
  EXPECT_EQ(g_watch->count(Log::WARN, "but the scene has no actuator") - before, 2);
}

// Many misnamed command topics at once: the node names the first 32 (over its
// life; the two of the flood above are among them) and then says once that it
// names no more: its memory of names stays bounded.
TEST(MalformedTraffic, ManyUnknownTopicsAreNamedUpToABound) {
  ros::NodeHandle nh;
  std::vector<ros::Publisher> pubs;
  for (int i = 0; i < 40; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "typo_%02d/command", i);
    pubs.push_back(nh.advertise<std_msgs::Float64>(nodeTopic(name), 1));
  }
  EXPECT_EQ(g_watch->waitFor(Log::WARN, "more command topics without an actuator", 1, 6.0), 1);
  ros::WallDuration(4.5).sleep();  // two more checks: nothing new
  EXPECT_EQ(g_watch->count(Log::WARN, "but the scene has no actuator"), 32);
  EXPECT_EQ(g_watch->count(Log::WARN, "more command topics without an actuator"), 1);
  nscd_sim::Step srv;
  ASSERT_TRUE(stepAnswers(5, 10.0, srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
}

// Storms of ~pause and ~reset, and ~step with count 0: every call answered, and
// the node ends where the last call put it.
TEST(MalformedTraffic, ServiceStormsAreAnswered) {
  for (int i = 0; i < 50; ++i) {
    std_srvs::SetBool pause;
    pause.request.data = i % 2 == 0;
    ASSERT_TRUE(nscd_test::callService(nodeTopic("pause"), pause, 5.0)) << "pause " << i;
    EXPECT_TRUE(pause.response.success) << pause.response.message;
  }
  ASSERT_TRUE(g_node->setPaused(true));
  for (int i = 0; i < 50; ++i) ASSERT_TRUE(resetAnswers()) << "reset " << i;
  nscd_sim::Step srv;
  ASSERT_TRUE(stepAnswers(0, 10.0, srv));
  EXPECT_TRUE(srv.response.success);
  EXPECT_EQ(srv.response.steps_taken, 1u) << "count 0 means 1";
  EXPECT_NEAR(srv.response.sim_time, 1e-3, 1e-15) << "one step of dt = 1 ms after the resets";
}

// Display parameters set to garbage while the node runs (rosparam set): one
// warning for them, the node keeps running, and nothing more once they are fixed.
TEST(MalformedTraffic, BadDisplayParametersWarnOnce) {
  const int before = g_watch->count(Log::WARN, "force_scale");
  ros::param::set(nodeTopic("force_scale"), std::string("abc"));
  ros::param::set(nodeTopic("ecc_scale"), -1.0);
  ros::param::set(nodeTopic("contact_labels"), std::string("maybe"));
  EXPECT_EQ(g_watch->waitFor(Log::WARN, "force_scale", before + 1, 5.0), before + 1);
  ros::WallDuration(3.0).sleep();  // read again every second: the same errors, no new warning
  EXPECT_EQ(g_watch->count(Log::WARN, "force_scale"), before + 1);
  ros::param::del(nodeTopic("force_scale"));
  ros::param::del(nodeTopic("ecc_scale"));
  ros::param::del(nodeTopic("contact_labels"));
  ros::WallDuration(2.0).sleep();
  EXPECT_EQ(g_watch->count(Log::WARN, "force_scale"), before + 1);
  nscd_sim::Step srv;
  ASSERT_TRUE(stepAnswers(5, 10.0, srv));
  EXPECT_TRUE(srv.response.success);
  EXPECT_EQ(g_watch->nonFinitePublished(), 0);
}

// ~step with a huge count (4294967295 steps would hold the node for hours): refused
// at once with one message naming the bound, nothing stepped, one warning for two
// refusals; the bound itself and the calls after it are served.
TEST(MalformedTraffic, HugeStepCountIsRefusedAndTheNodeKeepsServing) {
  ASSERT_TRUE(resetAnswers());
  nscd_sim::Step before;
  ASSERT_TRUE(stepAnswers(3, 10.0, before));
  const int warnings = g_watch->count(Log::WARN, "steps a call may take");
  for (const uint32_t count : {4294967295u, 100001u}) {
    SCOPED_TRACE(count);
    nscd_sim::Step srv;
    ASSERT_TRUE(stepAnswers(count, 10.0, srv));
    EXPECT_FALSE(srv.response.success);
    EXPECT_EQ(srv.response.steps_taken, 0u);
    EXPECT_EQ(srv.response.sim_time, before.response.sim_time) << "a refused call stepped";
    EXPECT_NE(srv.response.message.find(std::to_string(count)), std::string::npos) << srv.response.message;
    EXPECT_NE(srv.response.message.find("at most 100000 steps"), std::string::npos) << srv.response.message;
  }
  EXPECT_EQ(g_watch->waitFor(Log::WARN, "steps a call may take", warnings + 1, 5.0), warnings + 1);
  ros::WallDuration(0.5).sleep();
  EXPECT_EQ(g_watch->count(Log::WARN, "steps a call may take"), warnings + 1) << "one warning for both";
  std_srvs::SetBool pause;
  pause.request.data = true;
  ASSERT_TRUE(nscd_test::callService(nodeTopic("pause"), pause, 5.0));
  nscd_sim::Step after;
  ASSERT_TRUE(stepAnswers(7, 10.0, after));
  EXPECT_TRUE(after.response.success) << after.response.message;
  EXPECT_EQ(after.response.steps_taken, 7u);
}

int main(int argc, char** argv) {
  return nscd_test::runRosTestNode(argc, argv, "malformed_traffic_test", [] {
    g_watch = std::make_unique<NodeWatch>();
    g_node = std::make_unique<nscd_test::SteppedNode>();
    // The log is connected once a line the node writes now arrives (a reset's INFO).
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(60.0);
    while (g_watch->count(Log::INFO, "reset to the initial state") == 0 && ros::WallTime::now() < end) {
      resetAnswers();
      ros::WallDuration(0.2).sleep();
    }
    // The tests that count warnings fail then; this line says why.
    if (g_watch->count(Log::INFO, "reset to the initial state") == 0)
      std::fprintf(stderr, "malformed_traffic: the node's /rosout lines did not arrive within 60 s\n");
    const int result = RUN_ALL_TESTS();
    g_node.reset();
    g_watch.reset();
    return result;
  });
}
