// The step-size controller of adaptive steps (adaptive_step.hpp): a PI controller
// (Gustafsson 1991; Hairer-Wanner II, IV.2), h_new = h fac err_n^-a err_{n-1}^b
// with a = 0.7/k, b = 0.4/k for an error estimate of order k = 2 in h (the
// difference of two paths of a first-order scheme), a safety factor,
// limits on the change per step, no growth right after a rejection, and a floor;
// for smooth steps extrapolated further (max_order > 2), the order and length
// control of extrapolation codes (extrapolationStepLength).
#include <algorithm>
#include <cmath>
#include <vector>

#include "adaptive_step.hpp"

namespace nscd {
namespace {

constexpr double kOrder = 2;  // k
constexpr double kSafety = 0.9;
constexpr double kMaxGrowth = 5, kMaxShrink = 0.2;
// Errors below this count as this: a step with no error at all grows by kMaxGrowth
// without the PI term's memory of it stalling the next one.
constexpr double kErrorFloor = 1e-6;

}  // namespace

StepLengths stepLengths(const Settings& set) {
  StepLengths lim;
  lim.h_max = set.dt;
  lim.h_min = std::min(set.dt, set.dt_min > 0 ? set.dt_min : 1e-6 * set.dt);
  return lim;
}

double nextStepLength(const StepLengths& lim, double h, double error, double previous_error,
                      bool after_rejection) {
  const double e = std::max(error, kErrorFloor);
  double factor = kSafety * std::pow(e, -0.7 / kOrder);
  if (previous_error > 0) factor *= std::pow(std::max(previous_error, kErrorFloor), 0.4 / kOrder);
  else factor = kSafety * std::pow(e, -1 / kOrder);  // no memory yet: the I controller
  factor = std::clamp(factor, kMaxShrink, after_rejection ? 1.0 : kMaxGrowth);
  return std::clamp(h * factor, lim.h_min, lim.h_max);
}

// h within planStep's rounding of dt: a step cut to end on a time may fall short of it by that.
bool atLargestStep(const StepLengths& lim, double h) { return h >= lim.h_max * (1 - 1e-9); }

bool cappedWellWithinTolerance(const StepLengths& lim, double h, double error) {
  // The I controller's factor at that error (nextStepLength without memory).
  const double factor = kSafety * std::pow(std::max(error, kErrorFloor), -1 / kOrder);
  return atLargestStep(lim, h) && factor >= 2;
}

double retryStepLength(const StepLengths& lim, double h, double error) {
  const double factor = std::isfinite(error) ? kSafety * std::pow(error, -1 / kOrder) : kMaxShrink;
  return std::max(lim.h_min, h * std::clamp(factor, kMaxShrink, kSafety));
}

double extrapolationStepLength(const StepLengths& lim, double h, const std::vector<double>& errors, int order,
                               int max_order, double at_most) {
  // Substeps of levels 0 .. k-1: 2 + 4 + ... + 2k.
  auto work = [](int k) { return static_cast<double>(k * (k + 1)); };
  double best_length = 0, best_work = INFINITY;
  int best = 2;
  for (int k = 2; k <= order; ++k) {
    const double e = std::max(errors[k], kErrorFloor);
    const double factor = std::isfinite(e) ? kSafety * std::pow(e, -1.0 / k) : kMaxShrink;
    const double length = h * std::clamp(factor, kMaxShrink, kMaxGrowth);
    const double w = work(k) / length;
    if (w < best_work) best_work = w, best_length = length, best = k;
  }
  if (best == order && order < max_order && !(at_most < INFINITY)) best_length *= work(order + 1) / work(order);
  best_length = std::min(best_length, at_most * h);
  return std::clamp(best_length, lim.h_min, lim.h_max);
}

}  // namespace nscd
