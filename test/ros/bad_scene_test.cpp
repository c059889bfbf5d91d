// rostest: nscd_sim_node refuses bad input with exit status 2 and one line that
// names the file and line (scene) or the parameter (settings). The test runs the
// node binary (NSCD_NODE_EXE) against the master rostest started.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>

namespace {

struct RunResult {
  int status = -1;  // exit status, or -1 if it did not exit by itself
  std::string output;  // stdout and stderr
};

// Runs the node with extra ROS arguments (a fresh __name each time: private
// parameters given as _key:=value stay on the master); kills it after `timeout` seconds.
RunResult runNode(const std::vector<std::string>& args, double timeout = 15.0,
                  const char* exe = NSCD_NODE_EXE) {
  int fds[2];
  if (pipe(fds) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(fds[1], 1);
    dup2(fds[1], 2);
    close(fds[0]);
    close(fds[1]);
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(exe));
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(exe, argv.data());
    _exit(127);
  }
  close(fds[1]);
  fcntl(fds[0], F_SETFL, O_NONBLOCK);
  RunResult r;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  int wstatus = 0;
  bool exited = false;
  char buf[4096];
  while (true) {
    ssize_t n;
    while ((n = read(fds[0], buf, sizeof buf)) > 0) r.output.append(buf, n);
    if (exited) break;
    if (waitpid(pid, &wstatus, WNOHANG) == pid) {
      exited = true;
      continue;  // drain the pipe once more
    }
    if (std::chrono::steady_clock::now() > end) {
      kill(pid, SIGKILL);
      waitpid(pid, &wstatus, 0);
      close(fds[0]);
      r.output += "\n[killed after timeout]";
      return r;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  close(fds[0]);
  if (WIFEXITED(wstatus)) r.status = WEXITSTATUS(wstatus);
  return r;
}

const std::string kSource = NSCD_SOURCE_DIR;

}  // namespace

TEST(BadScene, InvalidSceneExitsWithFileAndLine) {
  const RunResult r = runNode({"__name:=bad_scene_file", "_scene:=" + kSource +
                                                             "/test/ros/bad_scene.urdf"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("FATAL"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("bad_scene.urdf:"), std::string::npos) << r.output;
  // "FILE:LINE:" with a line number
  const size_t at = r.output.find("bad_scene.urdf:");
  ASSERT_NE(at, std::string::npos);
  EXPECT_TRUE(std::isdigit(static_cast<unsigned char>(r.output[at + 15]))) << r.output;
}

TEST(BadScene, MissingFileExits) {
  const RunResult r = runNode({"__name:=missing_scene_file", "_scene:=/nonexistent/scene.urdf"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/scene.urdf"), std::string::npos) << r.output;
}

TEST(BadScene, NoSceneExits) {
  // No ~scene and no robot_description on this master.
  const RunResult r = runNode({"__name:=no_scene"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("robot_description"), std::string::npos) << r.output;
}

TEST(BadScene, BadSettingParameterExits) {
  const RunResult r = runNode({"__name:=bad_setting",
                               "_scene:=" + kSource + "/urdf/ball.urdf", "_dt:=-1.0"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("dt"), std::string::npos) << r.output;
}

TEST(BadScene, BadNodeParameterExits) {
  const RunResult r = runNode({"__name:=bad_node_param",
                               "_scene:=" + kSource + "/urdf/ball.urdf", "_publish_rate:=0"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("publish_rate"), std::string::npos) << r.output;
}

// ~scene of the wrong type says so (not "no scene").
TEST(BadScene, SceneParameterOfWrongTypeExits) {
  const RunResult r = runNode({"__name:=scene_int", "_scene:=42"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("expected a string"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("got an integer"), std::string::npos) << r.output;
}

// A scene that loads but cannot be assembled (two hinges on one body, 1 m apart):
// one FATAL line that names the file once.
TEST(BadScene, AssemblyFailureNamesTheFileOnce) {
  const std::string file = kSource + "/test/ros/assembly_fails.urdf";
  const RunResult r = runNode({"__name:=assembly_fails", "_scene:=" + file});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("assembly failed"), std::string::npos) << r.output;
  const size_t first = r.output.find(file);
  ASSERT_NE(first, std::string::npos) << r.output;
  EXPECT_EQ(r.output.find(file, first + 1), std::string::npos) << "file named twice: " << r.output;
}

// A status-text figure the scene does not have.
TEST(BadScene, UnknownOverlayFigureExits) {
  const RunResult r = runNode({"__name:=bad_overlay", "_scene:=" + kSource + "/test/ros/actuated_pendulum.urdf",
                               "_overlay_figures:=[nosuch.fn]"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("unknown figure 'nosuch.fn'"), std::string::npos) << r.output;
}

// A schedule for an actuator the scene does not have, and a malformed one.
TEST(BadScene, BadScheduleExits) {
  const std::string pendulum = "_scene:=" + kSource + "/test/ros/actuated_pendulum.urdf";
  RunResult r = runNode({"__name:=bad_schedule_name", pendulum, "_schedule:=nosuch=0:0,1:1"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("no actuator 'nosuch'"), std::string::npos) << r.output;
  r = runNode({"__name:=bad_schedule_text", pendulum, "_schedule:=hinge_motor=0:0,oops"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("schedule"), std::string::npos) << r.output;
}

// ~command_rate_limit naming an actuator the scene does not have, or a rate that is
// not a positive number.
TEST(BadScene, BadCommandRateLimitExits) {
  const std::string pendulum = "_scene:=" + kSource + "/test/ros/actuated_pendulum.urdf";
  XmlRpc::XmlRpcValue limits;
  limits["nosuch"] = 0.2;
  ros::param::set("/bad_rate_name/command_rate_limit", limits);
  RunResult r = runNode({"__name:=bad_rate_name", pendulum});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("command_rate_limit: no actuator 'nosuch'"), std::string::npos) << r.output;
  limits.clear();
  limits["hinge_motor"] = -1.0;
  ros::param::set("/bad_rate_value/command_rate_limit", limits);
  r = runNode({"__name:=bad_rate_value", pendulum});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("command_rate_limit/hinge_motor: expected a positive number"), std::string::npos)
      << r.output;
}

// nscd_actuator_markers refuses what it cannot drive, with one FATAL line and exit 2:
// no ~actuators, an unknown actuator, a torque actuator, an empty range.
TEST(BadScene, ActuatorMarkersRefuseBadParameters) {
  const std::string c60 = "_scene:=" + kSource + "/urdf/c60.urdf";
  auto run = [&](const std::string& name, const char* actuator, double min, double max) {
    if (actuator) {
      XmlRpc::XmlRpcValue range, actuators;
      range["min"] = min;
      range["max"] = max;
      actuators[actuator] = range;
      ros::param::set("/" + name + "/actuators", actuators);
    }
    return runNode({"__name:=" + name, c60}, 15.0, NSCD_MARKERS_EXE);
  };
  RunResult r = run("markers_none", nullptr, 0, 0);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("actuators: expected {NAME: {min: MIN, max: MAX}"), std::string::npos) << r.output;
  r = run("markers_unknown", "handel", 0, 1);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("no actuator 'handel'"), std::string::npos) << r.output;
  r = run("markers_torque", "bar_seating", 0, 1);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("'bar_seating' is a torque actuator"), std::string::npos) << r.output;
  r = run("markers_range", "handle", 1.3, 0);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("min must be below max"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("FATAL"), std::string::npos) << r.output;
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "bad_scene_test");
  return RUN_ALL_TESTS();
}
