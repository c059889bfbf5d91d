// Randomised clearance pendulums for the stress suite (see stress_cases.hpp).
#include "stress_cases.hpp"

#include <cmath>
#include <cstdio>

namespace nscd::sweep {
namespace {

// splitmix64: a fixed, documented generator, so case k never depends on the
// standard library's distribution implementations.
struct Rng {
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double unit() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
  double logUniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
};

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

struct V3 {
  double x, y, z;
};
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
V3 add(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 rotZ(double t, V3 a) { return {std::cos(t) * a.x - std::sin(t) * a.y, std::sin(t) * a.x + std::cos(t) * a.y, a.z}; }

std::string link(const std::string& name, double m, double l) {
  // A slender rod along -y, centre of mass at l/2.
  const double ia = m * l * l / 12.0, ib = m * 1e-5;
  return "  <link name=\"" + name + "\"><inertial><origin xyz=\"0 " + num(-l / 2) +
         " 0\"/><mass value=\"" + num(m) + "\"/><inertia ixx=\"" + num(ia) + "\" iyy=\"" + num(ib) +
         "\" izz=\"" + num(ia) + "\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n";
}

std::string clearance(const std::string& joint, const StressCase& c, double rj) {
  return "  <nscd><clearance joint=\"" + joint + "\" journal=\"parent\" radius=\"" + num(rj) +
         "\" radial=\"" + num(c.radial) + "\" length=\"" + num(4 * rj) + "\" axial=\"" +
         num(2 * c.radial) + "\" mu=\"" + num(c.mu) + "\" e=\"" + num(c.e) + "\"/></nscd>\n";
}

std::string initial(const std::string& link, V3 v, V3 w) {
  return "  <nscd><initial link=\"" + link + "\" vx=\"" + num(v.x) + "\" vy=\"" + num(v.y) +
         "\" vz=\"" + num(v.z) + "\" wx=\"" + num(w.x) + "\" wy=\"" + num(w.y) + "\" wz=\"" +
         num(w.z) + "\"/></nscd>\n";
}

}  // namespace

StressCase makeStressCase(std::uint64_t seed, long index, const StressRanges& r) {
  Rng rng{seed * 0x2545F4914F6CDD1Dull + static_cast<std::uint64_t>(index) * 0x9E3779B97F4A7C15ull};
  rng.next();
  StressCase c;
  c.index = index;
  c.links = rng.unit() < 0.75 ? 2 : 1;
  c.planar = rng.unit() < 0.5;
  c.radial = rng.logUniform(r.radial_lo, r.radial_hi);
  c.mu = rng.unit();
  c.e = rng.unit();
  c.dt = rng.logUniform(r.dt_lo, r.dt_hi);
  c.mass_ratio = rng.logUniform(r.ratio_lo, r.ratio_hi);
  if (c.links == 1) {
    c.m1 = 0.1 * c.mass_ratio;  // one link: the ratio is to the reference 0.1 kg
    c.m2 = 0;
  } else {
    c.m1 = 0.1;
    c.m2 = 0.1 * c.mass_ratio;
  }
  c.theta1 = rng.uniform(-1.5, 1.5);
  c.theta2 = rng.uniform(-1.0, 1.0);
  const double l1 = 0.1, l2 = 0.08, rj = 5e-3, g = 9.81;
  const V3 w1{c.planar ? 0.0 : rng.uniform(-r.tilt_spin, r.tilt_spin),
              c.planar ? 0.0 : rng.uniform(-r.tilt_spin, r.tilt_spin), rng.uniform(-r.spin, r.spin)};
  const V3 w2 = add(w1, V3{0, 0, rng.uniform(-r.spin, r.spin)});
  const V3 jolt1{rng.uniform(-r.jolt, r.jolt), rng.uniform(-r.jolt, r.jolt),
                 c.planar ? 0.0 : rng.uniform(-r.jolt, r.jolt)};
  const V3 jolt2{rng.uniform(-r.jolt, r.jolt), rng.uniform(-r.jolt, r.jolt),
                 c.planar ? 0.0 : rng.uniform(-r.jolt, r.jolt)};
  // Rigid-body velocities of the centres of mass, plus the jolts.
  const V3 com1 = rotZ(c.theta1, {0, -l1 / 2, 0});
  const V3 p2 = rotZ(c.theta1, {0, -l1, 0});
  const V3 com2 = add(p2, rotZ(c.theta1 + c.theta2, {0, -l2 / 2, 0}));
  const V3 v1 = add(cross(w1, com1), jolt1);
  const V3 v2 = add(add(cross(w1, p2), cross(w2, sub(com2, p2))), jolt2);
  c.energy_scale = (c.m1 + c.m2) * g * (l1 + l2);

  std::string s = "<robot name=\"stress_" + std::to_string(index) + "\">\n  <link name=\"world\"/>\n";
  s += link("arm1", c.m1, l1);
  s += "  <joint name=\"hinge1\" type=\"continuous\"><parent link=\"world\"/><child link=\"arm1\"/>"
       "<axis xyz=\"0 0 1\"/></joint>\n";
  s += clearance("hinge1", c, rj);
  s += "  <nscd><initial joint=\"hinge1\" position=\"" + num(c.theta1) + "\"/></nscd>\n";
  s += initial("arm1", v1, w1);
  if (c.links == 2) {
    s += link("arm2", c.m2, l2);
    s += "  <joint name=\"hinge2\" type=\"continuous\"><parent link=\"arm1\"/><child link=\"arm2\"/>"
         "<origin xyz=\"0 " + num(-l1) + " 0\"/><axis xyz=\"0 0 1\"/></joint>\n";
    s += clearance("hinge2", c, rj);
    s += "  <nscd><initial joint=\"hinge2\" position=\"" + num(c.theta2) + "\"/></nscd>\n";
    s += initial("arm2", v2, w2);
  }
  s += "  <nscd><simulation dt=\"" + num(c.dt) + "\" gravity=\"0 " + num(-g) +
       " 0\" projection=\"true\" planar=\"" + (c.planar ? "xy" : "false") + "\"/></nscd>\n</robot>\n";
  c.urdf = s;
  return c;
}

}  // namespace nscd::sweep
