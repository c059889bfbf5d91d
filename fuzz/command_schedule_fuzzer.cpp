// Fuzz target: the command schedule parser (nscd_run --command, the node's
// ~schedule, <actuator schedule="...">). Each input line is one schedule text.
// A parsed schedule's value stays within its points' values at any time; the
// texts are then bound to the actuators of the C-60 scene (probe, handle,
// bar_seating), where a bad binding must be refused with one line.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_support.hpp"
#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/scene_loader.hpp"

namespace {

const nscd::Model& c60() {
  static const nscd::Model m = nscd::loadScene(std::string(NSCD_SOURCE_DIR) + "/urdf/c60.urdf");
  return m;
}

void checkValues(const nscd::CommandSchedule& s) {
  if (s.points.empty()) nscd_fuzz::fail("a schedule parsed without points");
  double lo = s.points[0].second, hi = lo;
  for (size_t i = 0; i < s.points.size(); ++i) {
    const auto& p = s.points[i];
    if (!std::isfinite(p.first) || !std::isfinite(p.second)) nscd_fuzz::fail("a non-finite point was accepted");
    if (i > 0 && p.first < s.points[i - 1].first) nscd_fuzz::fail("decreasing times were accepted");
    lo = std::min(lo, p.second);
    hi = std::max(hi, p.second);
  }
  const double t0 = s.points.front().first, t1 = s.points.back().first;
  for (int i = -2; i <= 18; ++i) {
    const double t = t0 + (t1 - t0) * i / 16.0;
    const double v = s.value(t);
    const double round_off = 1e-12 * std::max(std::abs(lo), std::abs(hi)) + 1e-300;  // subnormals round coarsely
    if (!std::isfinite(v) || v < lo - round_off || v > hi + round_off)
      nscd_fuzz::fail("value(" + std::to_string(t) + ") = " + std::to_string(v) + " outside [" +
                      std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string> texts = nscd_fuzz::lines(data, size);
  for (const std::string& t : texts) {
    try {
      checkValues(nscd::parseCommandSchedule(t));
    } catch (const std::invalid_argument& e) {
      nscd_fuzz::expectOneLine(e.what(), "schedule '");
    }
  }
  try {
    nscd::bindCommandSchedules(texts, c60());
  } catch (const std::invalid_argument& e) {
    nscd_fuzz::expectOneLine(e.what(), "");
  }
  return 0;
}
