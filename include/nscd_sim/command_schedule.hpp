// Piecewise-linear actuator command schedules ("NAME=t0:v0,t1:v1,..."), as
// nscd_run --command and the node's ~schedule take them, and their binding to
// the actuators of a model (shared by both front ends).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace nscd {

struct Model;
class Simulator;

struct CommandSchedule {
  std::string actuator;
  std::vector<std::pair<double, double>> points;  // (time, value), times non-decreasing

  // Linear between points; the first value before the first time, the last after.
  double value(double t) const;
};

// Parses "NAME=t0:v0,t1:v1,...". Throws std::invalid_argument with a one-line
// message on malformed input (missing '=', bad number, NaN, decreasing times).
CommandSchedule parseCommandSchedule(const std::string& text);

// A schedule and the index of the actuator it drives.
struct BoundSchedule {
  int actuator = -1;
  CommandSchedule schedule;
};

// Parses each text and binds it to the model's actuator of that name, then adds
// the scene's own schedules (Actuator::schedule) of the actuators no text names:
// a text overrides the scene's schedule of its actuator. Throws
// std::invalid_argument with a one-line message on a malformed schedule, an
// actuator the scene does not have ("the scene has no actuator 'x' (actuators:
// a, b)") or two texts for one actuator.
std::vector<BoundSchedule> bindCommandSchedules(const std::vector<std::string>& texts,
                                                const Model& model);

// Sets every scheduled actuator's command to its schedule's value at time t.
void applySchedules(const std::vector<BoundSchedule>& schedules, double t, Simulator& sim);

}  // namespace nscd
