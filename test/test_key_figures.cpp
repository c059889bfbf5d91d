// The key figures (~key_figures of the node) carry the CSV's names in the CSV's
// order, and the same values as the simulator's queries.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "nscd_sim/key_figures.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "test_support.hpp"

using namespace nscd;

TEST(KeyFigures, NamesAreTheCsvColumnsInOrder) {
  const std::string scene = nscd_test::scenePath("urdf/c60.urdf");
  const std::string csv = nscd_test::writeTemp("", ".csv");
  const auto r = nscd_test::runNscd("'" + scene + "' --duration 0 --quiet --csv '" + csv + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream f(csv);
  std::string header;
  std::getline(f, header);
  std::vector<std::string> columns;
  std::stringstream ss(header);
  for (std::string c; std::getline(ss, c, ',');) columns.push_back(c);
  // The figures follow the body columns and precede "iters,residual".
  const Model m = loadScene(scene);
  const std::vector<std::string> names = keyFigureNames(m);
  const size_t first = 1 + 13 * m.bodies.size();
  ASSERT_EQ(columns.size(), first + names.size() + 2);
  for (size_t i = 0; i < names.size(); ++i) EXPECT_EQ(names[i], columns[first + i]) << i;
  for (const char* n : {"J1.q", "J4.ecc", "C7.fn", "C4.gap", "probe.cmd", "handle.effort"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
}

TEST(KeyFigures, ValuesAreTheSimulatorsAndDoNotAllocate) {
  Simulator sim(loadScene(nscd_test::scenePath("urdf/c60.urdf")));
  for (int k = 0; k < 50; ++k) sim.step();
  const std::vector<std::string> names = keyFigureNames(sim.model());
  std::vector<double> v;
  keyFigureValues(sim, v);
  ASSERT_EQ(v.size(), names.size());
  const int c7 = [&] {
    for (size_t i = 0; i < sim.model().contacts.size(); ++i)
      if (sim.model().contacts[i].name == "C7") return static_cast<int>(i);
    return -1;
  }();
  ASSERT_GE(c7, 0);
  const size_t at = std::find(names.begin(), names.end(), "C7.fn") - names.begin();
  EXPECT_EQ(v[at], sim.contactNormalForce(c7));
  EXPECT_GT(v[at], 1.0);
  const long before = nscd_test::allocationCount();
  keyFigureValues(sim, v);
  EXPECT_EQ(nscd_test::allocationCount(), before);
}

// One figure by index (the node's event conditions): the same number as the whole
// list, for every kind of figure; an index outside the list throws.
TEST(KeyFigures, OneValueByIndexEqualsTheList) {
  Simulator sim(loadScene(nscd_test::scenePath("urdf/c60.urdf")));
  sim.setCommand(0, 0.05);
  for (int k = 0; k < 30; ++k) sim.step();
  std::vector<double> v;
  keyFigureValues(sim, v);
  ASSERT_FALSE(sim.model().springs.empty());  // every kind of figure is checked
  ASSERT_FALSE(sim.model().actuators.empty());
  for (size_t i = 0; i < v.size(); ++i) {
    const double one = keyFigureValue(sim, static_cast<int>(i));
    EXPECT_TRUE(one == v[i] || (std::isnan(one) && std::isnan(v[i]))) << keyFigureNames(sim.model())[i];
  }
  EXPECT_THROW(keyFigureValue(sim, static_cast<int>(v.size())), std::out_of_range);
  EXPECT_THROW(keyFigureValue(sim, -1), std::out_of_range);
}
