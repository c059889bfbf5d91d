// The comparison models in nscd_sim: the same scene texts as the physics tests
// (test/physics_scenes.hpp), stepped by nscd::Simulator.
#include <cmath>
#include <stdexcept>

#include "models.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "physics_scenes.hpp"
#include "run_loop.hpp"

namespace nscd_siconos {

namespace {

std::vector<nscd::SettingOverride> overridesFor(const RunOptions& o) {
  auto num = [](double v) { return nscd_test::num(v); };
  return {{"tolerance", num(o.tolerance), "bench"},
          {"max_iterations", std::to_string(o.max_iterations), "bench"},
          {"projection", o.scheme == Scheme::CombinedProjection ? "true" : "false", "bench"}};
}

// The (only) body's state; read after each step, as step() may replace the state.
const nscd::BodyState& body(const nscd::Simulator& sim) { return sim.state().bodies[0]; }

// One step; a non-finite state ends the run.
void step(nscd::Simulator& sim, RunResult& res) {
  const nscd::StepStatus st = sim.step();
  if (st == nscd::StepStatus::NonFinite) throw std::runtime_error("non-finite state");
  if (st == nscd::StepStatus::NotConverged) ++res.unconverged_steps;
}

}  // namespace

RunResult runBallNscd(const BallParams& p, const RunOptions& o) {
  return guardedRun([&](RunResult& res) {
    // ballScene fixes r = 0.05 and m = 1; the comparison must use the same.
    if (p.r != 0.05 || p.m != 1.0 || p.g != 9.81) throw std::runtime_error("ball parameters differ from ballScene");
    nscd::Simulator sim(nscd::loadSceneFromString(nscd_test::ballScene(p.h0, p.e, p.mu, o.h),
                                                  "ball.urdf", overridesFor(o)));
    ApexDetector apex(p.g);
    runSampled(
        res, p.T, o,
        [&] {
          step(sim, res);
          const nscd::BodyState& b = body(sim);
          apex.update(b.x.z() - p.r, b.v.z(), res.apex);
        },
        [&] {
          const nscd::BodyState& b = body(sim);
          return Sample{b.x.z() - p.r, b.x.x(), p.r - b.x.z()};
        });
  });
}

RunResult runPendulumNscd(const PendulumParams& p, const RunOptions& o) {
  return guardedRun([&](RunResult& res) {
    if (p.m != 0.1 || p.I != 1e-6 || p.g != 9.81)
      throw std::runtime_error("pendulum parameters differ from clearancePendulumScene");
    nscd::Simulator sim(nscd::loadSceneFromString(
        nscd_test::clearancePendulumScene(p.cr, p.mu, p.rj, p.l, p.theta0, o.h,
                                          o.scheme == Scheme::CombinedProjection, "xy"),
        "clearance_pendulum.urdf", overridesFor(o)));
    runSampled(
        res, p.T, o, [&] { step(sim, res); },
        [&] {
          const nscd::BodyState& b = body(sim);
          // Rotation about z only (planar): angle from the quaternion.
          const double th = 2 * std::atan2(b.q.z(), b.q.w());
          const nscd::Vec3 hole = b.x - b.q * nscd::Vec3(0, -p.l, 0);
          const double ecc = std::hypot(hole.x(), hole.y());
          return Sample{th, ecc / p.cr, ecc - p.cr};
        });
  });
}

}  // namespace nscd_siconos
