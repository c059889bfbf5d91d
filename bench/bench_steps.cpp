// Step-cost benchmarks (Google Benchmark). Run: scripts/bench.sh
// Times one warm step of small reference scenes, and whole nscd_run runs.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "../test/physics_scenes.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"

using namespace nscd;

namespace {

std::unique_ptr<Simulator> makeSim(const std::string& xml,
                                   const std::vector<SettingOverride>& o = {}) {
  return std::make_unique<Simulator>(loadSceneFromString(xml, "bench.urdf", o));
}

// Steps a scene `warm` steps first (contacts established), then times single steps;
// the state is reset periodically so the benchmark stays in the same regime.
void runSteps(benchmark::State& state, Simulator& sim, int warm) {
  for (int k = 0; k < warm; ++k) sim.step();
  long iters = 0, n = 0;
  for (auto _ : state) {
    sim.step();
    iters += sim.stats().iterations;
    ++n;
  }
  state.counters["solver_iters"] = n ? double(iters) / n : 0.0;
  state.counters["rows"] = sim.stats().rows;
}

void BM_BallResting(benchmark::State& state) {
  auto sim = makeSim(nscd_test::ballScene(0.0, 0.0, 0.3, 1e-4));
  runSteps(state, *sim, 100);
}
BENCHMARK(BM_BallResting)->Unit(benchmark::kMicrosecond);

void BM_BallFlight(benchmark::State& state) {
  auto sim = makeSim(nscd_test::ballScene(1e6, 0.9, 0.0, 1e-4));  // far from the plane
  runSteps(state, *sim, 10);
}
BENCHMARK(BM_BallFlight)->Unit(benchmark::kMicrosecond);

void BM_SlopeSticking(benchmark::State& state) {
  auto sim = makeSim(nscd_test::slopeScene(15 * M_PI / 180, 0.3, 1e-4));
  runSteps(state, *sim, 100);
}
BENCHMARK(BM_SlopeSticking)->Unit(benchmark::kMicrosecond);

void BM_SlopeSliding(benchmark::State& state) {
  auto sim = makeSim(nscd_test::slopeScene(25 * M_PI / 180, 0.3, 1e-4));
  runSteps(state, *sim, 100);
}
BENCHMARK(BM_SlopeSliding)->Unit(benchmark::kMicrosecond);

void BM_Pendulum(benchmark::State& state) {
  auto sim = makeSim(nscd_test::pendulumScene(1.0, 1.0, 1e-3, 0.5, 1e-4));
  runSteps(state, *sim, 10);
}
BENCHMARK(BM_Pendulum)->Unit(benchmark::kMicrosecond);

void BM_FourBar(benchmark::State& state) {
  auto sim = makeSim(nscd_test::fourBarScene(M_PI / 2, 5.0, 1e-4));
  runSteps(state, *sim, 10);
}
BENCHMARK(BM_FourBar)->Unit(benchmark::kMicrosecond);

void BM_SpringMass(benchmark::State& state) {
  auto sim = makeSim(nscd_test::springMassScene(1.0, 100.0, 0.1, 1e-4));
  runSteps(state, *sim, 10);
}
BENCHMARK(BM_SpringMass)->Unit(benchmark::kMicrosecond);

// Scene files shipped in urdf/: one step, if the file loads.
void BM_SceneFile(benchmark::State& state, const char* rel) {
  std::unique_ptr<Simulator> sim;
  try {
    sim = std::make_unique<Simulator>(loadScene(std::string(NSCD_SOURCE_DIR) + "/" + rel));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  runSteps(state, *sim, 100);
}
BENCHMARK_CAPTURE(BM_SceneFile, journal, "urdf/journal.urdf")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SceneFile, clearance_pendulum, "urdf/clearance_pendulum.urdf")->Unit(benchmark::kMicrosecond);

// The clearance pendulum of the tests (50 µm, mu 0.1, h 1e-5), in 3D and planar mode.
void BM_ClearancePendulum(benchmark::State& state, const char* planar) {
  auto sim = makeSim(nscd_test::clearancePendulumScene(50e-6, 0.1, 4.5e-3, 0.05, 0.5236, 1e-5, true, planar));
  runSteps(state, *sim, 1000);
}
BENCHMARK_CAPTURE(BM_ClearancePendulum, three_d, "false")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ClearancePendulum, planar, "xy")->Unit(benchmark::kMicrosecond);

// The journal at rest (sleeve on a pin, 0.05 mm clearance) from the tests: 2 of its
// 8 candidate contacts are closed. "no_skip" forces all 8 into the solver
// (activation_margin = 1 m) to measure what skipping the open ones saves.
void BM_JournalAtRest(benchmark::State& state, const char* margin) {
  auto sim = makeSim(nscd_test::sleeveScene(0.05e-3, 0.0, 0.2, -9.81, 1e-4),
                     {{"activation_margin", margin, "bench"}});
  runSteps(state, *sim, 2000);
}
BENCHMARK_CAPTURE(BM_JournalAtRest, skip, "0")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_JournalAtRest, no_skip, "1")->Unit(benchmark::kMicrosecond);
void BM_ClearancePendulumNoSkip(benchmark::State& state) {
  auto sim = makeSim(nscd_test::clearancePendulumScene(50e-6, 0.1, 4.5e-3, 0.05, 0.5236, 1e-5),
                     {{"activation_margin", "1", "bench"}});
  runSteps(state, *sim, 1000);
}
BENCHMARK(BM_ClearancePendulumNoSkip)->Unit(benchmark::kMicrosecond);

// A whole nscd_run (process start, load, 1 s of the ball, JSON): wall time per run.
void BM_NscdRunBall(benchmark::State& state) {
  const std::string cmd = std::string(NSCD_RUN_EXE) + " " + NSCD_SOURCE_DIR +
                          "/urdf/ball.urdf --duration 1 --quiet > /dev/null";
  for (auto _ : state) {
    if (std::system(cmd.c_str()) != 0) {
      state.SkipWithError("nscd_run failed");
      return;
    }
  }
}
BENCHMARK(BM_NscdRunBall)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
