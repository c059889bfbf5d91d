// Fuzz target: a state file (nscd::readStateFile, what nscd_run --initial-state,
// nscd_sweep --initial-state and the Python module's Simulator.load_state read)
// against one of four small scenes, then set (Simulator::setState, as the front
// ends do) and stepped 3 times.
// The input's first byte chooses: bits 0-1 the scene (kScenes); bit 6 (0x40)
// clear: the rest's last line, if it is a 'checksum' line, is dropped and the
// right checksum line is appended, so mutations of the lines above it reach the
// reader's checks of them; set: the rest is read as it is (the checksum's check).
// Oracle: a refusal is a StateFileError of one line, "FILE:LINE: what"; a state
// read fits the scene (sizes), is finite but for NaN ring hints, has unit
// quaternions, step_next, step_error >= 0 and |t| / dt < 2^62 (the front ends'
// step count is a long); setState takes it; each step not reported NonFinite has
// finite outputs (fuzz_support.hpp).
// Seeds (fuzz/seeds/state_file/): the first byte, then a file nscd_run wrote, e.g.
//   nscd_run urdf/clearance_pendulum.urdf --duration 0.3 --save-state F  (0: clearance_pendulum,
//     @: the same read with its checksum; --duration 0: clearance_pendulum_start)
//   ... --set step_control=adaptive (1), urdf/slider_crank.urdf --duration 0.01 (2),
//   test/ros/actuated_pendulum.urdf --duration 0.2 --command hinge_motor=0:0,0.2:0.5
//     --command push=0:1 (3).
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "csv_writer.hpp"
#include "fuzz_support.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "nscd_sim/state_file.hpp"

namespace {

// A clearance joint (ring hints) under fixed and adaptive steps (step_next and
// step_error drive the controller), joints with contacts (bilateral warm starts),
// actuators (commands).
struct SceneChoice {
  const char* path;
  const char* step_control;
};
const SceneChoice kScenes[4] = {
    {"urdf/clearance_pendulum.urdf", "fixed"},
    {"urdf/clearance_pendulum.urdf", "adaptive"},
    {"urdf/slider_crank.urdf", "fixed"},
    {"test/ros/actuated_pendulum.urdf", "fixed"},
};

const nscd::Model& model(int i) {
  static const std::vector<nscd::Model> models = [] {
    std::vector<nscd::Model> m;
    for (const SceneChoice& s : kScenes)
      m.push_back(nscd::loadSceneFromString(nscd_fuzz::repoFile(s.path), s.path,
                                            {{"step_control", s.step_control, "fuzz"}}));
    return m;
  }();
  return models[i];
}

// The checksum line writeStateFile ends a file with (64-bit FNV-1a of the text above it).
std::string withChecksum(std::string text) {
  if (text.size() > 1) {
    const size_t last = text.rfind('\n', text.size() - 2);  // the last line's start, less one
    const size_t start = last == std::string::npos ? 0 : last + 1;
    if (text.back() == '\n' && text.compare(start, 9, "checksum ") == 0) text.resize(start);
  }
  if (!text.empty() && text.back() != '\n') text += '\n';
  return text + nscd::stateChecksumLine(text);
}

bool allFinite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

// What readStateFile promises of a state it returns for `sim`.
void checkState(const nscd::State& s, const nscd::Simulator& sim) {
  const nscd::State& now = sim.state();
  if (s.bodies.size() != sim.model().bodies.size() || s.commands.size() != now.commands.size() ||
      s.prev_commands.size() != now.prev_commands.size() || s.warm.size() != now.warm.size() ||
      s.warm_valid.size() != now.warm_valid.size() || s.warm_bilateral.size() != now.warm_bilateral.size() ||
      s.ring_hint.size() != now.ring_hint.size() || s.joint_position.size() != now.joint_position.size())
    nscd_fuzz::fail("a state read with sizes that do not fit the scene");
  if (!std::isfinite(s.t) || !std::isfinite(s.step_next) || !std::isfinite(s.step_error))
    nscd_fuzz::fail("a state read with a non-finite t, step_next or step_error");
  if (s.step_next < 0 || s.step_error < 0) nscd_fuzz::fail("a state read with step_next or step_error < 0");
  // The front ends' step count (nscd_run's clock, the Python module's) is round(t / dt), a long.
  if (!(std::abs(s.t) / sim.model().settings.dt < 0x1p62)) nscd_fuzz::fail("a state read whose t / dt is no long");
  for (const nscd::BodyState& b : s.bodies) {
    if (!b.x.allFinite() || !b.q.coeffs().allFinite() || !b.v.allFinite() || !b.w.allFinite())
      nscd_fuzz::fail("a state read with a non-finite body state");
    if (std::abs(b.q.norm() - 1) > 1e-9) nscd_fuzz::fail("a state read with a quaternion not of unit length");
  }
  for (const nscd::Vec3& w : s.warm)
    if (!w.allFinite()) nscd_fuzz::fail("a state read with a non-finite warm start");
  for (char v : s.warm_valid)
    if (v != 0 && v != 1) nscd_fuzz::fail("a state read with a warm_valid flag not 0 or 1");
  if (!allFinite(s.commands) || !allFinite(s.prev_commands) || !allFinite(s.warm_bilateral) ||
      !allFinite(s.joint_position))
    nscd_fuzz::fail("a state read with a non-finite command, warm start or joint position");
  for (double r : s.ring_hint)
    if (std::isinf(r)) nscd_fuzz::fail("a state read with an infinite ring hint");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const int scene = data[0] & 3;
  std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (!(data[0] & 0x40)) text = withChecksum(text);
  const std::string path = nscd_fuzz::scratchFile(reinterpret_cast<const uint8_t*>(text.data()), text.size(), ".state");

  nscd::Simulator sim(model(scene));  // a fresh one: an input's outcome does not depend on the last
  const double t0 = sim.state().t;
  const nscd::Vec3 x0 = sim.state().bodies[0].x;
  nscd::State s;
  try {
    s = nscd::readStateFile(path, sim);
  } catch (const nscd::StateFileError& e) {
    // "FILE:LINE: what", or "FILE: what" when no line is to blame.
    nscd_fuzz::expectOneLine(e.what(), path + ":");
    return 0;
  }
  if (sim.state().t != t0 || sim.state().bodies[0].x != x0) nscd_fuzz::fail("readStateFile changed the simulator");
  checkState(s, sim);
  try {
    sim.setState(s);
  } catch (const std::invalid_argument& e) {
    nscd_fuzz::fail(std::string("setState refused a state readStateFile returned: ") + e.what());
  }
  nscd::CsvWriter csv("/dev/null", sim);
  csv.writeRow(sim);
  std::vector<double> figures;
  for (int k = 1; k <= 3; ++k) {
    if (sim.step() == nscd::StepStatus::NonFinite) break;  // reported: the runner stops (status 3)
    nscd_fuzz::checkStepOutputs(sim, k, figures);
    csv.writeRow(sim);
  }
  return 0;
}
