// The Flores-Leine-Glocker slider-crank (urdf/slider_crank.urdf): a crank at
// 150 rad/s on ideal joints. Before the slider first touches its guide nothing
// dissipates, so the energy must stay put; and the problem is symmetric (the
// slider is pinned at its centre of mass and both lower corners strike the
// guide together), so the slider must not tilt.
#include <cmath>

#include <gtest/gtest.h>

#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "test_support.hpp"

using namespace nscd;

namespace {

bool anyContactForce(const Simulator& sim) {
  for (const ContactReport& c : sim.contactPoints())
    if (c.fn > 0) return true;
  return false;
}

double sliderTilt(const Simulator& sim) {
  const int slider = sim.model().findBody("slider");
  const Quat q = sim.state().bodies[slider].q;
  return 2 * std::atan2(q.z(), q.w());
}

}  // namespace

// h = 1e-4: before the first impact (about 1.9 ms, 19 steps) the energy drifts
// by less than 0.1 % (it lost 2.5 % when the joint rows acted on v_{k+1}).
TEST(SliderCrank, EnergyKeptBeforeTheFirstImpact) {
  Simulator sim(loadScene(nscd_test::scenePath("urdf/slider_crank.urdf")));
  const double e0 = sim.energy().total();
  double worst = 0;
  int steps = 0;
  for (; steps < 1000; ++steps) {
    ASSERT_NE(sim.step(), StepStatus::NonFinite);
    if (anyContactForce(sim)) break;
    worst = std::max(worst, std::abs(sim.energy().total() - e0) / e0);
  }
  ASSERT_GT(steps, 10) << "the slider touched its guide too early";
  EXPECT_LT(worst, 1e-3) << "over " << steps << " steps";
}

// 0.2 s (several impacts on both sides of the guide): the slider stays untilted
// (it is driven only through its centre; the corners' impulses keep both lower
// corners together) but for the solver's own error: the tilt in rad stays below
// the solver's tolerance, at the default 1e-8 (1.4e-9 rad) and at 1e-12 (1e-14
// rad). A law that treated the two corners differently would tilt it by far more
// at both.
TEST(SliderCrank, SymmetricSliderDoesNotTilt) {
  for (double tol : {1e-8, 1e-12}) {
    Model model = loadScene(nscd_test::scenePath("urdf/slider_crank.urdf"));
    if (tol == 1e-8) ASSERT_EQ(model.settings.tolerance, tol);  // the default
    model.settings.tolerance = tol;
    Simulator sim(std::move(model));
    double worst = 0;
    int impacts = 0;
    for (int k = 0; k < 2000; ++k) {
      ASSERT_NE(sim.step(), StepStatus::NonFinite);
      impacts += anyContactForce(sim);
      worst = std::max(worst, std::abs(sliderTilt(sim)));
    }
    EXPECT_GT(impacts, 0);
    EXPECT_LT(worst, tol) << "tolerance " << tol;
  }
}
