// Piecewise-linear command schedules, and their binding to a model's actuators.
#include "nscd_sim/command_schedule.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "nscd_sim/model.hpp"
#include "nscd_sim/simulator.hpp"
#include "number_text.hpp"

namespace nscd {

double CommandSchedule::value(double t) const {
  if (points.empty()) return 0;
  if (t <= points.front().first) return points.front().second;
  for (size_t i = 1; i < points.size(); ++i) {
    if (t <= points[i].first) {
      const auto& a = points[i - 1];
      const auto& b = points[i];
      const double span = b.first - a.first;
      if (span <= 0) return b.second;
      const double lo = std::min(a.second, b.second), hi = std::max(a.second, b.second);
      const double v = a.second + (b.second - a.second) * (t - a.first) / span;
      if (v >= lo && v <= hi) return v;
      // Values near the largest double (the difference overflows) or times a few
      // subnormal steps apart (the product rounds past b): the convex combination,
      // kept between the two values. The usual form keeps other runs bit for bit.
      const double s = (t - a.first) / span;
      return std::clamp(a.second * (1 - s) + b.second * s, lo, hi);
    }
  }
  return points.back().second;
}

namespace {
double finiteNumber(const std::string& s, const std::string& whole) {
  double v = 0;
  if (!parseNumber(s, v) || !std::isfinite(v))
    throw std::invalid_argument("schedule '" + whole + "': '" + s + "' is not a finite number");
  return v;
}
}  // namespace

CommandSchedule parseCommandSchedule(const std::string& text) {
  CommandSchedule sch;
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::invalid_argument("schedule '" + text + "': expected NAME=t0:v0,t1:v1,...");
  sch.actuator = text.substr(0, eq);
  std::string rest = text.substr(eq + 1);
  if (rest.empty()) throw std::invalid_argument("schedule '" + text + "': no time:value pairs");
  size_t pos = 0;
  while (pos <= rest.size()) {
    size_t comma = rest.find(',', pos);
    if (comma == std::string::npos) comma = rest.size();
    const std::string item = rest.substr(pos, comma - pos);
    const size_t colon = item.find(':');
    if (colon == std::string::npos)
      throw std::invalid_argument("schedule '" + text + "': '" + item + "' is not time:value");
    const double t = finiteNumber(item.substr(0, colon), text);
    const double v = finiteNumber(item.substr(colon + 1), text);
    if (!sch.points.empty() && t < sch.points.back().first)
      throw std::invalid_argument("schedule '" + text + "': times must not decrease");
    sch.points.emplace_back(t, v);
    pos = comma + 1;
  }
  return sch;
}

std::vector<BoundSchedule> bindCommandSchedules(const std::vector<std::string>& texts,
                                                const Model& model) {
  std::vector<BoundSchedule> out;
  for (const std::string& text : texts) {
    BoundSchedule b;
    b.schedule = parseCommandSchedule(text);
    b.actuator = model.findActuator(b.schedule.actuator);
    if (b.actuator < 0) {
      std::string names;
      for (const Actuator& a : model.actuators) names += (names.empty() ? "" : ", ") + a.name;
      throw std::invalid_argument("the scene has no actuator '" + b.schedule.actuator +
                                  "' (actuators: " + (names.empty() ? "none" : names) + ")");
    }
    for (const BoundSchedule& other : out)
      if (other.actuator == b.actuator)
        throw std::invalid_argument("two schedules for actuator '" + b.schedule.actuator + "'");
    out.push_back(std::move(b));
  }
  // The scene's own schedules, for the actuators the texts leave alone.
  for (size_t i = 0; i < model.actuators.size(); ++i) {
    const Actuator& a = model.actuators[i];
    if (a.schedule.empty()) continue;
    bool overridden = false;
    for (const BoundSchedule& other : out) overridden = overridden || other.actuator == static_cast<int>(i);
    if (overridden) continue;
    BoundSchedule b;
    b.actuator = static_cast<int>(i);
    b.schedule.actuator = a.name;
    b.schedule.points = a.schedule;
    out.push_back(std::move(b));
  }
  return out;
}

void applySchedules(const std::vector<BoundSchedule>& schedules, double t, Simulator& sim) {
  for (const BoundSchedule& b : schedules) sim.setCommand(b.actuator, b.schedule.value(t));
}

}  // namespace nscd
