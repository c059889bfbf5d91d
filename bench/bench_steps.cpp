// Step-cost benchmarks (Google Benchmark). Run: scripts/bench.sh
// Times one warm step of small reference scenes, and whole nscd_run runs.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <cstdlib>
#include <memory>
#include <string>

#include "../test/physics_scenes.hpp"
#include "nscd_sim/friction_contact_solver.hpp"
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

// "mu = 0 contacts are one row": the same n frictionless contacts (normal rows of
// a random SPD Delassus operator, approaching) solved as n one-row blocks, as the
// engine does, or as n three-row frictional blocks with mu = 0 (what it would do
// without the skip). Cold start each time.
void BM_FrictionlessContacts(benchmark::State& state) {
  const int n = 12;
  const bool three_rows = state.range(0) != 0;
  std::srand(7);
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(3 * n, 3 * n);
  const Eigen::MatrixXd W3 = A * A.transpose() / (3 * n) + 0.1 * Eigen::MatrixXd::Identity(3 * n, 3 * n);
  Eigen::VectorXd b3 = Eigen::VectorXd::Zero(3 * n);
  for (int i = 0; i < n; ++i) b3[3 * i] = -1.0 - 0.1 * i;
  Eigen::MatrixXd W1(n, n);
  Eigen::VectorXd b1(n);
  for (int i = 0; i < n; ++i) {
    b1[i] = b3[3 * i];
    for (int j = 0; j < n; ++j) W1(i, j) = W3(3 * i, 3 * j);
  }
  std::vector<ProblemBlock> blocks(n);
  for (int i = 0; i < n; ++i) {
    blocks[i].kind = three_rows ? BlockKind::Frictional : BlockKind::Frictionless;
    blocks[i].row = three_rows ? 3 * i : i;
    blocks[i].size = three_rows ? 3 : 1;
    blocks[i].mu = 0;
  }
  FrictionContactSolver solver;
  SolverOptions opt;
  Eigen::VectorXd P = Eigen::VectorXd::Zero(three_rows ? 3 * n : n);
  long iters = 0, k = 0;
  for (auto _ : state) {
    P.setZero();
    const SolverReport rep = three_rows ? solver.solve(W3, b3, blocks, opt, P)
                                        : solver.solve(W1, b1, blocks, opt, P);
    iters += rep.iteration_sum;
    ++k;
  }
  state.counters["iterations"] = k ? double(iters) / k : 0.0;
}
BENCHMARK(BM_FrictionlessContacts)->Arg(0)->Arg(1)->ArgNames({"three_rows"})->Unit(benchmark::kMicrosecond);

// The exact local 3x3 Coulomb solve (NSGS inner step): sticking, sliding from a
// cold start, sliding from the answer (warm). Same problems as the test
// LocalSolver.BenchmarkProblemsAreSolved, with a fixed W (condition number 10).
void BM_LocalSolver(benchmark::State& state) {
  const int kind = static_cast<int>(state.range(0));  // 0 stick, 1 slide cold, 2 slide warm
  const Eigen::Matrix3d O =
      Eigen::Quaterniond(0.3, -0.5, 0.7, 0.2).normalized().toRotationMatrix();
  const Eigen::Matrix3d W = O * Eigen::Vector3d(1.0, 0.3, 0.1).asDiagonal() * O.transpose();
  const double mu = 0.4;
  const Eigen::Vector3d Pslide = Eigen::Vector3d::UnitX() - mu * Eigen::Vector3d(0, 0.6, 0.8);
  const Eigen::Vector3d b = kind == 0 ? Eigen::Vector3d(-W * Eigen::Vector3d(1, 0.1, 0.1))
                                      : Eigen::Vector3d(Eigen::Vector3d(0, 1.2, 1.6) - W * Pslide);
  Eigen::Vector3d P = Eigen::Vector3d::Zero();
  for (auto _ : state) {
    if (kind != 2) P.setZero();
    solveLocalFrictional(W, b, mu, 1e-12, P);
    benchmark::DoNotOptimize(P.data());
  }
}
BENCHMARK(BM_LocalSolver)->Arg(0)->Arg(1)->Arg(2)->ArgNames({"stick0_cold1_warm2"})->Unit(benchmark::kNanosecond);

// "No projection pass when nothing is violated": the journal at rest with the
// projection on (each step only measures the violation, below the tolerance, and
// returns) against projection off.
void BM_JournalProjection(benchmark::State& state, const char* projection) {
  auto sim = makeSim(nscd_test::sleeveScene(0.05e-3, 0.0, 0.2, -9.81, 1e-4),
                     {{"projection", projection, "bench"}});
  runSteps(state, *sim, 2000);
  state.counters["projection_passes"] = sim->stats().projection_passes;
}
BENCHMARK_CAPTURE(BM_JournalProjection, on, "true")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_JournalProjection, off, "false")->Unit(benchmark::kMicrosecond);

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
