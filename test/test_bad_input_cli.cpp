// nscd_run refuses every bad scene (and bad YAML config) before the first step:
// exit status 2 and exactly one line on stderr that names the file.
#include <dirent.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include "test_support.hpp"

using nscd_test::runNscd;
using nscd_test::scenePath;

namespace {

std::vector<std::string> badScenes() {
  std::vector<std::string> out;
  const std::string dir = scenePath("test/scenes/bad");
  if (DIR* d = opendir(dir.c_str())) {
    for (dirent* e; (e = readdir(d));) {
      const std::string f = e->d_name;
      if (f.size() > 5 && f.substr(f.size() - 5) == ".urdf") out.push_back(dir + "/" + f);
    }
    closedir(d);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// One line: no newline except an optional final one, and not empty.
bool oneLine(const std::string& s) {
  std::string t = s;
  if (!t.empty() && t.back() == '\n') t.pop_back();
  return !t.empty() && t.find('\n') == std::string::npos;
}

// The run's result, for checks of its own.
nscd_test::RunResult expectRefused(const std::string& args, const std::string& file) {
  nscd_test::RunResult r = runNscd(args);
  EXPECT_EQ(r.status, 2) << args << "\nstderr: " << r.err;
  EXPECT_TRUE(oneLine(r.err)) << args << "\nstderr: [" << r.err << "]";
  EXPECT_NE(r.err.find(file), std::string::npos) << args << "\nstderr: " << r.err;
  return r;
}

}  // namespace

TEST(BadInputCli, EveryBadSceneExitsWithStatus2AndOneLine) {
  const std::vector<std::string> scenes = badScenes();
  ASSERT_GE(scenes.size(), 20u);
  for (const std::string& s : scenes) expectRefused("'" + s + "' --duration 0.001 --quiet", s);
}

// Scenes that load but whose loop cannot close (fuzzed four-bars: the rocker
// joint's origin garbled; the crank's yaw 68490 rad): refused once 20 projection
// passes in a row have not halved the violation, not after all 200 of the
// assembly. Found by fuzz/scene_loader_fuzzer.cpp as timeouts under the fuzz build
// (34 s, then 132 s in CI; 200 passes took 3 s in Release); kept out of
// test/scenes (the loader itself refuses the scenes of test/scenes/bad, and
// test/scenes seeds the fuzz target).
TEST(BadInputCli, SceneThatCannotBeAssembledIsRefusedEarly) {
  for (const char* name : {"fourbar_loop_open.urdf", "fourbar_crank_turned.urdf"}) {
    const std::string s = scenePath(std::string("test/bad_assembly/") + name);
    const nscd_test::RunResult r = expectRefused("'" + s + "' --duration 0.001 --quiet", s);
    EXPECT_NE(r.err.find("assembly failed: constraint violation"), std::string::npos) << r.err;
    const std::size_t after = r.err.find(" after ");
    ASSERT_NE(after, std::string::npos) << r.err;
    const int passes = std::atoi(r.err.c_str() + after + 7);
    EXPECT_GT(passes, 20) << r.err;
    EXPECT_LT(passes, 60) << r.err;  // the stall, not the budget of 200
    EXPECT_NE(r.err.find("did not halve it"), std::string::npos) << r.err;
  }
}

TEST(BadInputCli, BadYamlConfigIsRefused) {
  const std::string scene = scenePath("urdf/ball.urdf");
  for (const char* y : {"bad_settings.yaml", "malformed.yaml", "line_break_in_key.yaml"}) {
    const std::string cfg = scenePath(std::string("test/scenes/bad/") + y);
    expectRefused("'" + scene + "' --config '" + cfg + "' --duration 0.001 --quiet", cfg);
  }
}

TEST(BadInputCli, MissingSceneFile) {
  const std::string missing = scenePath("urdf/no_such_scene.urdf");
  expectRefused("'" + missing + "' --duration 0.001 --quiet", missing);
}
