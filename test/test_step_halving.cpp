// Step halving (Settings::max_step_halvings, step_halving.cpp): a step whose
// problem stays unsolved is taken again as two steps of h/2, each halved again
// while unsolved. Taken in halves, a step must be the same steps of h/2^k that a
// run at that step size takes, with the commands of a prescribed motion followed
// in between and the efforts averaged over the step.
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "test_support.hpp"

using namespace nscd;

namespace {

constexpr double kDt = 1e-5;
constexpr int kSteps = 6;

std::string text(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// The C-60 with its handle driven from t = 0 (a prescribed motion against the
// mechanism's springs and contacts). A tolerance no solve can reach leaves every
// problem unsolved, so every step is halved down to max_step_halvings.
Simulator c60(double dt, int halvings, double tolerance, bool adaptive = false) {
  std::vector<SettingOverride> o = {{"dt", text(dt), "test"},
                                    {"max_step_halvings", std::to_string(halvings), "test"},
                                    {"tolerance", text(tolerance == 0 ? 1e-300 : tolerance), "test"},
                                    {"max_iterations", "40", "test"}};
  if (adaptive) o.push_back({"step_control", "adaptive", "test"});
  return Simulator(loadScene(nscd_test::scenePath("urdf/c60.urdf"), o));
}

// The handle at rest until the mechanism has settled (its contacts loaded by the
// springs: a problem with P = 0 as its answer is solved exactly, at any
// tolerance), then turned.
constexpr int kSettle = 300;
const CommandSchedule& handleRamp() {
  static const CommandSchedule s = parseCommandSchedule("handle=0:0,0.003:0,0.013:1.2");
  return s;
}

void setHandle(Simulator& sim, double t) {
  sim.setCommand(sim.model().findActuator("handle"), handleRamp().value(t));
}

// The state after kSettle steps of kDt at the default settings.
const State& settled() {
  static const State s = [] {
    Simulator sim = c60(kDt, 4, 1e-8);
    for (int k = 1; k <= kSettle; ++k) {
      setHandle(sim, k * kDt);
      sim.step();
    }
    return sim.state();
  }();
  return s;
}

}  // namespace

// Every step unsolved, 2 halvings: the whole attempt and its first half are
// dropped, the first half's quarters are kept (the second quarter taken once: the
// first, unsolved at the smallest step, showed that halving does not settle this
// step), and so is the second half, taken once. The bodies, the step's stats and
// the handle's effort must be those of two steps of h/4 and one of h/2 with
// max_step_halvings 0 from the same state: the same stages on the same states,
// but for the commands in between, which the halving interpolates (the runs at
// h/4 and h/2 read the schedule), so equal to round-off.
TEST(StepHalving, HalvedStepIsTheStepsOfItsLength) {
  Simulator halved = c60(kDt, 2, 0);
  Simulator quarter = c60(kDt / 4, 0, 0);
  Simulator half = c60(kDt / 2, 0, 0);
  halved.setState(settled());
  const int handle = halved.model().findActuator("handle");
  ASSERT_GE(handle, 0);
  double effort_scale = 0;
  for (int k = kSettle + 1; k <= kSettle + kSteps; ++k) {
    quarter.setState(halved.state());
    setHandle(halved, k * kDt);
    EXPECT_EQ(halved.step(), StepStatus::NotConverged) << "step " << k;
    const StepStats& s = halved.stats();
    EXPECT_EQ(s.substeps, 3) << "step " << k;
    EXPECT_EQ(s.halvings, 2) << "step " << k;
    EXPECT_FALSE(s.converged);
    double effort = 0;
    int iterations = 0;
    for (int j = 1; j <= 2; ++j) {
      setHandle(quarter, ((k - 1) * 4 + j) * (kDt / 4));
      quarter.step();
      effort += quarter.actuatorEffort(handle) / 4;
      iterations += quarter.stats().iterations;
      EXPECT_EQ(quarter.stats().substeps, 1);
    }
    half.setState(quarter.state());
    setHandle(half, k * kDt);
    half.step();
    effort += half.actuatorEffort(handle) / 2;
    iterations += half.stats().iterations;
    EXPECT_EQ(half.stats().substeps, 1);
    // The attempts dropped (the whole step, its first half) did work too.
    EXPECT_GT(s.iterations, iterations) << "step " << k;
    effort_scale = std::max(effort_scale, std::abs(effort));
    EXPECT_NEAR(halved.actuatorEffort(handle), effort, 1e-9 * std::abs(effort) + 1e-12) << "step " << k;
    EXPECT_NEAR(halved.state().t, half.state().t, 1e-18) << "step " << k;
    EXPECT_DOUBLE_EQ(halved.command(handle), handleRamp().value(k * kDt));
    for (size_t b = 0; b < halved.state().bodies.size(); ++b) {
      const BodyState& x = halved.state().bodies[b];
      const BodyState& y = half.state().bodies[b];
      EXPECT_LT((x.x - y.x).norm(), 1e-13) << "step " << k << " body " << b;
      EXPECT_LT((x.v - y.v).norm(), 1e-8 * (1 + y.v.norm())) << "step " << k << " body " << b;
      EXPECT_LT((x.w - y.w).norm(), 1e-8 * (1 + y.w.norm())) << "step " << k << " body " << b;
    }
  }
  EXPECT_GT(effort_scale, 1e-6) << "the handle did no work: the effort check proved nothing";
}

// A step no solve settles, at the default 8 halvings: the attempts (each one's own
// solve, seen by an observer as its halvings and substep) go down the first
// halves to h/256, then take the rest of the step once each, from the smallest
// substep up: 2 * 8 + 1 attempts, where halving every unsolved substep would take
// 511. The kept substeps cover the step exactly.
TEST(StepHalving, UnsolvableStepIsNotHalvedPastItsFirstFailure) {
  constexpr int kLevels = 8;
  Simulator sim = c60(kDt, kLevels, 0);
  sim.setState(settled());
  std::vector<std::pair<int, int>> attempts;
  sim.setProblemObserver([&](const ProblemView& v) {
    if (v.resolve == nullptr && v.round == 0) attempts.emplace_back(v.halvings, v.substep);
  });
  setHandle(sim, settled().t + kDt);
  EXPECT_EQ(sim.step(), StepStatus::NotConverged);
  std::vector<std::pair<int, int>> expected;
  for (int level = 0; level <= kLevels; ++level) expected.emplace_back(level, 0);  // whole, first halves
  for (int level = kLevels; level >= 1; --level) expected.emplace_back(level, 1);  // each second half once
  EXPECT_EQ(attempts, expected);
  const StepStats& st = sim.stats();
  EXPECT_EQ(st.substeps, kLevels + 1);
  EXPECT_EQ(st.halvings, kLevels);
  EXPECT_FALSE(st.converged);
  EXPECT_TRUE(stepTookRescue(st, StepRescue::LongerSolve));
  EXPECT_NEAR(sim.state().t, settled().t + kDt, 1e-18);
}

// Adaptive steps: a step kept unsolved although its substeps were halved is not
// taken again shorter (its paths differ as unsolved answers do; a shorter step is
// no more solvable), and the next one keeps its length. The C-60 settling from
// its ON pose with a tolerance no solve reaches: its unsolved steps' paths differ
// by more than the tolerance (they were rejected, down to ~5e-8 s, before), and none
// is rejected; every step is dt.
TEST(StepHalving, AdaptiveStepKeepsAnUnsolvedStepAtItsLength) {
  Simulator sim = c60(kDt, 2, 0, true);
  int above = 0;
  for (int k = 1; k <= 2 * kSteps; ++k) {
    const StepStatus status = sim.step();
    const StepStats& st = sim.stats();
    EXPECT_EQ(st.rejected, 0) << k;
    EXPECT_EQ(st.h, kDt) << k;
    if (status == StepStatus::NotConverged && st.error > 1) {
      ++above;
      EXPECT_EQ(sim.state().step_next, kDt) << k;
    }
  }
  EXPECT_GE(above, 2) << "too few unsolved steps above the tolerance for the check to mean anything";
  EXPECT_NEAR(sim.state().t, 2 * kSteps * kDt, 1e-15);
}

// A step the solver settles is never halved, and halving off is the old stepping:
// with the default tolerance the C-60 steps the same bits either way.
TEST(StepHalving, SolvedStepsAreNotTouched) {
  Simulator with = c60(kDt, 4, 1e-8);
  Simulator without = c60(kDt, 0, 1e-8);
  with.setState(settled());
  without.setState(settled());
  for (int k = kSettle + 1; k <= kSettle + 3 * kSteps; ++k) {
    setHandle(with, k * kDt);
    setHandle(without, k * kDt);
    ASSERT_EQ(with.step(), StepStatus::Ok) << "step " << k;
    ASSERT_EQ(without.step(), StepStatus::Ok) << "step " << k;
    EXPECT_EQ(with.stats().substeps, 1);
    EXPECT_EQ(with.stats().iterations, without.stats().iterations);
  }
  for (size_t b = 0; b < with.state().bodies.size(); ++b) {
    EXPECT_EQ(with.state().bodies[b].x, without.state().bodies[b].x) << "body " << b;
    EXPECT_EQ(with.state().bodies[b].v, without.state().bodies[b].v) << "body " << b;
  }
}

// Halving copies states and commands into buffers sized at construction: a
// halved step allocates nothing once the solver's buffers have grown.
TEST(StepHalving, HalvedStepsAllocateNothing) {
  Simulator sim = c60(kDt, 2, 0);
  sim.setState(settled());
  int k = kSettle;
  for (int i = 0; i < 3; ++i, ++k) {  // the solver's buffers grow to the largest problem
    setHandle(sim, (k + 1) * kDt);
    sim.step();
  }
  const long before = nscd_test::allocationCount();
  for (int i = 0; i < 2; ++i, ++k) {
    setHandle(sim, (k + 1) * kDt);
    sim.step();
    EXPECT_EQ(sim.stats().substeps, 3);
  }
  EXPECT_EQ(nscd_test::allocationCount(), before);
}

// StepStats::solves_by_stage counts every solve of the step, under the stage that
// finished it: the attempts a halving drops and the rescues' solves included, as
// a problem observer sees them. Every step here is unsolved (halved twice, then
// the rescues at h/4 and on the second half, taken once), so every kind of solve occurs.
TEST(StepHalving, SolvesByStageCountEverySolveOfTheStep) {
  Simulator sim = c60(kDt, 2, 0);
  sim.setState(settled());
  std::array<int, kSolverStageCount> seen{};
  sim.setProblemObserver([&](const ProblemView& v) { ++seen[static_cast<int>(v.report.stage)]; });
  for (int k = 1; k <= kSteps; ++k) {
    seen.fill(0);
    setHandle(sim, settled().t + k * kDt);
    sim.step();
    const StepStats& st = sim.stats();
    EXPECT_EQ(st.substeps, 3) << k;
    EXPECT_TRUE(stepTookRescue(st, StepRescue::Halving)) << k;
    EXPECT_TRUE(stepTookRescue(st, StepRescue::LongerSolve)) << k;
    int solves = 0;
    for (int s = 0; s < kSolverStageCount; ++s) {
      EXPECT_EQ(st.solves_by_stage[s], seen[s]) << k << " " << solverStageName(static_cast<SolverStage>(s));
      solves += st.solves_by_stage[s];
    }
    // At least the whole attempt, its first half, and the two quarters and the second
    // half kept, each with a longer solve.
    EXPECT_GE(solves, 1 + 1 + 3 * 2) << k;
    EXPECT_GT(st.solves_by_stage[static_cast<int>(SolverStage::Unsolved)], 0) << k;
  }
}

TEST(StepRescue, NamesInPolicyOrder) {
  const char* expected[kStepRescueCount] = {"cold_retry",    "plastic_impact", "halving",   "longer_solve",
                                            "plastic_retry", "frictionless",   "energy_cap"};
  for (int i = 0; i < kStepRescueCount; ++i)
    EXPECT_STREQ(stepRescueName(static_cast<StepRescue>(i)), expected[i]);
}
