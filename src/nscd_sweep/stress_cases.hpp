// Randomised clearance-joint scenes for the stress suite: a one- or two-link
// pendulum in the x-y plane whose hinges have radial and axial clearance, with
// random clearance, friction, restitution, time step, mass ratio and initial
// velocities. Case k of seed s is the same on every machine and thread count.
#pragma once

#include <cstdint>
#include <string>

namespace nscd::sweep {

struct StressRanges {
  double radial_lo = 1e-6, radial_hi = 1e-3;   // m, log-uniform
  double dt_lo = 1e-6, dt_hi = 1e-3;           // s, log-uniform
  double ratio_lo = 1e-3, ratio_hi = 1e3;      // m2/m1 (or m1/0.1 kg for one link), log-uniform
  double spin = 10;                            // |wz| <= spin, rad/s
  double tilt_spin = 2;                        // |wx|, |wy| <= tilt_spin (3D cases), rad/s
  double jolt = 0.05;                          // |v_i| <= jolt added to each COM velocity, m/s
};

struct StressCase {
  long index = 0;
  int links = 2;
  bool planar = false;
  double radial = 0, mu = 0, e = 0, dt = 0, mass_ratio = 1;
  double m1 = 0.1, m2 = 0.1;
  double theta1 = 0, theta2 = 0;
  double energy_scale = 0;  // sum of m_i |g| l_tot: the potential energy range of the scene, J
  std::string urdf;         // the scene, loadable by nscd_run
};

StressCase makeStressCase(std::uint64_t seed, long index, const StressRanges& ranges = {});

}  // namespace nscd::sweep
