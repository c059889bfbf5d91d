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

double scaledStateDifference(const State& a, const State& b, double atol, double rtol,
                             double velocity_weight) {
  double worst = 0;
  auto take = [&](double x, double y) {
    const double scaled = std::abs(x - y) / (atol + rtol * std::max(std::abs(x), std::abs(y)));
    // A NaN fails every comparison: it makes the difference infinite.
    worst = scaled <= worst ? worst : (std::isnan(scaled) ? INFINITY : scaled);
  };
  const double c = velocity_weight;
  for (size_t i = 0; i < a.bodies.size(); ++i) {
    const BodyState& p = a.bodies[i];
    const BodyState& q = b.bodies[i];
    const Vec3 wp = p.q * p.w, wq = q.q * q.w;
    for (int k = 0; k < 3; ++k) {
      take(p.x[k], q.x[k]);
      take(c * p.v[k], c * q.v[k]);
      take(c * wp[k], c * wq[k]);
    }
    const double angle = logMap(p.q.conjugate() * q.q).norm();
    const double scaled = angle / (atol + rtol);
    worst = scaled <= worst ? worst : (std::isnan(scaled) ? INFINITY : scaled);
  }
  return worst;
}

bool sameContactModes(const std::vector<double>& slot_mu, const State& a, const State& b) {
  for (size_t slot = 0; slot < slot_mu.size(); ++slot) {
    const Mode ma = slotMode(slot_mu[slot], a, slot), mb = slotMode(slot_mu[slot], b, slot);
    if (ma != mb) return false;
    if (ma == Mode::Slide && a.warm[slot].tail<2>().dot(b.warm[slot].tail<2>()) <= 0) return false;
  }
  return true;
}

bool stepHadEvent(const StepStats& st) {
  return !st.converged || st.late_contacts > 0 || st.substeps > 1 || st.plastic_fallback || st.plastic_retry ||
         st.longer_solve || st.frictionless_fallback || st.energy_capped ||
         st.iteration_matrix_fallback;
}

void richardsonExtrapolate(const State& coarse, double f, State& fine) {
  for (size_t i = 0; i < fine.bodies.size(); ++i) {
    const BodyState& c = coarse.bodies[i];
    BodyState& b = fine.bodies[i];
    const Vec3 omega = b.q * b.w + f * (b.q * b.w - c.q * c.w);  // world frame
    b.x += f * (b.x - c.x);
    b.v += f * (b.v - c.v);
    b.q = (b.q * expMap(f * logMap(c.q.conjugate() * b.q))).normalized();
    b.w = b.q.conjugate() * omega;
  }
}

}  // namespace nscd
