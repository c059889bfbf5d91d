// Converged references of the comparison scenes, independent of both engines: each
// mechanism's equations of motion in its own minimal coordinates, integrated by
// classical RK4 with a step small enough that halving it changes nothing that
// matters (referenceSelfCheck); the ball in closed form.
//
// Planar conventions: the mechanisms move in the x-z plane and turn about +y. A
// rotation by p about +y takes the direction (0, 0, -1) to (-sin p, 0, -cos p) and
// (1, 0, 0) to (cos p, 0, -sin p).
#include <cmath>
#include <functional>

#include "compare_models.hpp"

namespace nscd_mujoco {
namespace {

constexpr double kG = 9.81;
constexpr double kPi = 3.14159265358979323846;
constexpr long kReferenceSteps = 1L << 16;  // per second of simulated time

using Vec2 = std::array<double, 2>;  // (x, z)
Vec2 dir(double a) { return {std::cos(a), std::sin(a)}; }      // the bar at angle a from +x towards +z
Vec2 perp(double a) { return {-std::sin(a), std::cos(a)}; }    // d dir / da
Vec2 operator+(Vec2 a, Vec2 b) { return {a[0] + b[0], a[1] + b[1]}; }
Vec2 operator-(Vec2 a, Vec2 b) { return {a[0] - b[0], a[1] - b[1]}; }
Vec2 operator*(double s, Vec2 a) { return {s * a[0], s * a[1]}; }
double dot(Vec2 a, Vec2 b) { return a[0] * b[0] + a[1] * b[1]; }
std::array<double, 3> world(Vec2 p) { return {p[0], 0.0, p[1]}; }

// State y of a first-order system, its derivative f(y), n steps of RK4 over [0, t].
using Ode = std::function<std::vector<double>(const std::vector<double>&)>;
std::vector<double> rk4(const Ode& f, std::vector<double> y, double t, long n) {
  const double h = t / n;
  const size_t m = y.size();
  std::vector<double> tmp(m);
  for (long k = 0; k < n; ++k) {
    const std::vector<double> k1 = f(y);
    for (size_t i = 0; i < m; ++i) tmp[i] = y[i] + 0.5 * h * k1[i];
    const std::vector<double> k2 = f(tmp);
    for (size_t i = 0; i < m; ++i) tmp[i] = y[i] + 0.5 * h * k2[i];
    const std::vector<double> k3 = f(tmp);
    for (size_t i = 0; i < m; ++i) tmp[i] = y[i] + h * k3[i];
    const std::vector<double> k4 = f(tmp);
    for (size_t i = 0; i < m; ++i) y[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
  }
  return y;
}

// ---- urdf/pendulum.urdf: 1 kg, centre of mass 1 m below the hinge, I = 1e-3 about it.
struct Pendulum {
  double m = 1, a = 1, I = 1e-3, theta0 = kPi / 6;
  std::vector<double> rate(const std::vector<double>& y) const {
    return {y[1], -m * kG * a * std::sin(y[0]) / (m * a * a + I)};
  }
  EndState end(const std::vector<double>& y) const {
    return {{y[0]}, {{-a * std::sin(y[0]), 0.0, -a * std::cos(y[0])}}};
  }
};

// ---- test/scenes/double_pendulum.urdf: two rods of length L and mass m, centres of
// mass at L/2, I about y through them; absolute pitches phi1, phi2 (Lagrange).
struct DoublePendulum {
  double m = 1, L = 0.5, a = 0.25, I = 0.020833333333333332;
  std::vector<double> rate(const std::vector<double>& y) const {
    const double p1 = y[0], p2 = y[1], w1 = y[2], w2 = y[3];
    const double c = m * L * a, s = std::sin(p1 - p2);
    const double M11 = m * a * a + I + m * L * L, M12 = c * std::cos(p1 - p2), M22 = m * a * a + I;
    const double r1 = -c * s * w2 * w2 - (m * a + m * L) * kG * std::sin(p1);
    const double r2 = c * s * w1 * w1 - m * a * kG * std::sin(p2);
    const double det = M11 * M22 - M12 * M12;
    return {w1, w2, (M22 * r1 - M12 * r2) / det, (M11 * r2 - M12 * r1) / det};
  }
  EndState end(const std::vector<double>& y) const {
    auto d = [](double p) { return std::array<double, 2>{-std::sin(p), -std::cos(p)}; };
    const auto d1 = d(y[0]), d2 = d(y[1]);
    return {{y[0], y[1]},
            {{a * d1[0], 0.0, a * d1[1]}, {L * d1[0] + a * d2[0], 0.0, L * d1[1] + a * d2[1]}}};
  }
};

// ---- urdf/fourbar.urdf: crank O2B, coupler BC, rocker C O4; bar k at angle a_k from
// +x towards +z (its link's pitch is -a_k); one degree of freedom, the crank angle a2.
// The coupler and rocker follow from the loop's position, velocity and acceleration
// analysis; the crank's equation is the principle of virtual power over the three
// bars with the velocity coefficients as virtual velocities.
struct Fourbar {
  double r2 = 0.1, r3 = 0.4, r4 = 0.3;
  Vec2 o4{0.4, 0.0};
  std::array<double, 3> m{0.1, 0.4, 0.3};
  std::array<double, 3> I{8.333333333333333e-5, 5.333333333333333e-3, 2.25e-3};

  struct Kinematics {
    std::array<double, 3> a;   // bar angles
    std::array<double, 3> u;   // d a_k / d a2
    std::array<Vec2, 3> com;   // centres of mass
    std::array<Vec2, 3> J;     // d com_k / d a2
  };

  // The upper assembly branch (C above the line B O4), the start's; a crank-rocker
  // (Grashof, crank shortest and next to the ground) never leaves it.
  Kinematics at(double a2) const {
    Kinematics k;
    const Vec2 B = r2 * dir(a2), d = o4 - B;
    const double dist = std::sqrt(dot(d, d));
    const Vec2 u = (1 / dist) * d, n{-u[1], u[0]};
    const double along = (r3 * r3 - r4 * r4 + dist * dist) / (2 * dist);
    const Vec2 C = B + along * u + std::sqrt(r3 * r3 - along * along) * n;
    k.a = {a2, std::atan2(C[1] - B[1], C[0] - B[0]), std::atan2(o4[1] - C[1], o4[0] - C[0])};
    // r2 e'(a2) + r3 e'(a3) u3 + r4 e'(a4) u4 = 0
    solveLoop(k.a, -1.0 * (r2 * perp(a2)), k.u[1], k.u[2]);
    k.u[0] = 1;
    k.com = {0.5 * r2 * dir(a2), B + 0.5 * r3 * dir(k.a[1]), C + 0.5 * r4 * dir(k.a[2])};
    const Vec2 JB = r2 * perp(a2), JC = JB + (r3 * k.u[1]) * perp(k.a[1]);
    k.J = {0.5 * r2 * perp(a2), JB + (0.5 * r3 * k.u[1]) * perp(k.a[1]), JC + (0.5 * r4 * k.u[2]) * perp(k.a[2])};
    return k;
  }

  // Solves r3 e'(a3) x3 + r4 e'(a4) x4 = rhs (Cramer).
  void solveLoop(const std::array<double, 3>& a, Vec2 rhs, double& x3, double& x4) const {
    const Vec2 c3 = r3 * perp(a[1]), c4 = r4 * perp(a[2]);
    const double det = c3[0] * c4[1] - c3[1] * c4[0];
    x3 = (rhs[0] * c4[1] - rhs[1] * c4[0]) / det;
    x4 = (c3[0] * rhs[1] - c3[1] * rhs[0]) / det;
  }

  double crankAcceleration(double a2, double w2) const {
    const Kinematics k = at(a2);
    const std::array<double, 3> w{w2, k.u[1] * w2, k.u[2] * w2};
    // The bars' angular accelerations at a2'' = 0 (beta) and their centres' (gamma).
    const Vec2 centripetal = r2 * w[0] * w[0] * dir(k.a[0]) + r3 * w[1] * w[1] * dir(k.a[1]) +
                             r4 * w[2] * w[2] * dir(k.a[2]);
    std::array<double, 3> beta{0, 0, 0};
    solveLoop(k.a, centripetal, beta[1], beta[2]);
    const Vec2 accB = -r2 * w[0] * w[0] * dir(k.a[0]);
    const Vec2 tip3 = r3 * beta[1] * perp(k.a[1]) - r3 * w[1] * w[1] * dir(k.a[1]);
    const Vec2 tip4 = r4 * beta[2] * perp(k.a[2]) - r4 * w[2] * w[2] * dir(k.a[2]);
    const std::array<Vec2, 3> gamma{0.5 * accB, accB + 0.5 * tip3, accB + tip3 + 0.5 * tip4};
    const Vec2 g{0, -kG};
    double num = 0, den = 0;
    for (int i = 0; i < 3; ++i) {
      num += m[i] * dot(g, k.J[i]) - m[i] * dot(k.J[i], gamma[i]) - I[i] * k.u[i] * beta[i];
      den += m[i] * dot(k.J[i], k.J[i]) + I[i] * k.u[i] * k.u[i];
    }
    return num / den;
  }

  // The scene gives the crank 5 rad/s about +y (a2' = -5) and its centre of mass the
  // matching velocity, the other bars none; the assembly keeps the generalised
  // momentum of that motion: a2' = J^T M v0 / (J^T M J).
  double startRate() const {
    const Kinematics k = at(kPi / 2);
    const double w0 = -5.0;
    const Vec2 v0 = w0 * k.J[0];
    double den = 0;
    for (int i = 0; i < 3; ++i) den += m[i] * dot(k.J[i], k.J[i]) + I[i] * k.u[i] * k.u[i];
    return (m[0] * dot(k.J[0], v0) + I[0] * w0) / den;
  }

  std::vector<double> rate(const std::vector<double>& y) const { return {y[1], crankAcceleration(y[0], y[1])}; }
  EndState end(const std::vector<double>& y) const {
    const Kinematics k = at(y[0]);
    EndState e;
    for (int i = 0; i < 3; ++i) {
      e.pitch.push_back(-k.a[i]);
      e.com.push_back(world(k.com[i]));
    }
    return e;
  }
};

// ---- urdf/ball.urdf: dropped with its lowest point h0 above the plane, restitution e.
EndState ballEnd(double t) {
  const double r = 0.05, h0 = 1.0, e = 0.9;
  double z = r + h0, vz = 0, t0 = 0;  // the state at time t0, in flight from there
  for (int bounce = 0; bounce < 1000; ++bounce) {
    // Lands when z + vz s - g s^2 / 2 = r.
    const double s = (vz + std::sqrt(vz * vz + 2 * kG * (z - r))) / kG;
    if (t0 + s >= t) break;
    vz = -e * (vz - kG * s);
    z = r;
    t0 += s;
  }
  const double s = t - t0;
  return {{0.0}, {{0.0, 0.0, z + vz * s - 0.5 * kG * s * s}}};
}

EndState referenceWith(SceneId id, double t, long n) {
  switch (id) {
    case SceneId::Pendulum: {
      const Pendulum p;
      return p.end(rk4([&](const std::vector<double>& y) { return p.rate(y); }, {p.theta0, 0.0}, t, n));
    }
    case SceneId::DoublePendulum: {
      const DoublePendulum p;
      return p.end(
          rk4([&](const std::vector<double>& y) { return p.rate(y); }, {-kPi / 2, -kPi / 2, 0.0, 0.0}, t, n));
    }
    case SceneId::Fourbar: {
      const Fourbar f;
      return f.end(rk4([&](const std::vector<double>& y) { return f.rate(y); }, {kPi / 2, f.startRate()}, t, n));
    }
    case SceneId::Ball:
      return ballEnd(t);
  }
  return {};
}

long referenceSteps(double t) { return std::max(1L, std::lround(std::ceil(t * kReferenceSteps))); }

}  // namespace

EndState referenceEnd(SceneId id, double t) { return referenceWith(id, t, referenceSteps(t)); }

Errors referenceSelfCheck(SceneId id, double t) {
  const long n = referenceSteps(t);
  return compareEnd(referenceWith(id, t, n / 2), referenceWith(id, t, n));
}

std::array<double, 3> fourbarStartJointRates() {
  const Fourbar f;
  const Fourbar::Kinematics k = f.at(kPi / 2);
  const double w2 = f.startRate();
  // Pitch rates are minus the angle rates; a joint's rate is its child's minus its parent's.
  return {-w2, -(k.u[1] - k.u[0]) * w2, -(k.u[2] - k.u[1]) * w2};
}

}  // namespace nscd_mujoco
