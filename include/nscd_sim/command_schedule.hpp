// Piecewise-linear actuator command schedules ("t0:v0,t1:v1,...") for headless runs.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace nscd {

struct CommandSchedule {
  std::string actuator;
  std::vector<std::pair<double, double>> points;  // (time, value), times non-decreasing

  // Linear between points; the first value before the first time, the last after.
  double value(double t) const;
};

// Parses "NAME=t0:v0,t1:v1,...". Throws std::invalid_argument with a one-line
// message on malformed input (missing '=', bad number, NaN, decreasing times).
CommandSchedule parseCommandSchedule(const std::string& text);

}  // namespace nscd
