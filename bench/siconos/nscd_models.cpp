// The comparison models in nscd_sim: the same scene texts as the physics tests
// (test/physics_scenes.hpp), stepped by nscd::Simulator.
#include <time.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "models.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "physics_scenes.hpp"

namespace nscd_siconos {

namespace {

std::vector<nscd::SettingOverride> overridesFor(const RunOptions& o) {
  auto num = [](double v) { return nscd_test::num(v); };
  return {{"tolerance", num(o.tolerance), "bench"},
          {"max_iterations", std::to_string(o.max_iterations), "bench"},
          {"projection", o.scheme == Scheme::CombinedProjection ? "true" : "false", "bench"}};
}

long stepsOf(double T, double h) { return std::lround(T / h); }
long sampleEvery(const RunOptions& o) { return std::max(1L, std::lround(o.sample_dt / o.h)); }

}  // namespace

double threadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

RunResult runBallNscd(const BallParams& p, const RunOptions& o) {
  RunResult res;
  try {
    // ballScene fixes r = 0.05 and m = 1; the comparison must use the same.
    if (p.r != 0.05 || p.m != 1.0 || p.g != 9.81) throw std::runtime_error("ball parameters differ from ballScene");
    nscd::Simulator sim(nscd::loadSceneFromString(nscd_test::ballScene(p.h0, p.e, p.mu, o.h),
                                                  "ball.urdf", overridesFor(o)));
    const long n = stepsOf(p.T, o.h), every = sampleEvery(o);
    res.t.reserve(n / every + 2);
    res.a.reserve(n / every + 2);
    res.b.reserve(n / every + 2);
    auto record = [&](long k) {
      const nscd::BodyState& b = sim.state().bodies[0];
      res.t.push_back(k * o.h);
      res.a.push_back(b.x.z() - p.r);
      res.b.push_back(b.x.x());
      res.max_penetration = std::max(res.max_penetration, p.r - b.x.z());
    };
    record(0);
    double prev_vz = 0;
    const double cpu0 = threadCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    for (long k = 1; k <= n; ++k) {
      const nscd::StepStatus st = sim.step();
      if (st == nscd::StepStatus::NonFinite) throw std::runtime_error("non-finite state");
      if (st == nscd::StepStatus::NotConverged) ++res.unconverged_steps;
      const nscd::BodyState& b = sim.state().bodies[0];
      const double vz = b.v.z();
      if (prev_vz > 0 && vz <= 0) res.apex.push_back(b.x.z() - p.r + vz * vz / (2 * p.g));
      prev_vz = vz;
      if (k % every == 0) record(k);
    }
    res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    res.cpu_seconds = threadCpuSeconds() - cpu0;
    res.steps = n;
  } catch (const std::exception& ex) {
    res.error = ex.what();
  }
  return res;
}

RunResult runPendulumNscd(const PendulumParams& p, const RunOptions& o) {
  RunResult res;
  try {
    if (p.m != 0.1 || p.I != 1e-6 || p.g != 9.81)
      throw std::runtime_error("pendulum parameters differ from clearancePendulumScene");
    nscd::Simulator sim(nscd::loadSceneFromString(
        nscd_test::clearancePendulumScene(p.cr, p.mu, p.rj, p.l, p.theta0, o.h,
                                          o.scheme == Scheme::CombinedProjection, "xy"),
        "clearance_pendulum.urdf", overridesFor(o)));
    const long n = stepsOf(p.T, o.h), every = sampleEvery(o);
    res.t.reserve(n / every + 2);
    res.a.reserve(n / every + 2);
    res.b.reserve(n / every + 2);
    auto record = [&](long k) {
      const nscd::BodyState& b = sim.state().bodies[0];
      // Rotation about z only (planar): angle from the quaternion.
      const double th = 2 * std::atan2(b.q.z(), b.q.w());
      const nscd::Vec3 hole = b.x - b.q * nscd::Vec3(0, -p.l, 0);
      const double ecc = std::hypot(hole.x(), hole.y());
      res.t.push_back(k * o.h);
      res.a.push_back(th);
      res.b.push_back(ecc / p.cr);
      res.max_penetration = std::max(res.max_penetration, ecc - p.cr);
    };
    record(0);
    const double cpu0 = threadCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    for (long k = 1; k <= n; ++k) {
      const nscd::StepStatus st = sim.step();
      if (st == nscd::StepStatus::NonFinite) throw std::runtime_error("non-finite state");
      if (st == nscd::StepStatus::NotConverged) ++res.unconverged_steps;
      if (k % every == 0) record(k);
    }
    res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    res.cpu_seconds = threadCpuSeconds() - cpu0;
    res.steps = n;
  } catch (const std::exception& ex) {
    res.error = ex.what();
  }
  return res;
}

}  // namespace nscd_siconos
