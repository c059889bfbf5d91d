// What one comparison run does the same way in both engines: the sampling, the
// timing of the stepping loop, the apex detection of the ball, and a failure
// ending the run with RunResult::error. The engine-specific parts (building the
// model, one step, reading a sample) are passed in as functions.
#pragma once

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <vector>

#include "models.hpp"

namespace nscd_siconos {

// CPU time of the calling thread, s.
inline double threadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// One recorded sample: RunResult's a and b, and the penetration at that instant.
struct Sample {
  double a, b, penetration;
};

// Calls run(res) on a fresh result; an exception ends the run, its message goes to
// res.error (the samples recorded so far stay).
template <class Run>
RunResult guardedRun(Run run) {
  RunResult res;
  try {
    run(res);
  } catch (const std::exception& ex) {
    res.error = ex.what();
  }
  return res;
}

// Steps a built model round(T / h) times: step() does one step, sample() reads
// the current Sample. Samples at step 0 and every sample_dt (at least every step);
// wall and CPU time cover the stepping loop only.
template <class Step, class SampleOf>
void runSampled(RunResult& res, double T, const RunOptions& o, Step step, SampleOf sample) {
  const long n = std::lround(T / o.h), every = std::max(1L, std::lround(o.sample_dt / o.h));
  res.t.reserve(n / every + 2);
  res.a.reserve(n / every + 2);
  res.b.reserve(n / every + 2);
  auto record = [&](long k) {
    const Sample s = sample();
    res.t.push_back(k * o.h);
    res.a.push_back(s.a);
    res.b.push_back(s.b);
    res.max_penetration = std::max(res.max_penetration, s.penetration);
  };
  record(0);
  const double cpu0 = threadCpuSeconds();
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 1; k <= n; ++k) {
    step();
    if (k % every == 0) record(k);
  }
  res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  res.cpu_seconds = threadCpuSeconds() - cpu0;
  res.steps = n;
}

// The ball's apexes: after each step, height (of the lowest point) and vertical
// velocity; where the velocity turns from up to down, records h + vz^2 / 2g.
class ApexDetector {
 public:
  explicit ApexDetector(double g) : g_(g) {}
  void update(double height, double vz, std::vector<double>& apex) {
    if (prev_vz_ > 0 && vz <= 0) apex.push_back(height + vz * vz / (2 * g_));
    prev_vz_ = vz;
  }

 private:
  double g_, prev_vz_ = 0;
};

}  // namespace nscd_siconos
