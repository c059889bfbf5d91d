// State files (include/nscd_sim/state_file.hpp): a run saved to a file, read back
// on a fresh simulator and continued is bit-identical to the run that never
// stopped, under fixed and adaptive steps; every kind of bad file is refused
// with its own "FILE:LINE: what" and leaves the simulator as it was.
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/key_figures.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/scheduled_step.hpp"
#include "nscd_sim/simulator.hpp"
#include "nscd_sim/state_file.hpp"
#include "test_support.hpp"

using namespace nscd;

namespace {

const char* kProbe = "probe=0:0,0.0007:0,0.0207:0.004";

Model loadModel(const std::string& scene, const std::vector<SettingOverride>& overrides = {}) {
  return loadScene(nscd_test::scenePath(scene), overrides);
}

bool sameBits(const double* a, const double* b, size_t n) { return n == 0 || std::memcmp(a, b, n * sizeof(double)) == 0; }
bool sameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && sameBits(a.data(), b.data(), a.size());
}

// Every field, bit for bit (a NaN ring hint equals the same NaN).
void expectSameState(const State& a, const State& b, const std::string& where) {
  EXPECT_TRUE(sameBits(&a.t, &b.t, 1)) << where << ": t " << a.t << " vs " << b.t;
  ASSERT_EQ(a.bodies.size(), b.bodies.size()) << where;
  for (size_t i = 0; i < a.bodies.size(); ++i) {
    const BodyState &x = a.bodies[i], &y = b.bodies[i];
    EXPECT_TRUE(sameBits(x.x.data(), y.x.data(), 3) && sameBits(x.q.coeffs().data(), y.q.coeffs().data(), 4) &&
                sameBits(x.v.data(), y.v.data(), 3) && sameBits(x.w.data(), y.w.data(), 3))
        << where << ": body " << i;
  }
  EXPECT_TRUE(sameBits(a.commands, b.commands)) << where << ": commands";
  EXPECT_TRUE(sameBits(a.prev_commands, b.prev_commands)) << where << ": prev_commands";
  ASSERT_EQ(a.warm.size(), b.warm.size()) << where;
  for (size_t i = 0; i < a.warm.size(); ++i)
    EXPECT_TRUE(sameBits(a.warm[i].data(), b.warm[i].data(), 3)) << where << ": warm " << i;
  EXPECT_EQ(a.warm_valid, b.warm_valid) << where;
  EXPECT_TRUE(sameBits(a.warm_bilateral, b.warm_bilateral)) << where << ": bilateral";
  EXPECT_TRUE(sameBits(a.ring_hint, b.ring_hint)) << where << ": ring_hint";
  EXPECT_TRUE(sameBits(a.joint_position, b.joint_position)) << where << ": joint_position";
  EXPECT_TRUE(sameBits(&a.step_next, &b.step_next, 1)) << where << ": step_next";
  EXPECT_TRUE(sameBits(&a.step_error, &b.step_error, 1)) << where << ": step_error";
}

// nscd_run's loop: steps first+1 .. first+n on the probe schedule (fixed: step k
// ends at k dt; adaptive: steps cut at `until`).
void run(Simulator& sim, const std::vector<BoundSchedule>& schedules, long first, long n, double until) {
  for (long k = first + 1; k <= first + n; ++k) {
    prepareScheduledStep(sim, schedules, k, until);
    ASSERT_NE(sim.step(), StepStatus::NonFinite);
  }
}

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "nscd_state_file_" + name + "_" + std::to_string(::getpid());
}

std::string readAll(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

void writeAll(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f << text;
}

// The body and the checksum line the file format ends with.
std::string withChecksum(const std::string& body) { return body + stateChecksumLine(body); }

std::string withoutChecksum(const std::string& text) {
  return text.substr(0, text.rfind("checksum "));
}

// The message readStateFile throws for `path` ("" if none).
std::string readError(const std::string& path, const Simulator& sim) {
  try {
    readStateFile(path, sim);
  } catch (const StateFileError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// The C-60 during its trip (probe moving, latch loaded) at fixed steps, and the
// clearance pendulum and the C-60 under adaptive steps (the controller's memory
// step_next/step_error is in the file): 1 run straight through vs saved at step
// 300, read by another simulator and continued.
TEST(StateFile, SaveLoadContinueIsBitIdentical) {
  struct Case {
    std::string scene;
    std::vector<SettingOverride> overrides;
    long before, after;
  };
  const std::vector<SettingOverride> adaptive = {{"step_control", "adaptive", "test"}, {"rtol", "1e-3", "test"},
                                                 {"atol", "1e-6", "test"}};
  const std::vector<Case> cases = {{"urdf/c60.urdf", {}, 300, 300},
                                   {"urdf/clearance_pendulum.urdf", adaptive, 200, 200},
                                   {"urdf/c60.urdf", adaptive, 40, 40}};
  for (const Case& c : cases) {
    const std::string where = c.scene + (c.overrides.empty() ? " fixed" : " adaptive");
    const double until = 0.0207;
    Simulator straight(loadModel(c.scene, c.overrides));
    const std::vector<BoundSchedule> schedules =
        straight.model().findActuator("probe") >= 0 ? bindCommandSchedules({kProbe}, straight.model())
                                                    : std::vector<BoundSchedule>{};
    applySchedules(schedules, 0.0, straight);
    run(straight, schedules, 0, c.before, until);
    const std::string path = tempPath("bitwise");
    writeStateFile(path, straight, "test: " + where);
    const State saved = straight.state();
    run(straight, schedules, c.before, c.after, until);

    Simulator resumed(loadModel(c.scene, c.overrides));
    const State read = readStateFile(path, resumed);
    expectSameState(read, saved, where + ", as read");
    resumed.setState(read);
    const long first = std::llround(read.t / resumed.model().settings.dt);  // fixed steps: the step clock
    if (c.overrides.empty()) EXPECT_EQ(first, c.before);
    run(resumed, schedules, first, c.after, until);
    expectSameState(resumed.state(), straight.state(), where + ", continued");
    EXPECT_GT(resumed.state().t, saved.t);
    std::remove(path.c_str());
  }
}

// A fresh simulator's state (ring hints NaN: none yet) reads back as it was, and
// loadStateFile puts it in place.
TEST(StateFile, InitialStateRoundTrips) {
  Simulator sim(loadModel("urdf/clearance_pendulum.urdf"));
  const State initial = sim.state();
  bool nan_hint = false;
  for (double h : initial.ring_hint) nan_hint = nan_hint || std::isnan(h);
  EXPECT_TRUE(nan_hint) << "the test needs a NaN ring hint";
  const std::string path = tempPath("initial");
  writeStateFile(path, sim);
  Simulator other(loadModel("urdf/clearance_pendulum.urdf"));
  for (int i = 0; i < 20; ++i) other.step();
  loadStateFile(path, other);
  expectSameState(other.state(), initial, "initial");
  std::remove(path.c_str());
}

// Each kind of bad file, its message, and the simulator untouched.
TEST(StateFile, BadFilesAreRefusedWithTheirLine) {
  Simulator c60(loadModel("urdf/c60.urdf"));
  Simulator pendulum(loadModel("urdf/clearance_pendulum.urdf"));
  for (int i = 0; i < 30; ++i) c60.step();
  const State before = c60.state();
  const std::string good = tempPath("good"), bad = tempPath("bad");
  writeStateFile(good, c60);
  const std::string text = readAll(good);
  EXPECT_EQ(readError(good, c60), "");

  struct BadFile {
    std::string what, text, message;
  };
  std::vector<BadFile> files;
  writeStateFile(bad, pendulum);
  files.push_back({"another scene", readAll(bad), bad + ":2: the state was written for another scene: "});
  files.push_back({"truncated in a line", text.substr(0, text.size() / 2), "the file ends inside this line (truncated)"});
  const size_t cut = text.rfind("\nwarm ") + 1;
  files.push_back({"truncated at a line", text.substr(0, cut), "the file ends before its 'checksum' line (truncated)"});
  std::string damaged = text;
  const size_t digit = damaged.find("body 3 ") + 12;
  damaged[digit] = damaged[digit] == '7' ? '8' : '7';
  files.push_back({"damaged", damaged, "the checksum differs: the file was changed or damaged after it was written"});
  // Well-formed files (their checksum right) that say something impossible.
  std::string body = withoutChecksum(text);
  auto replaceWord = [](std::string s, const std::string& line_key, int word, const std::string& by) {
    const size_t a = s.find("\n" + line_key + " ") + 1;
    size_t b = a;
    for (int i = 0; i < word; ++i) b = s.find(' ', b) + 1;
    const size_t e = s.find_first_of(" \n", b);
    return s.replace(b, e - b, by);
  };
  const int body2_line = [&] {
    std::istringstream in(text);
    int n = 0;
    for (std::string l; std::getline(in, l);) {
      ++n;
      if (l.rfind("body 2 ", 0) == 0) return n;
    }
    return -1;
  }();
  const std::string at_body2 = bad + ":" + std::to_string(body2_line) + ": ";
  files.push_back({"NaN velocity", withChecksum(replaceWord(body, "body 2", 9, "nan")),
                   at_body2 + "body 2: value 7 is not finite"});
  files.push_back({"infinite position", withChecksum(replaceWord(body, "body 2", 2, "-inf")),
                   at_body2 + "body 2: value 0 is not finite"});
  files.push_back({"not a number", withChecksum(replaceWord(body, "body 2", 3, "0x1.2q")),
                   at_body2 + "body 2: '0x1.2q' is not a number"});
  files.push_back({"non-unit quaternion", withChecksum(replaceWord(body, "body 2", 5, "0x1.8p+0")),
                   at_body2 + "body 2: its quaternion is not of unit length"});
  files.push_back({"a number short", withChecksum(replaceWord(body, "body 2", 14, "")),
                   at_body2 + "body 2 has 12 numbers, expected 13"});
  files.push_back({"negative step_next", withChecksum(replaceWord(body, "step_next", 1, "-0x1p-20")),
                   ":5: step_next must be >= 0"});
  files.push_back({"a line missing", withChecksum(replaceWord(body, "commands", 0, "command")),
                   "expected a 'commands' line, found 'command'"});
  files.push_back({"not a state file", "nscd-friction-contact-problem 1\n", bad + ":1: not a state file"});

  for (const BadFile& f : files) {
    writeAll(bad, f.text);
    const std::string message = readError(bad, c60);
    EXPECT_NE(message.find(f.message), std::string::npos) << f.what << ": got '" << message << "'";
    EXPECT_EQ(message.rfind(bad + ":", 0), 0u) << f.what << ": the message names the file: " << message;
    EXPECT_THROW(loadStateFile(bad, c60), StateFileError) << f.what;
  }
  EXPECT_EQ(readError(bad + "_missing", c60), bad + "_missing: cannot read the state file");
  expectSameState(c60.state(), before, "after refused files");
  std::remove(good.c_str());
  std::remove(bad.c_str());
}

namespace {

// A state file without its comment and checksum lines (they name the command).
std::string stateLines(const std::string& path) {
  std::istringstream in(readAll(path));
  std::string out;
  for (std::string l; std::getline(in, l);)
    if (l.rfind("#", 0) != 0 && l.rfind("checksum ", 0) != 0) out += l + "\n";
  return out;
}

}  // namespace

// nscd_run: 2 ms in one run, or 1 ms, --save-state, then 1 ms from it with
// --initial-state: the same final state, fixed and adaptive.
TEST(StateFile, NscdRunContinuesFromAStateFile) {
  const std::string scene = nscd_test::scenePath("urdf/c60.urdf");
  const std::string common = scene + " --quiet --command " + kProbe;
  for (const std::string control : {"--dt 1e-5", "--set step_control=adaptive --set rtol=1e-2 --set atol=1e-5"}) {
    const std::string half = tempPath("half"), split = tempPath("split"), whole = tempPath("whole");
    ASSERT_EQ(nscd_test::runNscd(common + " " + control + " --duration 0.001 --save-state " + half).status, 0);
    const nscd_test::RunResult second = nscd_test::runNscd(common + " " + control + " --duration 0.001 --initial-state " +
                                                           half + " --save-state " + split);
    ASSERT_EQ(second.status, 0) << second.err;
    EXPECT_NE(second.out.find("\"sim_time\":0.001"), std::string::npos) << "sim_time counts from the state: " << second.out;
    ASSERT_EQ(nscd_test::runNscd(common + " " + control + " --duration 0.002 --save-state " + whole).status, 0);
    EXPECT_EQ(stateLines(split), stateLines(whole)) << control;
    EXPECT_NE(stateLines(half), stateLines(whole)) << control;
    for (const std::string& p : {half, split, whole}) std::remove(p.c_str());
  }
}

// nscd_run's bad state files and paths: status 2 and one line.
TEST(StateFile, NscdRunRefusesBadStateFiles) {
  const std::string pendulum_state = tempPath("pendulum");
  Simulator pendulum(loadModel("urdf/clearance_pendulum.urdf"));
  writeStateFile(pendulum_state, pendulum);
  const std::string c60 = nscd_test::scenePath("urdf/c60.urdf") + " --quiet --duration 0.0001";
  nscd_test::RunResult r = nscd_test::runNscd(c60 + " --initial-state " + pendulum_state);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, pendulum_state + ":2: the state was written for another scene: 1 bodies in the file, 8 in this scene\n");
  r = nscd_test::runNscd(c60 + " --initial-state " + pendulum_state + "_missing");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, pendulum_state + "_missing: cannot read the state file\n");
  r = nscd_test::runNscd(c60 + " --save-state /nonexistent_folder/x.state");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "nscd_run: --save-state /nonexistent_folder/x.state: cannot write this file\n");
  EXPECT_EQ(r.out, "") << "refused before the run";
  std::remove(pendulum_state.c_str());
}

// Found by fuzz/state_file_fuzzer.cpp: a step_next of 5e-324 s (>= 0, so read) was
// the adaptive clearance pendulum's next step, and its clearance joint's force
// (impulse / h) infinite in a step reported finite. planStep clamps the length a
// state proposes to [h_min, h_max] of the run's settings.
TEST(StateFile, TinyStepNextIsClampedToTheShortestStep) {
  const std::vector<SettingOverride> adaptive = {{"step_control", "adaptive", "test"}};
  Simulator sim(loadModel("urdf/clearance_pendulum.urdf", adaptive));
  for (int i = 0; i < 100000 && sim.contactPoints().empty(); ++i) ASSERT_NE(sim.step(), StepStatus::NonFinite);
  const std::string path = tempPath("tiny_step_next");
  writeStateFile(path, sim);
  std::string body = withoutChecksum(readAll(path));
  const size_t a = body.find("\nstep_next ") + 11;
  body.replace(a, body.find('\n', a) - a, "0x1p-1074");
  writeAll(path, withChecksum(body));

  Simulator resumed(loadModel("urdf/clearance_pendulum.urdf", adaptive));
  loadStateFile(path, resumed);
  EXPECT_EQ(resumed.state().step_next, 0x1p-1074);
  const double h_min = 1e-6 * resumed.model().settings.dt;  // dt_min unset: 1e-6 dt
  ASSERT_NE(resumed.step(), StepStatus::NonFinite);
  EXPECT_GE(resumed.stats().h, h_min * (1 - 1e-12));
  EXPECT_GT(resumed.state().t, sim.state().t);
  const std::vector<ContactReport> contacts = resumed.contactPoints();
  EXPECT_FALSE(contacts.empty()) << "the pendulum rests on its clearance at t = " << sim.state().t;
  for (const ContactReport& c : contacts) EXPECT_TRUE(std::isfinite(c.fn) && c.ft.allFinite()) << c.fn;
  std::vector<double> figures;
  keyFigureValues(resumed, figures);
  const std::vector<std::string> names = keyFigureNames(resumed.model());
  for (size_t i = 0; i < figures.size(); ++i) EXPECT_TRUE(std::isfinite(figures[i])) << names[i];
  std::remove(path.c_str());
}

// Found while writing the fuzz target: t = 1e300 was read, and nscd_run's clock
// converted t / dt (1e305) to a long (undefined). |t| / dt must stay below 2^62;
// 10^6 s at dt 1e-5 (t / dt = 1e11) is read.
TEST(StateFile, TimeBeyondTheStepCountIsRefused) {
  Simulator sim(loadModel("urdf/clearance_pendulum.urdf"));
  const std::string path = tempPath("huge_t");
  writeStateFile(path, sim);
  const std::string body = withoutChecksum(readAll(path));
  const size_t a = body.find("\nt ") + 3;
  const auto withTime = [&](const std::string& t) {
    writeAll(path, withChecksum(std::string(body).replace(a, body.find('\n', a) - a, t)));
  };
  withTime("0x1p+1000");
  EXPECT_EQ(readError(path, sim),
            path + ":4: t = 1.07151e+301 s is beyond this run's step count (|t| / dt >= 2^62, dt = 1e-05 s)");
  withTime("-0x1p+1000");
  EXPECT_NE(readError(path, sim).find(":4: t = -1.07151e+301 s is beyond"), std::string::npos);
  withTime("1e6");
  EXPECT_EQ(readError(path, sim), "");
  std::remove(path.c_str());
}
