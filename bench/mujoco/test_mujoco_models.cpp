// The MuJoCo comparison's models (bench/mujoco): the engine-free references are
// converged, MuJoCo's models have the scenes' masses, inertias and lengths (the same
// energy at the start, and both engines converge to the same reference), and the
// four-bar's start is the one our assembly makes. Built only when MuJoCo is found.
#include <gtest/gtest.h>

#include <cmath>

#include "compare_models.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"

using namespace nscd_mujoco;

namespace {

const std::string kSource = NSCD_SOURCE_DIR;

RunOptions once() {
  RunOptions o;
  o.min_seconds = 0;
  o.max_repetitions = 1;
  return o;
}

}  // namespace

// The references' RK4 step against twice it, at t = 1 s: far below any error the
// comparison measures (its smallest, MuJoCo RK4's, are ~1e-13 rad).
TEST(MujocoModels, ReferencesAreConverged) {
  for (SceneId id : {SceneId::Pendulum, SceneId::DoublePendulum, SceneId::Fourbar}) {
    const Errors e = referenceSelfCheck(id, 1.0);
    EXPECT_LT(e.angle, 1e-11) << scene(id).name;
    EXPECT_LT(e.position, 1e-12) << scene(id).name;
  }
}

// The four-bar's bars after our assembly turn at the rates the reference's
// mass-metric projection of the scene's crank spin gives: the URDF's masses,
// inertias and lengths are the reference's.
TEST(MujocoModels, FourbarStartIsOurAssembly) {
  nscd::Simulator sim(nscd::loadScene(kSource + "/" + scene(SceneId::Fourbar).urdf));
  const std::array<double, 3> joint = fourbarStartJointRates();
  double pitch_rate = 0;
  for (int i = 0; i < 3; ++i) {
    pitch_rate += joint[i];
    const int body = sim.model().findBody(scene(SceneId::Fourbar).links[i]);
    ASSERT_GE(body, 0);
    EXPECT_NEAR(sim.angularVelocityWorld(body).y(), pitch_rate, 1e-9) << scene(SceneId::Fourbar).links[i];
  }
}

// MuJoCo's model of each scene holds the same energy at the start as ours.
TEST(MujocoModels, StartEnergiesAgree) {
  for (const SceneSpec& s : scenes()) {
    nscd::Simulator sim(nscd::loadScene(kSource + "/" + s.urdf));
    const double ours = sim.energy().total(), theirs = mujocoStartEnergy(kSource, s);
    EXPECT_NEAR(theirs, ours, 1e-12 * std::max(1.0, std::abs(ours))) << s.name;
  }
}

// Both engines converge to the same engine-free answer at t = 1 s (MuJoCo's four-bar
// only as far as its soft loop lets it).
TEST(MujocoModels, BothEnginesReachTheReference) {
  const RunOptions o = once();
  for (SceneId id : {SceneId::Pendulum, SceneId::DoublePendulum, SceneId::Fourbar}) {
    const SceneSpec& s = scene(id);
    const EndState ref = referenceEnd(id, o.duration);
    const RunResult ours = runNscd(kSource, s, Method::NscdAdaptive, 1e-5, o);
    ASSERT_TRUE(ours.error.empty()) << ours.error;
    EXPECT_LT(compareEnd(ours.end, ref).angle, 1e-4) << s.name;
    const RunResult theirs = runMujoco(kSource, s, Method::MujocoRk4, id == SceneId::Fourbar ? 1e-4 : 1e-3, o);
    ASSERT_TRUE(theirs.error.empty()) << theirs.error;
    EXPECT_LT(compareEnd(theirs.end, ref).angle, id == SceneId::Fourbar ? 1e-3 : 1e-7) << s.name;
  }
}
