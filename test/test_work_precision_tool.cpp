// nscd_work_precision (bench/work_precision.cpp) runs a scene file as nscd_run does:
// its --command schedules, and the scene's own schedules for the actuators they
// leave alone (the C-60's seating moment is one; it was once left out).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace {

const char* kSpin = "0:0,0.005:0.02,0.01:-0.01,0.015:0";

// The clearance pendulum with a torque actuator on its arm, with `schedule` as
// its own schedule (none when empty).
std::string spinPendulum(const std::string& schedule) {
  std::ifstream in(nscd_test::scenePath("urdf/clearance_pendulum.urdf"));
  std::stringstream ss;
  ss << in.rdbuf();
  std::string u = ss.str();
  const size_t at = u.find("<simulation");
  if (at == std::string::npos) throw std::runtime_error("clearance_pendulum.urdf: no <simulation");
  const std::string own = schedule.empty() ? "" : " schedule=\"" + schedule + "\"";
  u.insert(at, "<actuator name=\"spin\" type=\"torque\" link=\"arm\" axis=\"0 1 0\"" + own + "/>\n    ");
  return u;
}

// The CSV rows of one nscd_work_precision run (reference and runs), without the
// wall-time columns, which differ between runs.
std::vector<std::string> runRows(const std::string& scene, const std::string& extra) {
  const std::string csv = nscd_test::writeTemp("", ".csv");
  const nscd_test::RunResult r = nscd_test::runProgram(
      nscd_test::toolExe("nscd_work_precision"),
      "--scenes none --scene-file spin=" + scene + " --file-duration 0.02 --file-sample-dt 1e-3 --hs 1e-4,5e-5"
      " --href 1e-5 --tols 1e-8 --jobs 1 --csv " + csv + extra);
  EXPECT_EQ(r.status, 0) << r.err;
  std::ifstream in(csv);
  std::vector<std::string> rows;
  std::vector<int> timing;  // columns wall_s, us_per_step, ref_wall_s
  for (std::string line; std::getline(in, line);) {
    std::stringstream cells(line);
    std::string kept, cell;
    for (int c = 0; std::getline(cells, cell, ','); ++c) {
      if (rows.empty() && (cell == "wall_s" || cell == "us_per_step" || cell == "ref_wall_s")) timing.push_back(c);
      bool drop = false;
      for (int t : timing) drop = drop || t == c;
      if (!drop) kept += cell + ",";
    }
    rows.push_back(kept);
  }
  std::filesystem::remove(csv);
  return rows;
}

}  // namespace

// The scene's own schedule gives the same runs as that schedule given by --command,
// and not the runs of the same scene with no schedule at all.
TEST(WorkPrecisionTool, SceneFileRunsWithItsOwnSchedules) {
  const std::string own = nscd_test::writeTemp(spinPendulum(kSpin));
  const std::string bare = nscd_test::writeTemp(spinPendulum(""));
  const std::vector<std::string> with_own = runRows(own, "");
  const std::vector<std::string> by_command = runRows(bare, std::string(" --command spin=") + kSpin);
  const std::vector<std::string> without = runRows(bare, "");
  ASSERT_EQ(with_own.size(), 4u);  // header, reference, two runs
  EXPECT_EQ(with_own, by_command);
  EXPECT_NE(with_own, without);
  // A --command of an actuator the scene does not have leaves the scene's own schedule.
  EXPECT_EQ(runRows(own, " --command nosuch=0:0,1:1"), with_own);
  std::filesystem::remove(own);
  std::filesystem::remove(bare);
}
