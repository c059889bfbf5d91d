// Step doubling (adaptive_step.hpp): how far the whole step and its two halves
// differ, whether a contact changed mode, and the Richardson extrapolation.
#include <algorithm>
#include <cmath>
#include <limits>

#include "adaptive_step.hpp"

namespace nscd {
namespace {

// A closed contact slides when its tangential impulse is on the cone's boundary
// (the test of impulse_reports.cpp).
enum class Mode { Open, Stick, Slide };

Mode slotMode(double mu, const State& s, size_t slot) {
  if (!s.warm_valid[slot]) return Mode::Open;
  const Vec3& p = s.warm[slot];
  if (!(p[0] > 0)) return Mode::Open;
  if (mu > 0 && p.tail<2>().norm() >= mu * p[0] * (1 - 1e-6)) return Mode::Slide;
  return Mode::Stick;
}

}  // namespace

double scaledBodiesDifference(const std::vector<BodyState>& a, const std::vector<BodyState>& b, double atol,
                              double rtol, double velocity_weight, const std::vector<double>& rotation_length) {
  double worst = 0;
  auto take = [&](double x, double y) {
    const double scaled = std::abs(x - y) / (atol + rtol * std::max(std::abs(x), std::abs(y)));
    // A NaN fails every comparison: it makes the difference infinite.
    worst = scaled <= worst ? worst : (std::isnan(scaled) ? INFINITY : scaled);
  };
  const double c = velocity_weight;
  for (size_t i = 0; i < a.size(); ++i) {
    const BodyState& p = a[i];
    const BodyState& q = b[i];
    const double r = rotation_length[i];
    const Vec3 wp = r * (p.q * p.w), wq = r * (q.q * q.w);
    for (int k = 0; k < 3; ++k) {
      take(p.x[k], q.x[k]);
      take(c * p.v[k], c * q.v[k]);
      take(c * wp[k], c * wq[k]);
    }
    // The turn between the orientations, as the arc it moves a point at r through.
    const double angle = r * logMap(p.q.conjugate() * q.q).norm();
    const double scaled = angle / (atol + rtol * r);
    worst = scaled <= worst ? worst : (std::isnan(scaled) ? INFINITY : scaled);
  }
  return worst;
}

double scaledStateDifference(const State& a, const State& b, double atol, double rtol,
                             double velocity_weight, const std::vector<double>& rotation_length) {
  return scaledBodiesDifference(a.bodies, b.bodies, atol, rtol, velocity_weight, rotation_length);
}

namespace {

// The farthest a point of the shape lies from its frame's origin (0: a plane).
double shapeReach(const Shape& s) {
  switch (s.type) {
    case ShapeType::Sphere:
    case ShapeType::Ring: return s.radius;
    case ShapeType::Capsule: return 0.5 * s.length + s.radius;
    case ShapeType::Cylinder: return std::hypot(s.radius, 0.5 * s.length);
    case ShapeType::Box:
    case ShapeType::Face: return s.half_extents.norm();
    case ShapeType::Plane: return 0;
  }
  return 0;
}

}  // namespace

double rotationLength(const Model& m, int body) {
  const Body& b = m.bodies[body];
  const double r2 = 0.5 * b.inertia.trace() / b.mass;
  double len = r2 > 0 && std::isfinite(r2) ? std::sqrt(r2) : 0;
  auto reach = [&](int on, const Vec3& at, double extra) {
    if (on == body) len = std::max(len, at.norm() + extra);
  };
  for (const Joint& j : m.joints) {
    reach(j.body_a, j.anchor_a, 0);
    reach(j.body_b, j.anchor_b, 0);
  }
  for (const ClearanceJoint& c : m.clearance_joints) {
    const double extra = 0.5 * c.length + c.radius + c.radial;
    reach(c.journal_body, c.journal_center, extra);
    reach(c.bearing_body, c.bearing_center, extra);
  }
  for (const ContactPair& c : m.contacts) {
    reach(c.a.body, c.a.pose.p, shapeReach(c.a));
    reach(c.b.body, c.b.pose.p, shapeReach(c.b));
  }
  for (const Spring& s : m.springs)
    if (s.type == SpringType::Linear) {
      reach(s.body_a, s.end_a, 0);
      reach(s.body_b, s.end_b, 0);
    }
  return len > 0 && std::isfinite(len) ? len : 1.0;
}

bool sameContactModes(const std::vector<double>& slot_mu, const State& a, const State& b) {
  for (size_t slot = 0; slot < slot_mu.size(); ++slot) {
    const Mode ma = slotMode(slot_mu[slot], a, slot), mb = slotMode(slot_mu[slot], b, slot);
    if (ma != mb) return false;
    if (ma == Mode::Slide && a.warm[slot].tail<2>().dot(b.warm[slot].tail<2>()) <= 0) return false;
  }
  return true;
}

bool contactsOpen(const std::vector<double>& slot_mu, const State& s) {
  for (size_t slot = 0; slot < slot_mu.size(); ++slot)
    if (slotMode(slot_mu[slot], s, slot) != Mode::Open) return false;
  return true;
}

bool stepHadEvent(const StepStats& st) {
  return !st.converged || st.late_contacts > 0 || st.substeps > 1 || st.plastic_fallback || st.plastic_retry ||
         st.longer_solve || st.frictionless_fallback || st.energy_capped ||
         st.iteration_matrix_fallback;
}

double embeddedEventError(const std::vector<std::vector<BodyState>>& substeps, int n, double h, double atol,
                          double rtol, const std::vector<double>& rotation_length, bool as_velocity) {
  const double weight = as_velocity ? 1.0 : h;
  double worst = 0;
  const double s = h / n;
  for (size_t b = 0; b < substeps[0].size(); ++b) {
    const double r = rotation_length[b];
    // Per component (linear, then r times the world rotation): the summed second
    // differences of the velocities the body moved with over each substep, and
    // the largest of them.
    Vec3 sum_lin = Vec3::Zero(), sum_ang = Vec3::Zero();
    Vec3 du_lin = Vec3::Zero(), du_ang = Vec3::Zero();  // the last first difference
    Vec3 u_lin = Vec3::Zero(), u_ang = Vec3::Zero();    // the last substep's velocities
    double speed = 0;
    for (int i = 1; i <= n; ++i) {
      const BodyState& p = substeps[i - 1][b];
      const BodyState& q = substeps[i][b];
      const Vec3 lin = (q.x - p.x) / s;
      const Vec3 ang = (r / s) * (p.q * logMap(p.q.conjugate() * q.q));
      if (i > 1) {
        const Vec3 dl = lin - u_lin, da = ang - u_ang;
        if (i > 2) {
          sum_lin += (dl - du_lin).cwiseAbs();
          sum_ang += (da - du_ang).cwiseAbs();
        }
        du_lin = dl;
        du_ang = da;
      }
      u_lin = lin;
      u_ang = ang;
      speed = std::max({speed, lin.cwiseAbs().maxCoeff(), ang.cwiseAbs().maxCoeff()});
    }
    if (!sum_lin.allFinite() || !sum_ang.allFinite() || !std::isfinite(speed)) return INFINITY;
    // The path's n substeps err by n (s^2 / 2) a' in velocity; its n - 2 second
    // differences sum to (n - 2) s^2 a'.
    const double factor = n / (2.0 * (n - 2));
    const double e = weight * factor * std::max(sum_lin.maxCoeff(), sum_ang.maxCoeff()) / (atol + rtol * weight * speed);
    // A NaN fails every comparison: it makes the estimate infinite.
    worst = e <= worst ? worst : (std::isnan(e) ? INFINITY : e);
  }
  return worst;
}

void extrapolateBodies(const std::vector<BodyState>& coarse, double f, std::vector<BodyState>& fine) {
  for (size_t i = 0; i < fine.size(); ++i) {
    const BodyState& c = coarse[i];
    BodyState& b = fine[i];
    const Vec3 omega = b.q * b.w + f * (b.q * b.w - c.q * c.w);  // world frame
    b.x += f * (b.x - c.x);
    b.v += f * (b.v - c.v);
    b.q = (b.q * expMap(f * logMap(c.q.conjugate() * b.q))).normalized();
    b.w = b.q.conjugate() * omega;
  }
}

void richardsonExtrapolate(const State& coarse, double f, State& fine) {
  extrapolateBodies(coarse.bodies, f, fine.bodies);
}

void addTableauLevel(int j, const std::vector<BodyState>& y, AdaptiveStepWorkspace& a) {
  a.cur = y;  // same sizes: no allocation
  for (int k = 0; k < j; ++k) {
    const double f = 1.0 / (static_cast<double>(levelSubsteps(j)) / levelSubsteps(j - k - 1) - 1.0);
    a.tmp = a.cur;                       // T_{j,k}
    extrapolateBodies(a.row[k], f, a.cur);  // T_{j,k+1}
    std::swap(a.row[k], a.tmp);          // row[k] <- T_{j,k}: no allocation
  }
  a.row[j] = a.cur;
}

}  // namespace nscd
