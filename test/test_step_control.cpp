// Adaptive step control (Settings::step_control = adaptive; docs/step_control.md):
// analytic cases followed to within their tolerance, the error against a converged
// reference below the tolerance, events located, commands followed to their
// corners, runs deterministic and restorable, and the fixed default untouched.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/scheduled_step.hpp"
#include "nscd_sim/simulator.hpp"
#include "physics_scenes.hpp"
#include "step/adaptive_step.hpp"

using namespace nscd;
using namespace nscd_test;

namespace {

std::vector<SettingOverride> adaptive(double tol, double dt_max) {
  return {{"step_control", "adaptive", "test"},
          {"rtol", num(tol), "test"},
          {"atol", num(tol), "test"},
          {"dt", num(dt_max), "test"}};
}

Simulator makeSim(const std::string& xml, const std::vector<SettingOverride>& o) {
  return Simulator(loadSceneFromString(xml, "test.urdf", o));
}

// theta'' = -k sin(theta), integrated by RK4 with steps of at most 1e-4 s: the
// pendulum's converged reference (error ~1e-15 over seconds).
class PendulumReference {
 public:
  PendulumReference(double k, double theta0) : k_(k), y_{theta0, 0} {}
  // Angle and rate at time t >= the last time asked.
  std::array<double, 2> at(double t) {
    while (t_ < t) {
      const double h = std::min(1e-4, t - t_);
      auto f = [&](const std::array<double, 2>& y) { return std::array<double, 2>{y[1], -k_ * std::sin(y[0])}; };
      auto add = [](const std::array<double, 2>& y, const std::array<double, 2>& d, double s) {
        return std::array<double, 2>{y[0] + s * d[0], y[1] + s * d[1]};
      };
      const auto k1 = f(y_), k2 = f(add(y_, k1, h / 2)), k3 = f(add(y_, k2, h / 2)), k4 = f(add(y_, k3, h));
      for (int i = 0; i < 2; ++i) y_[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
      t_ += h;
    }
    return y_;
  }

 private:
  double k_;
  std::array<double, 2> y_;
  double t_ = 0;
};

struct RunCount {
  long steps = 0, rejected = 0, extrapolated = 0;
  double h_min = INFINITY, h_max = 0;
};

// Steps to `duration` as the front ends do (scheduled_step.hpp), calling
// `each` after every step.
RunCount runTo(Simulator& sim, double duration, const std::function<void()>& each = {}) {
  RunCount c;
  for (long k = 1; !runFinished(sim, k - 1, duration); ++k) {
    prepareScheduledStep(sim, {}, k, duration);
    EXPECT_EQ(sim.step(), StepStatus::Ok) << "at t = " << sim.state().t;
    const StepStats& s = sim.stats();
    ++c.steps;
    c.rejected += s.rejected;
    c.extrapolated += s.extrapolated;
    c.h_min = std::min(c.h_min, s.h);
    c.h_max = std::max(c.h_max, s.h);
    if (each) each();
  }
  return c;
}

}  // namespace

// The settings' names and values, and their refusals.
TEST(StepControl, Settings) {
  const std::string xml = pendulumScene(1, 1, 1e-3, 0.5, 1e-3);
  EXPECT_EQ(loadSceneFromString(xml, "t.urdf").settings.step_control, StepControl::Fixed);
  const Model m = loadSceneFromString(xml, "t.urdf",
                                      {{"step_control", "adaptive", "s"}, {"rtol", "1e-5", "s"},
                                       {"atol", "1e-7", "s"}, {"dt_min", "1e-9", "s"}, {"max_order", "4", "s"}});
  EXPECT_EQ(m.settings.step_control, StepControl::Adaptive);
  EXPECT_EQ(m.settings.rtol, 1e-5);
  EXPECT_EQ(m.settings.atol, 1e-7);
  EXPECT_EQ(m.settings.dt_min, 1e-9);
  EXPECT_EQ(m.settings.max_order, 4);
  EXPECT_EQ(loadSceneFromString(xml, "t.urdf").settings.max_order, 6);
  for (const SettingOverride& bad : {SettingOverride{"step_control", "variable", "--set"},
                                     SettingOverride{"rtol", "1", "--set"},
                                     SettingOverride{"atol", "0", "--set"},
                                     SettingOverride{"dt_min", "-1", "--set"},
                                     SettingOverride{"max_order", "1", "--set"},
                                     SettingOverride{"max_order", "13", "--set"},
                                     SettingOverride{"max_order", "4.5", "--set"}}) {
    try {
      loadSceneFromString(xml, "t.urdf", {bad});
      ADD_FAILURE() << bad.key << "=" << bad.value << " was accepted";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("--set: setting '" + bad.key + "'"), std::string::npos) << e.what();
    }
  }
}

// Fixed steps stay what they were: every step is dt, planStep ignores its limit,
// nothing of the controller moves.
TEST(StepControl, FixedIsTheDefaultAndUntouched) {
  Simulator sim = makeSim(pendulumScene(1, 1, 1e-3, 0.5, 1e-3), {});
  EXPECT_EQ(sim.planStep(1e-9), 1e-3);
  for (int k = 0; k < 10; ++k) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    EXPECT_EQ(sim.stats().h, 1e-3);
    EXPECT_EQ(sim.stats().rejected, 0);
    EXPECT_FALSE(sim.stats().extrapolated);
  }
  EXPECT_EQ(sim.state().step_next, 0);
  EXPECT_EQ(sim.state().step_error, 0);
  // The fixed step is the same with the setting spelled out.
  Simulator spelled = makeSim(pendulumScene(1, 1, 1e-3, 0.5, 1e-3), {{"step_control", "fixed", "t"}});
  for (int k = 0; k < 10; ++k) spelled.step();
  EXPECT_EQ(spelled.state().bodies[0].x, sim.state().bodies[0].x);
  EXPECT_EQ(spelled.state().bodies[0].q.coeffs(), sim.state().bodies[0].q.coeffs());
}

// An ideal pendulum released from 60 degrees, steps of up to 0.05 s: at the end of
// every step its angle is within the tolerance of the converged reference over
// 3 s (about 2 periods), and closer at the tighter tolerance. (The extrapolation
// meets both with steps of 0.05 s, raising its order for the tighter one.)
TEST(StepControl, PendulumFollowsTheReferenceWithinTolerance) {
  const double l = 1, m = 1, I = 1e-3, g = 9.81, th0 = M_PI / 3;
  double worst_prev = INFINITY;
  for (double tol : {1e-4, 1e-6}) {
    Simulator sim = makeSim(pendulumScene(l, m, I, th0, 0.05), adaptive(tol, 0.05));
    PendulumReference ref(m * g * l / (I + m * l * l), th0);
    double worst = 0;
    const RunCount c = runTo(sim, 3.0, [&] {
      worst = std::max(worst, std::abs(sim.jointPosition(0) - ref.at(sim.state().t)[0]));
    });
    std::printf("[ figures  ] pendulum 60 deg, 3 s, tol %g: %ld steps (%ld rejected, %ld extrapolated), "
                "h %.3g..%.3g s, max angle error %.3g rad\n",
                tol, c.steps, c.rejected, c.extrapolated, c.h_min, c.h_max, worst);
    EXPECT_LT(worst, tol);
    EXPECT_EQ(c.extrapolated, c.steps);  // no contact: every step extrapolated
    EXPECT_LT(worst, worst_prev);
    EXPECT_LE(c.h_max, 0.05 * (1 + 1e-9));  // the last step may take the end's sliver (planStep)
    worst_prev = worst;
  }
}

// A spring-mass oscillator (k = 100 N/m, m = 1 kg, 0.1 m): x(t) = 0.4 - A cos(w t)
// over 3 periods. The tolerance bounds each step's error (LocalError below); over
// ~400 steps the phase error adds up to about 40 tolerances here (the scheme is
// second order on a linear oscillator, so the extrapolation only keeps that order
// and doubles the fine path's error), and shrinks with the tolerance.
TEST(StepControl, SpringMassFollowsCosine) {
  const double m = 1, k = 100, A = 0.1, w = std::sqrt(k / m);
  double prev = INFINITY;
  for (double tol : {1e-5, 1e-6}) {
    Simulator sim = makeSim(springMassScene(m, k, A, 0.01), adaptive(tol, 0.01));
    double worst = 0;
    const RunCount c = runTo(sim, 3 * 2 * M_PI / w, [&] {
      const double x = sim.state().bodies[0].x.x();
      worst = std::max(worst, std::abs(x - (0.4 + A * std::cos(w * sim.state().t))));
    });
    std::printf("[ figures  ] spring-mass, 3 periods, tol %g: %ld steps (%ld rejected), h %.3g..%.3g s, "
                "max position error %.3g m\n", tol, c.steps, c.rejected, c.h_min, c.h_max, worst);
    EXPECT_LT(worst, 100 * tol);
    EXPECT_LT(worst, 0.3 * prev);
    prev = worst;
  }
}

// A ball dropped from 1 m with e = 0.9 on steps of up to 10 ms: apex heights
// e^(2k) h0 to 1e-4 relative (fixed 0.1 ms steps: 0.5 % in test_physics), the
// first impact located in time to within 1e-4 s of sqrt(2 h0 / g) (the step
// that meets it is short: the controller shrinks around events), and the steps
// that meet the impacts are not extrapolated.
TEST(StepControl, BouncingBallApexHeightsAndImpactTime) {
  const double h0 = 1.0, e = 0.9, r = 0.05, g = 9.81, tol = 1e-6;
  Simulator sim = makeSim(ballScene(h0, e, 0.0, 0.01), adaptive(tol, 0.01));
  std::vector<double> apex;
  double prev_vz = 0, first_impact = -1, impact_h = 0;
  long not_extrapolated = 0;
  const RunCount c = runTo(sim, 2.3, [&] {
    const BodyState& b = sim.state().bodies[0];
    if (prev_vz > 0 && b.v.z() <= 0) apex.push_back(b.x.z() - r + b.v.z() * b.v.z() / (2 * g));
    if (prev_vz < 0 && b.v.z() > 0 && first_impact < 0) {
      first_impact = sim.state().t;
      impact_h = sim.stats().h;
    }
    not_extrapolated += !sim.stats().extrapolated;
    prev_vz = b.v.z();
  });
  std::printf("[ figures  ] ball e=0.9, tol %g: %ld steps (%ld rejected, %ld not extrapolated), h %.3g..%.3g s; "
              "first impact at %.7f s (exact %.7f, its step %.3g s); apexes",
              tol, c.steps, c.rejected, not_extrapolated, c.h_min, c.h_max, first_impact,
              std::sqrt(2 * h0 / g), impact_h);
  for (double a : apex) std::printf(" %.6f", a);
  std::printf(" m\n");
  ASSERT_GE(apex.size(), 2u);
  for (size_t k = 0; k < apex.size(); ++k) {
    const double expected = h0 * std::pow(e, 2 * (k + 1));
    EXPECT_NEAR(apex[k], expected, 1e-4 * expected) << "bounce " << k + 1;
  }
  EXPECT_NEAR(first_impact, std::sqrt(2 * h0 / g), 1e-4);
  EXPECT_LT(impact_h, 1e-4);
  EXPECT_GE(not_extrapolated, 2);  // the impacts
  EXPECT_LT(c.steps, 2.3 / 1e-3);
}

// The four-bar (ideal joints, a loop) driven by its initial crank rate: against a
// converged reference (adaptive at 1e-8), every body's position after 0.2 s is
// within the tolerance (the scheme is first order on it: the extrapolation raises
// the kept answer to second order while the estimate stays that of the first).
TEST(StepControl, FourBarErrorBelowToleranceAgainstConvergedReference) {
  auto finalState = [](double tol, RunCount* count) {
    Simulator sim = makeSim(fourBarScene(M_PI / 2, 5.0, 0.01), adaptive(tol, 0.01));
    const RunCount c = runTo(sim, 0.2);
    if (count) *count = c;
    return sim.state();
  };
  const State ref = finalState(1e-8, nullptr);
  double prev = INFINITY;
  for (double tol : {1e-3, 1e-4, 1e-5}) {
    RunCount c;
    const State s = finalState(tol, &c);
    double err = 0;
    for (size_t i = 0; i < s.bodies.size(); ++i) err = std::max(err, (s.bodies[i].x - ref.bodies[i].x).norm());
    std::printf("[ figures  ] four-bar 0.2 s, tol %g: %ld steps (%ld rejected), h %.3g..%.3g s, "
                "position error vs tol 1e-8: %.3g m\n", tol, c.steps, c.rejected, c.h_min, c.h_max, err);
    EXPECT_LT(err, tol);
    EXPECT_LT(err, prev);
    prev = err;
  }
}

// Each step's own error: from the State a step starts at, a converged reference
// over the step's length h and the adaptive step's answer differ in every
// position, velocity and angular velocity component by less than atol + rtol
// |value|: the promise of the tolerance, on a pendulum, a spring-mass and the
// four-bar, every 10th step. The reference: fixed steps of h/4096 and h/2048
// combined as 2 y(h/4096) - y(h/2048) (the fixed scheme is first order on the
// four-bar: this cancels its first error term); its own error, estimated by its
// difference from the same combination of h/2048 and h/1024, is printed and
// asserted below a fifth of the tolerance. (Plain steps of h/512 were not
// converged enough for the extrapolated answers: their own error is ~5
// tolerances on the four-bar.)
TEST(StepControl, LocalErrorBelowTolerance) {
  const double tol = 1e-6;
  const std::vector<std::pair<std::string, std::string>> scenes = {
      {"pendulum", pendulumScene(1, 1, 1e-3, M_PI / 3, 0.05)},
      {"spring-mass", springMassScene(1, 100, 0.1, 0.01)},
      {"four-bar", fourBarScene(M_PI / 2, 5.0, 0.01)}};
  // Every body's position, velocity and world angular velocity, one after the other.
  auto components = [](const State& s) {
    std::vector<double> c;
    for (const BodyState& b : s.bodies) {
      const Vec3 w = b.q * b.w;
      for (int k = 0; k < 3; ++k) c.insert(c.end(), {b.x[k], b.v[k], w[k]});
    }
    return c;
  };
  auto scaled = [tol](const std::vector<double>& a, const std::vector<double>& b) {
    double worst = 0;
    for (size_t i = 0; i < a.size(); ++i)
      worst = std::max(worst, std::abs(a[i] - b[i]) / (tol + tol * std::max(std::abs(a[i]), std::abs(b[i]))));
    return worst;
  };
  auto combine = [](const std::vector<double>& fine, const std::vector<double>& coarse) {
    std::vector<double> c(fine.size());
    for (size_t i = 0; i < c.size(); ++i) c[i] = 2 * fine[i] - coarse[i];
    return c;
  };
  for (const auto& [name, xml] : scenes) {
    Simulator sim = makeSim(xml, adaptive(tol, 0.01));
    double worst = 0, reference_error = 0;
    long k = 0;
    State start = sim.state();
    runTo(sim, 0.3, [&] {
      if (k++ % 10 == 0) {
        const double h = sim.stats().h;
        auto fixedRun = [&](int n) {
          Simulator ref = makeSim(xml, {{"dt", num(h / n), "test"}});
          ref.setState(start);
          for (int i = 0; i < n; ++i) ref.step();
          return components(ref.state());
        };
        const std::vector<double> r1 = fixedRun(1024), r2 = fixedRun(2048), r4 = fixedRun(4096);
        const std::vector<double> reference = combine(r4, r2);
        worst = std::max(worst, scaled(components(sim.state()), reference));
        reference_error = std::max(reference_error, scaled(combine(r2, r1), reference));
      }
      start = sim.state();
    });
    std::printf("[ figures  ] %s, tol %g: largest local error of a step / tolerance %.3g (the reference's own, "
                "estimated: %.3g)\n", name.c_str(), tol, worst, reference_error);
    EXPECT_LT(worst, 1.0) << name;
    EXPECT_LT(reference_error, 0.2) << name;
  }
}

// The order the extrapolation reaches on a mechanism where nothing is nonsmooth
// (docs/step_control.md, "The order of the scheme, measured"): the four-bar over
// 0.2 s in steps of a fixed length H (dt_min = dt and a tolerance no step meets:
// every step is kept at the floor with every level of the tableau up to
// max_order taken), its bodies' positions against a converged reference
// (max_order 6 at H = 1e-3; its change from H = 2e-3 is printed and asserted
// below 1e-12 m). Halving H from 0.01 to 0.005 (from 0.02 to 0.01 for max_order 5,
// whose error at 0.005 is near the reference's) divides the error by 2^p with the
// observed order p = log2(E(H) / E(H/2)) within [K - 0.3, K + 1] for max_order K,
// both errors at least 5 times the reference's change. The fixed scheme
// (Moreau-Jean) is first order on the four-bar; each level of the tableau adds one.
TEST(StepControl, ExtrapolationOrderOnTheFourBar) {
  auto positions = [](int order, double H) {
    Simulator sim = makeSim(fourBarScene(M_PI / 2, 5.0, 0.01),
                            {{"step_control", "adaptive", "t"}, {"dt", num(H), "t"}, {"dt_min", num(H), "t"},
                             {"rtol", "1e-15", "t"}, {"atol", "1e-15", "t"}, {"max_order", std::to_string(order), "t"}});
    for (long k = 1; !runFinished(sim, k - 1, 0.2); ++k) {
      prepareScheduledStep(sim, {}, k, 0.2);
      EXPECT_NE(sim.step(), StepStatus::NonFinite);
    }
    std::vector<Vec3> x;
    for (const BodyState& b : sim.state().bodies) x.push_back(b.x);
    return x;
  };
  auto distance = [](const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    double d = 0;
    for (size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
    return d;
  };
  const std::vector<Vec3> ref = positions(6, 1e-3);
  const double ref_change = distance(ref, positions(6, 2e-3));
  std::printf("[ figures  ] four-bar 0.2 s, reference (max_order 6, H 1e-3) against H 2e-3: %.3g m\n", ref_change);
  EXPECT_LT(ref_change, 1e-12);
  for (int K : {2, 3, 4, 5}) {
    const double H = K == 5 ? 0.02 : 0.01;
    const double e1 = distance(positions(K, H), ref), e2 = distance(positions(K, H / 2), ref);
    const double p = std::log2(e1 / e2);
    std::printf("[ figures  ] four-bar 0.2 s, max_order %d: error %.3g m at H %g, %.3g m at H %g: order %.2f\n", K,
                e1, H, e2, H / 2, p);
    EXPECT_GT(e2, 5 * ref_change) << K;
    EXPECT_GT(p, K - 0.3) << K;
    EXPECT_LT(p, K + 1.0) << K;
  }
}

// Same input, same bits; a run saved with state() and continued on another
// simulator with setState() continues bit for bit (the controller's memory is in
// the State); reset() starts over to the same bits.
TEST(StepControl, DeterministicAndRestorable) {
  // A clearance pendulum (its contact closed: the coarse and fine paths) and the
  // four-bar (ideal joints: the extrapolation tableau, its order chosen per step).
  const std::vector<std::pair<std::string, std::vector<SettingOverride>>> cases = {
      {clearancePendulumScene(50e-6, 0.1, 2e-3, 0.1, 0.5, 1e-3, true, "false"), adaptive(1e-5, 1e-3)},
      {fourBarScene(M_PI / 2, 5.0, 0.01), adaptive(1e-6, 0.05)}};
  for (const auto& [xml, o] : cases) {
    Simulator a = makeSim(xml, o), b = makeSim(xml, o);
    runTo(a, 0.05);
    runTo(b, 0.05);
    const State mid = a.state();
    EXPECT_GT(mid.step_next, 0);
    EXPECT_EQ(mid.t, b.state().t);
    for (size_t i = 0; i < mid.bodies.size(); ++i) {
      EXPECT_EQ(mid.bodies[i].x, b.state().bodies[i].x);
      EXPECT_EQ(mid.bodies[i].v, b.state().bodies[i].v);
    }
    runTo(a, 0.1);
    Simulator c = makeSim(xml, o);
    c.setState(mid);
    runTo(c, 0.1);
    EXPECT_EQ(a.state().t, c.state().t);
    EXPECT_EQ(a.state().step_next, c.state().step_next);
    for (size_t i = 0; i < mid.bodies.size(); ++i) {
      EXPECT_EQ(a.state().bodies[i].x, c.state().bodies[i].x);
      EXPECT_EQ(a.state().bodies[i].q.coeffs(), c.state().bodies[i].q.coeffs());
      EXPECT_EQ(a.state().bodies[i].w, c.state().bodies[i].w);
    }
    a.reset();
    runTo(a, 0.05);
    EXPECT_EQ(a.state().t, mid.t);
    EXPECT_EQ(a.state().bodies[0].x, mid.bodies[0].x);
    State bad = mid;
    bad.step_next = -1;
    EXPECT_THROW(c.setState(bad), std::invalid_argument);
  }
}

// Warm starts are impulses: a kept adaptive step leaves them scaled to the next
// step's fine substep (step_next / 4), whatever length it was itself. A ball of
// 1 kg resting on the plane takes m g times that from it; a step cut to 0.3 ms
// (its substeps 75 us) leaves 9.81 * 1e-3 / 4 N s for the next step of 1 ms, not
// 9.81 * 0.3e-3 / 4.
TEST(StepControl, WarmStartsScaledToTheNextStep) {
  Simulator sim = makeSim(ballScene(0, 0, 0.5, 1e-3), adaptive(1e-3, 1e-3));
  runTo(sim, 0.05);
  const double t = sim.state().t;
  sim.planStep(t + 0.3e-3);
  ASSERT_EQ(sim.step(), StepStatus::Ok);
  EXPECT_NEAR(sim.stats().h, 0.3e-3, 1e-15);
  const State& s = sim.state();
  EXPECT_EQ(s.step_next, 1e-3);
  ASSERT_TRUE(s.warm_valid[0]);
  EXPECT_NEAR(s.warm[0][0], 9.81 * s.step_next / 4, 1e-3 * 9.81 * s.step_next / 4);
  // And the next step, of 1 ms, starts its fine path from them as they are.
  ASSERT_EQ(sim.step(), StepStatus::Ok);
  EXPECT_NEAR(sim.state().warm[0][0], 9.81 * sim.state().step_next / 4, 1e-3 * 9.81 * 1e-3 / 4);
}

// A prescribed motion with a corner in its schedule: a step ends exactly at the
// corner and at the end of the run, and the joint follows the schedule there.
TEST(StepControl, StepsEndAtScheduleCornersAndTheEnd) {
  const std::string xml = fourBarScene(M_PI / 2, 0.0, 1e-3);
  // Drive the crank joint j1 with a prescribed motion.
  std::string driven = xml;
  const std::string tag = "<nscd><simulation";
  driven.replace(driven.find(tag), 0,
                 "<nscd><actuator name=\"drive\" type=\"prescribed\" joint=\"j1\"/></nscd>\n  ");
  Simulator sim = makeSim(driven, adaptive(1e-6, 1e-2));
  const std::vector<BoundSchedule> sched = bindCommandSchedules({"drive=0:0,0.0137:0.2,0.05:0.2"}, sim.model());
  applySchedules(sched, 0.0, sim);
  bool corner_hit = false;
  double worst = 0;
  for (long k = 1; !runFinished(sim, k - 1, 0.03); ++k) {
    const double end = prepareScheduledStep(sim, sched, k, 0.03);
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    corner_hit = corner_hit || sim.state().t == 0.0137;
    if (sim.state().t == end)  // a step kept whole ends where planned, on the schedule
      worst = std::max(worst, std::abs(sim.jointPosition(0) - sched[0].schedule.value(end)));
  }
  EXPECT_TRUE(corner_hit);
  EXPECT_EQ(sim.state().t, 0.03);
  EXPECT_LT(worst, 1e-9);
}

// A torque whose scene schedule starts away from the actuator's initial command
// (0) and jumps to 0 at a corner: 0.01 N m for 0.1 s, then none, on a bar turning
// freely on a hinge (J = 1.33e-3 kg m^2, no gravity). The steps start from the
// schedule's value just after their start, so the torque is a step function, as
// fixed steps apply it, and the run is smooth between the jumps: a handful of
// steps, none at the floor, and the analytic rate tau 0.1 / J and angle.
// (Interpolated from the initial 0, each step cut short pulled the command back
// towards 0 and the controller ran to the floor at the start.)
TEST(StepControl, ScheduleJumpsAreTakenAtTheStepStart) {
  const std::string urdf = crankScene(
      R"(<actuator name="spin" type="torque" link="bar" axis="0 0 2" schedule="0:0.01,0.1:0.01,0.1:0"/>
  <simulation dt="1e-2" gravity="0 0 0"/>)");
  Simulator sim(loadSceneFromString(urdf, "crank.urdf", adaptive(1e-6, 1e-2)));
  const std::vector<BoundSchedule> sched = bindCommandSchedules({}, sim.model());
  ASSERT_EQ(sched.size(), 1u);
  applySchedules(sched, 0.0, sim);
  const double J = 3.3e-4 + 0.1 * 0.1 * 0.1, tau = 0.01;
  long steps = 0;
  double h_min = INFINITY;
  for (long k = 1; !runFinished(sim, k - 1, 0.2); ++k) {
    prepareScheduledStep(sim, sched, k, 0.2);
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    ++steps;
    h_min = std::min(h_min, sim.stats().h);
    if (sim.state().t == 0.1) {
      EXPECT_NEAR(sim.actuatorEffort(0), tau, 1e-15);
      EXPECT_NEAR(sim.jointVelocity(0), tau * 0.1 / J, 1e-6 * tau * 0.1 / J);
    }
  }
  std::printf("[ figures  ] torque 0.01 N m for 0.1 s from a command of 0, tol 1e-6: %ld steps, h_min %.3g s\n", steps,
              h_min);
  EXPECT_EQ(sim.actuatorEffort(0), 0.0);
  EXPECT_NEAR(sim.jointVelocity(0), tau * 0.1 / J, 1e-6 * tau * 0.1 / J);
  EXPECT_NEAR(sim.jointPosition(0), tau * 0.01 / (2 * J) + tau * 0.1 / J * 0.1, 1e-6);
  EXPECT_LE(steps, 60);
  EXPECT_GE(h_min, 1e-3);
}

namespace {

// The bodies of a path of n substeps of h / n from t = 0: one body whose centre
// moves as x(t) along x and which turns by phi(t) about z, its velocities set to
// v(t) plus `flip` (-1)^i (what the substeps end with need not be what the
// positions move with).
std::vector<std::vector<BodyState>> pathOf(int n, double h, const std::function<double(double)>& x,
                                           const std::function<double(double)>& phi, double flip) {
  std::vector<std::vector<BodyState>> path(n + 1, std::vector<BodyState>(1));
  for (int i = 0; i <= n; ++i) {
    const double t = h * i / n;
    BodyState& b = path[i][0];
    b.x = Vec3(x(t), 0, 0);
    b.q = Quat(Eigen::AngleAxisd(phi(t), Vec3::UnitZ()));
    b.v = Vec3((i % 2 ? -1 : 1) * flip, 0, 0);
    b.w = Vec3::Zero();
  }
  return path;
}

}  // namespace

// The embedded estimate of an event step, against its closed form: for x = c t^3
// the velocities over the substeps (displacement / s) have second differences
// 6 c s^2 exactly, two of them in 4 substeps, counted by n / (2 (n - 2)) = 1
// and times h, over atol (rtol 0); a turn phi = c t^3 at a rotation length r the
// same times r; counted as a velocity, the same without the factor h. A
// uniformly accelerated body whose velocities flip by 0.5 m/s
// every substep (the joints' rows on the theta-average velocity do that) gives 0:
// the positions never move with the flip.
TEST(StepControl, EmbeddedEventErrorClosedForm) {
  const double h = 1e-3, s = h / 4, c = 2.0, atol = 1e-6, r = 0.05;
  const std::vector<double> length{r};
  auto zero = [](double) { return 0.0; };
  const double cubic = embeddedEventError(pathOf(4, h, [&](double t) { return c * t * t * t; }, zero, 0), 4, h,
                                          atol, 0, length);
  EXPECT_NEAR(cubic, h * 12 * c * s * s / atol, 1e-6 * h * 12 * c * s * s / atol);
  const double turn = embeddedEventError(pathOf(4, h, zero, [&](double t) { return c * t * t * t; }, 0), 4, h,
                                         atol, 0, length);
  EXPECT_NEAR(turn, h * 12 * r * c * s * s / atol, 1e-6 * h * 12 * r * c * s * s / atol);
  const double uniform = embeddedEventError(
      pathOf(4, h, [](double t) { return 0.3 + 1.5 * t - 4.905 * t * t; }, [](double t) { return 7 * t * t; }, 0.5),
      4, h, atol, 0, length);
  EXPECT_LT(uniform, 1e-6);
  // A step from 1 m/s to -1 m/s at the second substep's end: two second
  // differences of 2 m/s, times h, over atol + rtol h |u|.
  const double rtol = 1e-3;
  const double impact = embeddedEventError(
      pathOf(4, h, [&](double t) { return t <= 2 * s ? t : 4 * s - t; }, zero, 0), 4, h, atol, rtol, length);
  EXPECT_NEAR(impact, h * 4 / (atol + rtol * h * 1), 1e-6 * h * 4 / (atol + rtol * h));
  // Counted as a velocity (as_velocity): the same sums with weight 1 for h, over
  // atol + rtol |u|.
  const double cubic_v = embeddedEventError(pathOf(4, h, [&](double t) { return c * t * t * t; }, zero, 0), 4, h,
                                            atol, 0, length, true);
  EXPECT_NEAR(cubic_v, 12 * c * s * s / atol, 1e-6 * 12 * c * s * s / atol);
  const double impact_v = embeddedEventError(
      pathOf(4, h, [&](double t) { return t <= 2 * s ? t : 4 * s - t; }, zero, 0), 4, h, atol, rtol, length, true);
  EXPECT_NEAR(impact_v, 4 / (atol + rtol * 1), 1e-6 * 4 / (atol + rtol));
  std::vector<std::vector<BodyState>> bad = pathOf(4, h, zero, zero, 0);
  bad[3][0].x[1] = NAN;
  EXPECT_EQ(embeddedEventError(bad, 4, h, atol, rtol, length), INFINITY);
}

// A step at dt whose fine path had no event and whose own estimate is far within
// the tolerance (cappedWellWithinTolerance: the I controller would ask for twice
// dt) keeps the fine path's answer without taking the coarse path: 4 substep
// problems, where the coarse path would add two. On the clearance pendulum (a
// journal held in its bearing: a contact closed in every substep) at rtol = atol
// 1e-2 and dt 1e-3 most steps are such steps: each solves 4 problems (its own
// solve of each substep at its full length; rescues, halvings and late contacts
// not counted), none extrapolated, where the engine before this rule solved 6 on
// every step at dt without an event. Its arm after 0.2 s is about where the fixed
// run at dt / 4 leaves it: both against a fixed run at dt 1e-6, the adaptive run
// errs by at most 1.5 times the fixed run's error plus 1e-6 m.
TEST(StepControl, CappedStepTakesTheFinePathAlone) {
  const std::string xml = clearancePendulumScene(50e-6, 0.1, 2e-3, 0.1, 0.5, 1e-3);
  Simulator sim = makeSim(xml, adaptive(1e-2, 1e-3));
  int problems = 0;
  sim.setProblemObserver(
      [&](const ProblemView& v) { problems += v.round == 0 && v.resolve == nullptr && v.halvings == 0; });
  long alone = 0, both = 0;
  for (long k = 1; !runFinished(sim, k - 1, 0.2); ++k) {
    prepareScheduledStep(sim, {}, k, 0.2);
    problems = 0;
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    const StepStats& st = sim.stats();
    if (st.rejected > 0 || st.h < 1e-3 * (1 - 1e-9)) continue;
    if (problems == 4 && st.error <= 0.2) {
      ++alone;
      EXPECT_FALSE(st.extrapolated) << "at t = " << sim.state().t;
    } else if (problems == 6) {
      ++both;
    }
  }
  auto endError = [&](const Simulator& s) {
    Simulator ref = makeSim(xml, {{"dt", "1e-6", "test"}});
    for (int i = 0; i < 200000; ++i) ref.step();
    return (s.state().bodies[0].x - ref.state().bodies[0].x).norm();
  };
  Simulator quarter = makeSim(xml, {{"dt", "2.5e-4", "test"}});
  for (int i = 0; i < 800; ++i) quarter.step();
  const double adaptive_error = endError(sim), quarter_error = endError(quarter);
  std::printf("[ figures  ] clearance pendulum, rtol 1e-2, dt 1e-3: %ld steps at dt on the fine path alone, %ld on "
              "both paths; arm at 0.2 s off a dt 1e-6 run by %.3g m (fixed dt 2.5e-4: %.3g m)\n",
              alone, both, adaptive_error, quarter_error);
  EXPECT_GT(alone, 150);
  EXPECT_LT(both, alone / 10);
  EXPECT_LT(adaptive_error, 1.5 * quarter_error + 1e-6);
}

// The threshold of a step kept on its fine path alone: at dt (to planStep's
// rounding) and an error at which the I controller's factor 0.9 error^-1/2 is at
// least 2, error <= 0.2025.
TEST(StepControl, CappedWellWithinToleranceThreshold) {
  const StepLengths lim{1e-9, 1e-3};
  EXPECT_TRUE(cappedWellWithinTolerance(lim, 1e-3, 0.0));
  EXPECT_TRUE(cappedWellWithinTolerance(lim, 1e-3, 0.20));
  EXPECT_FALSE(cappedWellWithinTolerance(lim, 1e-3, 0.21));
  EXPECT_FALSE(cappedWellWithinTolerance(lim, 1e-3, INFINITY));
  EXPECT_FALSE(cappedWellWithinTolerance(lim, 1e-3, NAN));
  EXPECT_TRUE(cappedWellWithinTolerance(lim, 1e-3 * (1 - 1e-10), 0.1));
  EXPECT_FALSE(cappedWellWithinTolerance(lim, 1e-3 * (1 - 1e-8), 0.1));
}
