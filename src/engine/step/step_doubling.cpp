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

void recordClosedContacts(const std::vector<ContactReport>& reports, AdaptiveStepWorkspace& a) {
  for (const ContactReport& r : reports) {
    if (!(r.fn > 0)) continue;
    const int slot = r.clearance ? a.slot_base_clearance + r.source * kMaxClearancePoints + r.feature
                                 : r.source * kMaxPointsPerPair + r.feature;
    a.closed[slot] = 1;
    a.closed_at[slot] = r;  // no allocation: a ContactReport owns no memory
  }
}

namespace {

// Include a sticking contact's tangent rows in the split (else its normal row alone).
constexpr bool kSplitStickRows = false;
// A row whose pivot falls below this fraction of its diagonal is (numerically)
// in the span of the rows before it, and left out.
constexpr double kDependentRow = 1e-10;

// Starts a row of the split on up to two bodies (kGround: none).
AdaptiveStepWorkspace::SplitRow& newSplitRow(int body_a, int body_b, AdaptiveStepWorkspace& a) {
  AdaptiveStepWorkspace::SplitRow& row = a.split_rows[a.split_count++];
  row.body[0] = body_a == kGround ? -1 : body_a;
  row.body[1] = body_b == kGround || body_b == body_a ? -1 : body_b;
  return row;
}

// Sets the row's part on its k-th body: linear and angular (world) parts, and M^-1 times them.
void setSplitRow(AdaptiveStepWorkspace::SplitRow& row, int k, const Vec3& lin, const Vec3& ang, const State& s,
                 const AdaptiveStepWorkspace& a) {
  const int b = row.body[k];
  if (b < 0) return;
  const Mat3 R = s.bodies[b].q.toRotationMatrix();
  row.J[k] << lin, ang;
  row.Y[k] << a.inverse_mass[b] * lin, R * (a.inverse_inertia[b] * (R.transpose() * ang));
}

// The row dir . (v_a + w_a x r_a - v_b - w_b x r_b) of a contact point (r from
// each body's centre to the point).
void addContactRow(const Vec3& point, const Vec3& dir, int body_a, int body_b, const State& s,
                   AdaptiveStepWorkspace& a) {
  AdaptiveStepWorkspace::SplitRow& row = newSplitRow(body_a, body_b, a);
  for (int k = 0; k < 2; ++k) {
    if (row.body[k] < 0) continue;
    const double sign = k == 0 ? 1.0 : -1.0;
    setSplitRow(row, k, sign * dir, sign * (point - s.bodies[row.body[k]].x).cross(dir), s, a);
  }
}

}  // namespace

double eventStepDifference(const State& coarse, const State& fine, double atol, double rtol, double h,
                           const StepWorkspace& bilateral, AdaptiveStepWorkspace& a) {
  // The rows at the fine path's end: the ideal joints' and prescribed motions'
  // (bilateral.G, angular parts in body axes), then the closed contacts'.
  a.split_count = 0;
  for (const ConstraintBlock& blk : bilateral.blocks) {
    if (blk.kind != BlockKind::Bilateral) continue;
    for (int r = blk.row; r < blk.row + blk.size; ++r) {
      AdaptiveStepWorkspace::SplitRow& row = newSplitRow(blk.body_a, blk.body_b, a);
      for (int k = 0; k < 2; ++k) {
        const int b = row.body[k];
        if (b < 0) continue;
        const auto g = bilateral.G.block<1, 6>(r, 6 * b).transpose();
        setSplitRow(row, k, g.head<3>(), fine.bodies[b].q * Vec3(g.tail<3>()), fine, a);
      }
    }
  }
  const int joint_rows = a.split_count;
  for (size_t slot = 0; slot < a.closed.size(); ++slot) {
    if (!a.closed[slot]) continue;
    const ContactReport& r = a.closed_at[slot];
    addContactRow(r.point, r.normal, r.body_a, r.body_b, fine, a);
    if (kSplitStickRows && a.slot_mu[slot] > 0 && !r.sliding) {
      const Vec3 t1 = r.normal.unitOrthogonal(), t2 = r.normal.cross(t1);
      addContactRow(r.point, t1, r.body_a, r.body_b, fine, a);
      addContactRow(r.point, t2, r.body_a, r.body_b, fine, a);
    }
  }
  const int m = a.split_count;
  const size_t nb = fine.bodies.size();
  // The velocity difference (fine - coarse), world frame.
  for (size_t i = 0; i < nb; ++i) {
    const BodyState& c = coarse.bodies[i];
    const BodyState& f = fine.bodies[i];
    a.velocity_difference[i] = f.v - c.v;
    a.angular_difference[i] = f.q * f.w - c.q * c.w;
  }
  // W = J M^-1 J^T and J dv.
  for (int i = 0; i < m; ++i) {
    const AdaptiveStepWorkspace::SplitRow& ri = a.split_rows[i];
    double jdv = 0;
    for (int k = 0; k < 2; ++k)
      if (ri.body[k] >= 0)
        jdv += ri.J[k].head<3>().dot(a.velocity_difference[ri.body[k]]) + ri.J[k].tail<3>().dot(a.angular_difference[ri.body[k]]);
    a.split_rhs[i] = jdv;
    for (int j = 0; j <= i; ++j) {
      const AdaptiveStepWorkspace::SplitRow& rj = a.split_rows[j];
      double w = 0;
      for (int k = 0; k < 2; ++k)
        for (int l = 0; l < 2; ++l)
          if (ri.body[k] >= 0 && ri.body[k] == rj.body[l]) w += ri.J[k].dot(rj.Y[l]);
      a.split_W(i, j) = w;
    }
  }
  // Cholesky factor in place (lower triangle), dependent rows left out (lambda 0).
  Eigen::MatrixXd& L = a.split_W;
  for (int j = 0; j < m; ++j) {
    a.split_diagonal[j] = L(j, j);
    double d = L(j, j);
    for (int k = 0; k < j; ++k) d -= L(j, k) * L(j, k);
    if (!(d > kDependentRow * a.split_diagonal[j])) {
      for (int i = j; i < m; ++i) L(i, j) = 0;
      continue;
    }
    L(j, j) = std::sqrt(d);
    for (int i = j + 1; i < m; ++i) {
      double x = L(i, j);
      for (int k = 0; k < j; ++k) x -= L(i, k) * L(j, k);
      L(i, j) = x / L(j, j);
    }
  }
  Eigen::VectorXd& lambda = a.split_rhs;
  for (int j = 0; j < m; ++j) {
    if (L(j, j) == 0) { lambda[j] = 0; continue; }
    double x = lambda[j];
    for (int k = 0; k < j; ++k) x -= L(j, k) * lambda[k];
    lambda[j] = x / L(j, j);
  }
  // y = L^-1 J dv are the coordinates of dv's projection in an M-orthonormal
  // basis of the rows' span, the joints' rows first: without their coordinates
  // it is the part along the contacts' rows M-orthogonal to the joints' (the
  // velocity change a contact impulse makes, passed through the ideal joints).
  for (int j = 0; j < joint_rows; ++j) lambda[j] = 0;
  for (int j = m - 1; j >= 0; --j) {
    if (L(j, j) == 0) { lambda[j] = 0; continue; }
    double x = lambda[j];
    for (int k = j + 1; k < m; ++k) x -= L(k, j) * lambda[k];
    lambda[j] = x / L(j, j);
  }
  // The part along the contacts' rows, M^-1 J^T lambda (weight h); the rest (free
  // motion, and the part along the joints' rows) at weight 1.
  // Positions and orientations as scaledBodiesDifference counts them (velocities at weight 0).
  double worst = scaledBodiesDifference(coarse.bodies, fine.bodies, atol, rtol, 0.0, a.rotation_length);
  auto take = [&](double constrained, double free, double x, double y) {
    const double scale = std::max(std::abs(x), std::abs(y));
    const double e = std::max(h * std::abs(constrained) / (atol + rtol * h * scale),
                              std::abs(free) / (atol + rtol * scale));
    worst = e <= worst ? worst : (std::isnan(e) ? INFINITY : e);
  };
  for (size_t i = 0; i < nb; ++i) {
    const BodyState& c = coarse.bodies[i];
    const BodyState& f = fine.bodies[i];
    Vec3 cv = Vec3::Zero(), cw = Vec3::Zero();
    for (int j = 0; j < m; ++j) {
      const AdaptiveStepWorkspace::SplitRow& row = a.split_rows[j];
      for (int k = 0; k < 2; ++k)
        if (row.body[k] == static_cast<int>(i)) {
          cv += lambda[j] * row.Y[k].head<3>();
          cw += lambda[j] * row.Y[k].tail<3>();
        }
    }
    const double r = a.rotation_length[i];
    const Vec3 wc = r * (c.q * c.w), wf = r * (f.q * f.w);
    const Vec3 dv = a.velocity_difference[i], dw = r * a.angular_difference[i];
    cw *= r;
    for (int k = 0; k < 3; ++k) {
      take(cv[k], dv[k] - cv[k], c.v[k], f.v[k]);
      take(cw[k], dw[k] - cw[k], wc[k], wf[k]);
    }
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
