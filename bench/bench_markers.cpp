// What the node saves by building ~contact_markers and ~contacts only while
// someone subscribes: the cost
// of one publication's marker array and contacts message for the C-60 at rest
// (latched: ~30 contact points, 8 clearance joints), next to the cost of one
// engine step. Run: nscd_bench_markers (built with the node; Google Benchmark).
#include <benchmark/benchmark.h>

#include <memory>
#include <string>

#include "contact_markers.hpp"
#include "nscd_sim/ContactArray.h"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "ros_conversions.hpp"

namespace {

// The C-60 after 2 ms at rest (contacts established).
nscd::Simulator& c60() {
  static std::unique_ptr<nscd::Simulator> sim = [] {
    auto s = std::make_unique<nscd::Simulator>(
        nscd::loadScene(std::string(NSCD_SOURCE_DIR) + "/urdf/c60.urdf"));
    for (int k = 0; k < 200; ++k) s->step();
    return s;
  }();
  return *sim;
}

void BM_C60Step(benchmark::State& state) {
  nscd::Simulator& sim = c60();
  for (auto _ : state) sim.step();
  state.counters["contacts"] = static_cast<double>(sim.contactPoints().size());
}
BENCHMARK(BM_C60Step)->Unit(benchmark::kMicrosecond);

// One publication of ~contact_markers: eccentricity views + the marker array.
void BM_C60MarkerArray(benchmark::State& state) {
  nscd::Simulator& sim = c60();
  std::vector<nscd_node::EccentricityView> ecc(sim.model().clearance_joints.size());
  nscd_node::MarkerStyle style;
  visualization_msgs::MarkerArray msg;
  for (auto _ : state) {
    for (size_t i = 0; i < ecc.size(); ++i)
      ecc[i] = nscd_node::eccentricityView(sim, static_cast<int>(i));
    nscd_node::buildContactMarkers(sim.contactPoints(), ecc, style, ros::Time(1.0), msg);
    benchmark::DoNotOptimize(msg.markers.data());
  }
  state.counters["markers"] = static_cast<double>(msg.markers.size());
}
BENCHMARK(BM_C60MarkerArray)->Unit(benchmark::kMicrosecond);

// One publication of ~contacts.
void BM_C60ContactsMessage(benchmark::State& state) {
  nscd::Simulator& sim = c60();
  nscd_sim::ContactArray msg;
  for (auto _ : state) {
    const auto& reports = sim.contactPoints();
    msg.contacts.resize(reports.size());
    for (size_t i = 0; i < reports.size(); ++i)
      nscd_node::toContactMsg(sim.model(), reports[i], msg.contacts[i]);
    benchmark::DoNotOptimize(msg.contacts.data());
  }
}
BENCHMARK(BM_C60ContactsMessage)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
