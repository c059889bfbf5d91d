// <clearance initial_offset>: journals placed inside their bearings before the
// assembly (journal_placement.cpp), on the C-60's closed loop of clearance joints.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>

#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "step/step_stages.hpp"
#include "test_support.hpp"

using namespace nscd;
using nscd_test::scenePath;

namespace {

std::string readText(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// The C-60 scene with `attr` added to the <clearance> of each joint named in offsets.
std::string withOffsets(const std::map<std::string, std::string>& offsets) {
  std::string xml = readText(scenePath("urdf/c60.urdf"));
  for (const auto& [joint, xyz] : offsets) {
    const std::string key = "<clearance joint=\"" + joint + "\"";
    const size_t at = xml.find(key);
    EXPECT_NE(at, std::string::npos) << joint;
    xml.insert(at + key.size(), " initial_offset=\"" + xyz + "\"");
  }
  return xml;
}

std::string xyz(double x, double y, double z) {
  std::ostringstream s;
  s.precision(17);
  s << x << ' ' << y << ' ' << z;
  return s.str();
}

int clearanceIndex(const Model& m, const std::string& name) {
  for (size_t i = 0; i < m.clearance_joints.size(); ++i)
    if (m.clearance_joints[i].name == name) return static_cast<int>(i);
  return -1;
}

}  // namespace

// Radial offsets drawn at random in every joint of the loop and off it (axial 0, so
// the loop closes). The placement puts each journal exactly where the scene says
// and keeps the journals without an offset centred; the assembly projection then
// clears the contacts the turned links now penetrate (the latch and the stops are
// a few um open at ON), which moves some journals a little but keeps every one
// inside its bearing.
TEST(JournalPlacement, JournalsStartWhereTheSceneSays) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  const std::map<std::string, double> radial = {{"J1", 85e-6}, {"J2", 50e-6}, {"J3", 60e-6}, {"J5", 45e-6},
                                                {"J6", 45e-6}, {"J7", 55e-6}, {"S3", 6e-6}};
  std::map<std::string, std::string> offsets;
  std::map<std::string, double> target;
  for (const auto& [name, cr] : radial) {
    const double r = 0.9 * cr * std::sqrt(u(rng)), phi = 2 * M_PI * u(rng);
    offsets[name] = xyz(r * std::cos(phi), r * std::sin(phi), 0);
    target[name] = r / cr;
  }
  const Model model = loadSceneFromString(withOffsets(offsets), "c60_offsets.urdf");
  // The placement alone, before the assembly projection.
  StepWorkspace ws;
  initStepWorkspace(model, ws);
  State placed = initialState(model, ws);
  placeJournals(model, placed);
  Simulator at_placement(model);
  at_placement.setState(placed);
  Simulator sim(model);  // placement and assembly
  for (const auto& [name, ecc] : target) {
    const int c = clearanceIndex(model, name);
    ASSERT_GE(c, 0) << name;
    EXPECT_NEAR(at_placement.clearanceEccentricity(c), ecc, 1e-8) << name;
    EXPECT_LT(sim.clearanceEccentricity(c), 1.0) << name;
    std::printf("%s: drawn %.4f, placed %.4f, after assembly %.4f (of c_r)\n", name.c_str(), ecc,
                at_placement.clearanceEccentricity(c), sim.clearanceEccentricity(c));
  }
  // J4 (the trip bar) has no offset: its journal stays centred while the plate moves.
  EXPECT_LT(at_placement.clearanceEccentricity(clearanceIndex(model, "J4")), 1e-6);
  EXPECT_LT(sim.constraintViolation(), 1e-9);
  // The placement moved the links (the loop's offsets do not add up): it is not a no-op.
  Simulator centred(loadScene(scenePath("urdf/c60.urdf")));
  EXPECT_GT((placed.bodies[0].x - centred.state().bodies[0].x).norm(), 1e-6);
  double turn = 0;
  for (size_t b = 0; b < placed.bodies.size(); ++b)
    turn = std::max(turn, placed.bodies[b].q.angularDistance(initialState(model, ws).bodies[b].q));
  std::printf("largest turn of a link by the placement: %.3g rad\n", turn);
}

// Axial offsets are differences of the bodies' axial positions: around a closed
// loop they must add up. One journal shifted axially alone cannot be placed.
TEST(JournalPlacement, AnAxialOffsetTheLoopCannotCloseIsRefused) {
  const std::string xml = withOffsets({{"J1", xyz(0, 0, 40e-6)}, {"S3", xyz(0, 0, 0)}, {"J2", xyz(0, 0, 0)},
                                       {"J3", xyz(0, 0, 0)}, {"J5", xyz(0, 0, 0)}, {"J6", xyz(0, 0, 0)}});
  try {
    Simulator sim(loadSceneFromString(xml, "c60_axial.urdf"));
    FAIL() << "an axial offset around a closed loop was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("c60_axial.urdf: assembly failed: the journals cannot be placed"),
              std::string::npos)
        << e.what();
  }
}

// An offset outside the clearance is a scene error naming the line.
TEST(JournalPlacement, AnOffsetOutsideTheBearingIsASceneError) {
  for (const std::string& bad : {xyz(90e-6, 0, 0), xyz(0, 0, 60e-6), std::string("1e-6 nan 0"), std::string("1e-6 0")}) {
    try {
      loadSceneFromString(withOffsets({{"J1", bad}}), "c60_bad.urdf");
      FAIL() << "accepted initial_offset=" << bad;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("c60_bad.urdf:"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("initial_offset"), std::string::npos) << e.what();
    }
  }
}
