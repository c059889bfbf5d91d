// rostest (actuator_markers.test): nscd_actuator_markers on the C-60, driven as RViz
// drives an interactive marker (InteractiveMarkerFeedback on its feedback topic:
// MOUSE_DOWN, POSE_UPDATEs, MOUSE_UP), against nscd_sim_node started paused and
// stepped with ~step. Checks the commands the drags publish, their clipping to the
// range (one warning per excursion), the marker text, and the breaker's response:
// the handle dragged to OFF opens C7, the probe pushed past the trip travel releases
// the latch, each at the same step as the engine run in-process with the same commands.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <std_msgs/Float64.h>
#include <std_srvs/Empty.h>
#include <visualization_msgs/InteractiveMarkerFeedback.h>
#include <visualization_msgs/InteractiveMarkerInit.h>
#include <visualization_msgs/InteractiveMarkerUpdate.h>
#include <visualization_msgs/Marker.h>

#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "ros_test_support.hpp"

namespace {

using visualization_msgs::InteractiveMarker;
using visualization_msgs::InteractiveMarkerControl;
using visualization_msgs::InteractiveMarkerFeedback;

const std::string kServer = "/nscd_actuator_markers";

// The ranges of config/c60_actuator_markers.yaml (loaded by the .test).
constexpr double kHandleMax = 1.3;   // rad
constexpr double kProbeMax = 0.004;  // m
constexpr double kProbeRate = 0.2;   // m/s, command_rate_limit of the .test
constexpr int kRestSteps = 200;      // 2 ms after a reset: at rest, latched

std::unique_ptr<nscd_test::SteppedNode> g_node;

// What the markers' node publishes: the commands, its warnings (from /rosout), and
// its markers as RViz sees them (update_full, then the updates and pose updates).
class Recorder {
 public:
  Recorder() {
    for (const char* a : {"handle", "probe"})
      subs_.push_back(nh_.subscribe<std_msgs::Float64>(
          nscd_test::nodeTopic(std::string(a) + "/command"), 100,
          [this, a](const std_msgs::Float64ConstPtr& m) {
            std::lock_guard<std::mutex> lock(mutex_);
            commands_[a == std::string("handle") ? 0 : 1].push_back(m->data);
          }));
    subs_.push_back(nh_.subscribe<rosgraph_msgs::Log>("/rosout", 100, [this](const rosgraph_msgs::LogConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (m->name == kServer && m->level == rosgraph_msgs::Log::WARN) warnings_.push_back(m->msg);
    }));
    subs_.push_back(nh_.subscribe<visualization_msgs::InteractiveMarkerInit>(
        kServer + "/update_full", 10, [this](const visualization_msgs::InteractiveMarkerInitConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          if (!markers_.empty()) return;  // RViz takes the init once
          for (const auto& im : m->markers) markers_[im.name] = im;
        }));
    subs_.push_back(nh_.subscribe<visualization_msgs::InteractiveMarkerUpdate>(
        kServer + "/update", 100, [this](const visualization_msgs::InteractiveMarkerUpdateConstPtr& u) {
          std::lock_guard<std::mutex> lock(mutex_);
          for (const auto& im : u->markers) markers_[im.name] = im;
          for (const auto& p : u->poses)
            if (markers_.count(p.name)) markers_[p.name].pose = p.pose;
        }));
  }
  ~Recorder() {
    for (auto& s : subs_) s.shutdown();
  }
  std::vector<double> commands(const std::string& a) {
    std::lock_guard<std::mutex> lock(mutex_);
    return commands_[a == "handle" ? 0 : 1];
  }
  std::vector<std::string> warnings() {
    std::lock_guard<std::mutex> lock(mutex_);
    return warnings_;
  }
  // The marker as last published (false if none yet).
  bool marker(const std::string& name, InteractiveMarker& out) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = markers_.find(name);
    if (it == markers_.end()) return false;
    out = it->second;
    return true;
  }
  // Waits until `a` has received `n` commands in all (wall timeout).
  bool waitCommands(const std::string& a, size_t n, double timeout = 10.0) {
    return waitFor([&] { return commands(a).size() >= n; }, timeout);
  }
  static bool waitFor(const std::function<bool()>& pred, double timeout) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
    while (ros::ok() && ros::WallTime::now() < end) {
      if (pred()) return true;
      ros::WallDuration(0.005).sleep();
    }
    return pred();
  }

 private:
  ros::NodeHandle nh_;
  std::mutex mutex_;
  std::vector<ros::Subscriber> subs_;
  std::vector<double> commands_[2];
  std::vector<std::string> warnings_;
  std::map<std::string, InteractiveMarker> markers_;
};

std::unique_ptr<Recorder> g_recorder;

// RViz's side of a drag: one client id, poses in the marker's frame.
class Mouse {
 public:
  Mouse() { pub_ = nh_.advertise<InteractiveMarkerFeedback>(kServer + "/feedback", 100); }
  void down(const InteractiveMarker& m, const std::string& control) { send(m, control, InteractiveMarkerFeedback::MOUSE_DOWN, m.pose); }
  void move(const InteractiveMarker& m, const std::string& control, const geometry_msgs::Pose& pose) {
    send(m, control, InteractiveMarkerFeedback::POSE_UPDATE, pose);
  }
  void up(const InteractiveMarker& m, const std::string& control, const geometry_msgs::Pose& pose) {
    send(m, control, InteractiveMarkerFeedback::MOUSE_UP, pose);
  }

 private:
  void send(const InteractiveMarker& m, const std::string& control, uint8_t type, const geometry_msgs::Pose& pose) {
    InteractiveMarkerFeedback f;
    f.header.frame_id = m.header.frame_id;
    f.header.stamp = ros::Time::now();
    f.client_id = "/rviz_test/InteractiveMarkers";
    f.marker_name = m.name;
    f.control_name = control;
    f.event_type = type;
    f.pose = pose;
    ASSERT_TRUE(nscd_test::publishWhenConnected(pub_, f)) << "the markers' node does not listen to feedback";
    ros::WallDuration(0.02).sleep();  // RViz's pace, and the order kept
  }
  ros::NodeHandle nh_;
  ros::Publisher pub_;
};

std::unique_ptr<Mouse> g_mouse;

// The markers as first published (latched update_full), kept: the drags start from
// their poses at command 0.
std::vector<InteractiveMarker> initialMarkers() {
  static std::vector<InteractiveMarker> first;
  if (first.empty()) {
    auto init = nscd_test::waitForMessage<visualization_msgs::InteractiveMarkerInit>(kServer + "/update_full", 20.0);
    if (init) first = init->markers;
  }
  return first;
}

const InteractiveMarker* find(const std::vector<InteractiveMarker>& ms, const std::string& name) {
  for (const auto& m : ms)
    if (m.name == name) return &m;
  return nullptr;
}

const InteractiveMarkerControl* control(const InteractiveMarker& m, const std::string& name) {
  for (const auto& c : m.controls)
    if (c.name == name) return &c;
  return nullptr;
}

// The marker's text, its lines (one text marker each) joined by newlines.
std::string text(const InteractiveMarker& m) {
  const InteractiveMarkerControl* c = control(m, "text");
  std::string s;
  for (size_t i = 0; c && i < c->markers.size(); ++i) s += (i ? "\n" : "") + c->markers[i].text;
  return s;
}

// The marker `name` as last published once it satisfies `pred` (null on timeout).
std::unique_ptr<InteractiveMarker> waitMarker(const std::string& name,
                                              const std::function<bool(const InteractiveMarker&)>& pred,
                                              double timeout = 10.0) {
  InteractiveMarker m;
  if (!Recorder::waitFor([&] { return g_recorder->marker(name, m) && pred(m); }, timeout)) return {};
  return std::make_unique<InteractiveMarker>(m);
}

// `pose` turned by `angle` about world z (J1's axis) about its position.
geometry_msgs::Pose turned(const geometry_msgs::Pose& pose, double angle) {
  const Eigen::Quaterniond q0(pose.orientation.w, pose.orientation.x, pose.orientation.y, pose.orientation.z);
  const Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ())) * q0;
  geometry_msgs::Pose p = pose;
  p.orientation.w = q.w();
  p.orientation.x = q.x();
  p.orientation.y = q.y();
  p.orientation.z = q.z();
  return p;
}

// `pose` moved by `d` along world x (the probe's bore).
geometry_msgs::Pose moved(const geometry_msgs::Pose& pose, double d) {
  geometry_msgs::Pose p = pose;
  p.position.x += d;
  return p;
}

bool hasContact(const nscd_sim::ContactArray& m, const std::string& name) {
  for (const auto& c : m.contacts)
    if (c.name == name) return true;
  return false;
}
bool latchClosed(const nscd_sim::ContactArray& m) {
  for (const auto& c : m.contacts)
    if (c.name == "C4" || c.name.rfind("C4_", 0) == 0) return true;
  return false;
}
bool c7Closed(const nscd::Simulator& sim) {
  for (const nscd::ContactReport& r : sim.contactPoints())
    if (!r.clearance && sim.model().contacts[r.source].name == "C7") return true;
  return false;
}
bool latchClosed(const nscd::Simulator& sim) {
  for (const nscd::ContactReport& r : sim.contactPoints()) {
    if (r.clearance) continue;
    const std::string& n = sim.model().contacts[r.source].name;
    if (n == "C4" || n.rfind("C4_", 0) == 0) return true;
  }
  return false;
}

// Steps the node in chunks until `pred` holds on ~contacts (null after max_steps).
nscd_sim::ContactArrayConstPtr stepUntil(uint32_t chunk, uint32_t max_steps,
                                         const std::function<bool(const nscd_sim::ContactArray&)>& pred) {
  for (uint32_t taken = 0; taken < max_steps; taken += chunk) {
    auto m = g_node->step(chunk, 60.0);
    if (!m) return {};
    if (pred(*m)) return m;
  }
  return {};
}

// The same in-process, the scene's own schedules applied as the node applies them
// and `before_step` setting the commands; the sim time at which `pred` first holds
// at a chunk's end (NaN after max_steps).
double inProcessUntil(nscd::Simulator& sim, uint32_t chunk, uint32_t max_steps,
                      const std::function<void(nscd::Simulator&)>& before_step,
                      const std::function<bool(const nscd::Simulator&)>& pred) {
  for (uint32_t taken = 0; taken < max_steps; taken += chunk) {
    for (uint32_t i = 0; i < chunk; ++i) {
      before_step(sim);
      sim.step();
    }
    if (pred(sim)) return sim.state().t;
  }
  return NAN;
}

// ~key_figures of sim time `t` (after a ~step): the value of `name` (NaN on timeout).
double figureAt(const std::string& name, double t) {
  auto m = nscd_test::waitForMessage<nscd_sim::KeyFigures>(
      nscd_test::nodeTopic("key_figures"), [t](const nscd_sim::KeyFigures& k) { return k.sim_time == t; }, 10.0);
  if (!m) return NAN;
  for (size_t i = 0; i < m->names.size(); ++i)
    if (m->names[i] == name) return m->values[i];
  return NAN;
}

}  // namespace

// Both markers, in the world frame: the handle's ring about J1 at its pivot, the
// probe's arrows at its centre of mass; each with its text.
TEST(ActuatorMarkers, StandAtTheActuatedBodies) {
  const auto markers = initialMarkers();
  const nscd::Model model = nscd::loadScene(nscd_test::sceneParam());
  const InteractiveMarker* handle = find(markers, "handle");
  const InteractiveMarker* probe = find(markers, "probe");
  ASSERT_TRUE(handle && probe) << "no handle and probe markers on " << kServer << "/update_full";
  EXPECT_EQ(handle->header.frame_id, "world");
  EXPECT_NEAR(handle->pose.position.x, -0.0161, 1e-12);
  EXPECT_NEAR(handle->pose.position.y, 0.01, 1e-12);
  EXPECT_NEAR(handle->pose.position.z, 0.00555, 1e-12);
  ASSERT_TRUE(control(*handle, "rotate"));
  EXPECT_EQ(control(*handle, "rotate")->interaction_mode, InteractiveMarkerControl::ROTATE_AXIS);
  const nscd::Vec3 p = model.bodies[model.findBody("probe")].initial_pose.p;
  EXPECT_EQ(probe->header.frame_id, "world");
  EXPECT_NEAR(probe->pose.position.x, p.x(), 1e-12);
  EXPECT_NEAR(probe->pose.position.y, p.y(), 1e-12);
  EXPECT_NEAR(probe->pose.position.z, p.z(), 1e-12);
  ASSERT_TRUE(control(*probe, "slide"));
  EXPECT_EQ(control(*probe, "slide")->interaction_mode, InteractiveMarkerControl::MOVE_AXIS);
  EXPECT_EQ(text(*handle).rfind("handle 0.000 rad", 0), 0u) << text(*handle);
  // The text of config/c60_actuator_markers.yaml's text_offset [-0.016, 0]: 16 mm left
  // of the pivot on the screen, which is +y in a view-facing control (seen in RViz).
  const InteractiveMarkerControl* label = control(*handle, "text");
  ASSERT_TRUE(label && !label->markers.empty());
  EXPECT_EQ(label->orientation_mode, InteractiveMarkerControl::VIEW_FACING);
  EXPECT_NEAR(label->markers[0].pose.position.y, 0.016, 1e-12);
  EXPECT_NEAR(label->markers[0].pose.position.z, 0.0, 1e-12);
  EXPECT_EQ(text(*probe).rfind("probe 0.000 mm", 0), 0u) << text(*probe);
}

// Paused, the node's status text says so instead of the rtf (0 while paused).
TEST(ActuatorMarkers, StatusSaysPaused) {
  auto status = nscd_test::waitForMessage<visualization_msgs::Marker>(nscd_test::nodeTopic("status"), 10.0);
  ASSERT_TRUE(status);
  EXPECT_NE(status->text.find("ms   paused"), std::string::npos) << status->text;
  EXPECT_EQ(status->text.find("rtf"), std::string::npos) << status->text;
}

// The handle dragged ON -> OFF (0.4, 0.8, 1.2 rad): those commands are published;
// C7 opens at the step an in-process engine opens it with the same command; the
// marker text shows the command, the effort and C7.fn of the node's key figures.
TEST(ActuatorMarkers, HandleDraggedToOffOpensC7) {
  const auto markers = initialMarkers();
  const InteractiveMarker* handle = find(markers, "handle");
  ASSERT_TRUE(handle);
  auto rest = g_node->step(kRestSteps, 60.0);
  ASSERT_TRUE(rest);
  ASSERT_TRUE(hasContact(*rest, "C7"));

  g_mouse->down(*handle, "rotate");
  for (double a : {0.4, 0.8, 1.2}) g_mouse->move(*handle, "rotate", turned(handle->pose, a));
  g_mouse->up(*handle, "rotate", turned(handle->pose, 1.2));
  ASSERT_TRUE(g_recorder->waitCommands("handle", 3));
  const std::vector<double> sent = g_recorder->commands("handle");
  ASSERT_EQ(sent.size(), 3u);
  EXPECT_NEAR(sent[0], 0.4, 1e-12);
  EXPECT_NEAR(sent[1], 0.8, 1e-12);
  EXPECT_NEAR(sent[2], 1.2, 1e-12);
  // The node holds the last one (its command queue is 1 long: the others may be dropped).
  ASSERT_TRUE(Recorder::waitFor([&] { return g_node->keyFigure("handle.cmd") == sent[2]; }, 10.0))
      << "the node does not show the dragged command: handle.cmd " << g_node->keyFigure("handle.cmd");

  auto open = stepUntil(10, 1200, [](const nscd_sim::ContactArray& m) { return !hasContact(m, "C7"); });
  ASSERT_TRUE(open) << "C7 did not open within 12 ms of the drag to OFF";

  nscd::Simulator sim(nscd::loadScene(nscd_test::sceneParam()));
  const int a = sim.model().findActuator("handle");
  const auto own = nscd::bindCommandSchedules({}, sim.model());
  const double dt = sim.model().settings.dt;
  auto scheduled = [&](nscd::Simulator& s) { nscd::applySchedules(own, s.state().t + dt, s); };
  for (int i = 0; i < kRestSteps; ++i) {
    scheduled(sim);
    sim.step();
  }
  sim.setCommand(a, sent[2]);
  EXPECT_EQ(open->sim_time, inProcessUntil(sim, 10, 1200, scheduled, [](const nscd::Simulator& s) { return !c7Closed(s); }))
      << "the node and the engine open C7 at different steps";

  // The text: the command, the effort and C7.fn the node published for this state.
  const double effort = figureAt("handle.effort", open->sim_time);
  const double c7 = figureAt("C7.fn", open->sim_time);
  ASSERT_TRUE(std::isfinite(effort) && std::isfinite(c7));
  char want[160];
  std::snprintf(want, sizeof want, "handle 1.200 rad\neffort %.3g N m   C7.fn %.3g", effort, c7);
  auto shown = waitMarker("handle", [&](const InteractiveMarker& m) { return text(m) == want; });
  ASSERT_TRUE(shown) << "no handle text \"" << want << "\"";
  const InteractiveMarkerControl* lines = control(*shown, "text");
  ASSERT_TRUE(lines && lines->markers.size() == 2u);
  EXPECT_LT(lines->markers[1].pose.position.z, lines->markers[0].pose.position.z) << "lines go down";
}

// Past the range: the command is clipped to it, with one warning per excursion; the
// marker goes back to the range's end.
TEST(ActuatorMarkers, OutOfRangeIsClippedWithOneWarning) {
  const auto markers = initialMarkers();
  const InteractiveMarker* handle = find(markers, "handle");
  ASSERT_TRUE(handle);
  const size_t before = g_recorder->commands("handle").size();
  const size_t warned = g_recorder->warnings().size();
  g_mouse->down(*handle, "rotate");
  for (double a : {1.25, 1.6, 2.0, 2.4}) g_mouse->move(*handle, "rotate", turned(handle->pose, a));
  ASSERT_TRUE(g_recorder->waitCommands("handle", before + 4));
  std::vector<double> sent = g_recorder->commands("handle");
  EXPECT_NEAR(sent[before], 1.25, 1e-12);
  for (size_t k = before + 1; k < before + 4; ++k) EXPECT_EQ(sent[k], kHandleMax) << "not clipped";
  ASSERT_TRUE(Recorder::waitFor([&] { return g_recorder->warnings().size() > warned; }, 5.0));
  ros::WallDuration(0.5).sleep();  // a second warning would have arrived by now
  std::vector<std::string> w = g_recorder->warnings();
  ASSERT_EQ(w.size(), warned + 1) << "one warning for one excursion";
  // Warned when the excursion began.
  EXPECT_NE(w.back().find("handle command 1.6 rad is outside its range [0, 1.3]: clipped to 1.3"),
            std::string::npos) << w.back();
  // Back in range, then below it: a new excursion, a new warning.
  g_mouse->move(*handle, "rotate", turned(handle->pose, 0.9));
  g_mouse->move(*handle, "rotate", turned(handle->pose, -0.3));
  g_mouse->up(*handle, "rotate", turned(handle->pose, -0.3));
  ASSERT_TRUE(g_recorder->waitCommands("handle", before + 6));
  sent = g_recorder->commands("handle");
  EXPECT_NEAR(sent[before + 4], 0.9, 1e-12);
  EXPECT_EQ(sent[before + 5], 0.0);
  ASSERT_TRUE(Recorder::waitFor([&] { return g_recorder->warnings().size() == warned + 2; }, 5.0))
      << "no warning for the second excursion";
  // After the drag the marker stands at the clipped command, 0 (its initial pose).
  const double yaw0 = nscd_test::yawOf(handle->pose.orientation);
  auto back = waitMarker("handle", [&](const InteractiveMarker& m) {
    return std::abs(nscd_test::yawOf(m.pose.orientation) - yaw0) < 1e-9;
  });
  EXPECT_TRUE(back) << "the marker did not return into the range";
}

// The probe, 2 ms after ~reset: dragged to 1 mm, short of the trip travel, it follows at
// the node's rate limit (0.2 m/s) and touches the bar, but the latch holds; dragged
// on to 3 mm, it releases the latch and C7 opens, at the steps the engine gives
// in-process with the same rate-limited commands.
TEST(ActuatorMarkers, ProbePushedPastTheTripTravelReleasesTheLatch) {
  std_srvs::Empty reset;
  ASSERT_TRUE(nscd_test::callService(nscd_test::nodeTopic("reset"), reset));
  auto start = g_node->step(kRestSteps, 60.0);  // at rest, latched
  ASSERT_TRUE(start);
  ASSERT_TRUE(latchClosed(*start));
  const auto markers = initialMarkers();
  const InteractiveMarker* probe = find(markers, "probe");
  ASSERT_TRUE(probe);
  const size_t before = g_recorder->commands("probe").size();

  g_mouse->down(*probe, "slide");
  g_mouse->move(*probe, "slide", moved(probe->pose, 0.0005));
  g_mouse->move(*probe, "slide", moved(probe->pose, 0.001));
  g_mouse->up(*probe, "slide", moved(probe->pose, 0.001));
  ASSERT_TRUE(g_recorder->waitCommands("probe", before + 2));
  std::vector<double> sent = g_recorder->commands("probe");
  EXPECT_NEAR(sent[before], 0.0005, 1e-12);
  EXPECT_NEAR(sent[before + 1], 0.001, 1e-12);
  const double short_travel = sent[before + 1];
  // The text shows the command and where the node is: 0 until stepped.
  EXPECT_TRUE(waitMarker("probe", [](const InteractiveMarker& m) { return text(m).rfind("probe 1.000 mm (now 0.000)", 0) == 0; }))
      << "the probe's text does not show the command and the travel";

  // At 0.2 m/s the probe needs 500 steps (5 ms) for 1 mm: half way after 250.
  const double dt = nscd::loadScene(nscd_test::sceneParam()).settings.dt;
  const double per_step = kProbeRate * dt;
  auto half = g_node->step(250, 60.0);
  ASSERT_TRUE(half);
  EXPECT_NEAR(figureAt("probe.cmd", half->sim_time), 250 * per_step, 1e-12) << "not at the rate limit";
  // There, and held 2.5 ms: the latch holds, C7 stays closed.
  auto held = g_node->step(500, 60.0);
  ASSERT_TRUE(held);
  EXPECT_NEAR(figureAt("probe.cmd", held->sim_time), short_travel, 1e-15);
  EXPECT_TRUE(latchClosed(*held)) << "released at 1 mm of travel";
  EXPECT_TRUE(hasContact(*held, "C7"));
  std::printf("at 1 mm of probe travel: TRIP %s, C7.fn %.3f N\n", hasContact(*held, "TRIP") ? "touching" : "open",
              figureAt("C7.fn", held->sim_time));

  // On to 3 mm (past the trip travel, about 1.5 mm).
  g_mouse->down(*probe, "slide");
  g_mouse->move(*probe, "slide", moved(probe->pose, 0.002));
  g_mouse->move(*probe, "slide", moved(probe->pose, 0.003));
  g_mouse->up(*probe, "slide", moved(probe->pose, 0.003));
  ASSERT_TRUE(g_recorder->waitCommands("probe", before + 4));
  sent = g_recorder->commands("probe");
  EXPECT_NEAR(sent[before + 3], 0.003, 1e-12);
  const double far_travel = sent[before + 3];
  auto released = stepUntil(10, 1500, [](const nscd_sim::ContactArray& m) { return !latchClosed(m); });
  ASSERT_TRUE(released) << "the latch did not release with the probe dragged to 3 mm";
  const double travel = figureAt("probe.cmd", released->sim_time);
  std::printf("latch released at t = %.3f ms, probe travel %.4f mm\n", 1e3 * released->sim_time, 1e3 * travel);
  EXPECT_GT(travel, short_travel);
  EXPECT_LT(travel, far_travel);
  auto open = stepUntil(10, 1000, [](const nscd_sim::ContactArray& m) { return !hasContact(m, "C7"); });
  EXPECT_TRUE(open) << "C7 did not open after the release";

  // In-process: the scene's schedules as the node applies them, the probe's command
  // moved towards the dragged one by at most rate * dt a step, as the node moves it.
  nscd::Simulator sim(nscd::loadScene(nscd_test::sceneParam()));
  const int a = sim.model().findActuator("probe");
  const auto own = nscd::bindCommandSchedules({}, sim.model());
  double target = 0;
  bool dragged = false;
  auto drive = [&](nscd::Simulator& s) {
    nscd::applySchedules(own, s.state().t + dt, s);
    if (!dragged) return;
    const double now = s.command(a);
    s.setCommand(a, now + std::clamp(target - now, -per_step, per_step));
  };
  for (int i = 0; i < kRestSteps; ++i) {  // before the drag
    drive(sim);
    sim.step();
  }
  dragged = true;
  target = short_travel;
  for (int i = 0; i < 750; ++i) {
    drive(sim);
    sim.step();
  }
  target = far_travel;
  EXPECT_EQ(released->sim_time,
            inProcessUntil(sim, 10, 1500, drive, [](const nscd::Simulator& s) { return !latchClosed(s); }))
      << "the node and the engine release the latch at different steps";
}

int main(int argc, char** argv) {
  return nscd_test::runRosTestNode(argc, argv, "actuator_markers_test", [] {
    g_node = std::make_unique<nscd_test::SteppedNode>();
    g_recorder = std::make_unique<Recorder>();
    g_mouse = std::make_unique<Mouse>();
    const int result = RUN_ALL_TESTS();
    g_mouse.reset();
    g_recorder.reset();
    g_node.reset();
    return result;
  });
}
