// The two comparison models (bouncing ball, planar clearance pendulum), their
// physical parameters, and one run of each in nscd_sim and in Siconos.
// Both sides record the same samples so that a script can compare them.
#pragma once

#include <string>
#include <vector>

namespace nscd_siconos {

// A sphere dropped on the plane z = 0 (test/physics_scenes.hpp ballScene).
struct BallParams {
  double r = 0.05, m = 1.0, g = 9.81;
  double h0 = 1.0;  // initial height of the lowest point
  double e = 0.8, mu = 0.3;
  double T = 2.5;  // simulated time, s
};

// A point-like arm on a pin with radial clearance, in the x-y plane, gravity -y
// (test/physics_scenes.hpp clearancePendulumScene with planar="xy").
// The pin (radius rj) is fixed at the origin; the hole (radius rj + cr) is at
// the arm's link origin; the centre of mass is l below it in the link frame.
struct PendulumParams {
  double m = 0.1, I = 1e-6, g = 9.81;
  double l = 0.05, rj = 5e-3, cr = 0.1e-3;
  double mu = 0.1;  // e = 0 at the pin
  double theta0 = 0.5;  // released at rest, hole centred on the pin
  double T = 1.0;
};

enum class Scheme { MoreauJean, CombinedProjection };

struct RunOptions {
  double h = 1e-3;
  double tolerance = 1e-8;  // friction-contact solver (normalised residual)
  int max_iterations = 200;
  Scheme scheme = Scheme::MoreauJean;
  double sample_dt = 1e-3;  // sampling interval of the recorded trajectory (multiple of h)
  // Siconos only: iterate TimeStepping's Newton loop to convergence (its default,
  // SICONOS_TS_NONLINEAR: constraint Jacobians re-evaluated at q_k+1), or take one
  // iteration (SICONOS_TS_LINEAR: Jacobians at q_k, as nscd_sim does).
  bool siconos_newton = true;
};

// Samples at t = k * sample_dt. Ball: a = height of the lowest point, b = x.
// Pendulum: a = arm angle (rad), b = eccentricity |hole centre - pin centre| / cr.
struct RunResult {
  std::vector<double> t, a, b;
  std::vector<double> apex;    // ball: apex heights of the bounces (from z + vz^2 / 2g)
  double wall_seconds = 0;     // stepping loop only (set-up excluded)
  double cpu_seconds = 0;      // CPU time of this thread over the same loop (less load-sensitive)
  long steps = 0;
  double max_penetration = 0;  // largest negative gap seen at the sample instants, m
  long unconverged_steps = 0;  // steps whose solver reported no convergence (ours only)
  std::string error;           // non-empty if the run failed
};

RunResult runBallNscd(const BallParams& p, const RunOptions& o);
RunResult runPendulumNscd(const PendulumParams& p, const RunOptions& o);
RunResult runBallSiconos(const BallParams& p, const RunOptions& o);
RunResult runPendulumSiconos(const PendulumParams& p, const RunOptions& o);

}  // namespace nscd_siconos
