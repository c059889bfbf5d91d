// Stage 2b: unilateral contact candidates, in three steps: narrowphase (every
// point of the shape pairs and clearance joints within reach of the step),
// activation (the points that can close within the step; the others wait for
// the answer, activateLateContacts) and rows (contact frame and Jacobian).
#include "contact_candidates.hpp"

#include <cmath>

#include "joints/clearance_joint.hpp"
#include "contact_pair.hpp"

namespace nscd {
namespace {

// A larger turn of the normal between q_k and the predicted configuration means
// the motion within the step is not small against the local curvature (a light
// body crossing a tight clearance in one step): the prediction is then no better
// than q_k, and can be far worse (a normal that flips).
const double kMinPredictedCos = std::cos(kMaxPredictedTurn);

// The point of ahead[0..na) with the feature of cp, if its normal turns by less
// than kMaxPredictedTurn; null otherwise.
const ContactPoint* predictedFeature(const ContactPoint& cp, const ContactPoint* ahead, int na) {
  for (int i = 0; i < na; ++i)
    if (ahead[i].feature == cp.feature)
      return ahead[i].normal.dot(cp.normal) >= kMinPredictedCos ? &ahead[i] : nullptr;
  return nullptr;
}

Vec3 pointVelocity(const BodyState& b, const Vec3& p_world) {
  return b.v + (b.q * b.w).cross(p_world - b.x);
}

// Normal approach velocity of a contact point for the velocities in `st`, with
// each body's q * w taken from omega (computed once per pass by the same expression
// as pointVelocity's: the same bits); ground's by pointVelocity.
double normalVelocity(const State& st, const std::vector<Vec3>& omega, int ia, int ib,
                      const ContactPoint& cp) {
  const auto velocity = [&](int i, const Vec3& p) {
    if (i == kGround) return pointVelocity(bodyOrGround(st, i), p);
    const BodyState& b = st.bodies[i];
    return Vec3(b.v + omega[i].cross(p - b.x));
  };
  const Vec3 va = velocity(ia, cp.point_a);
  const Vec3 vb = velocity(ib, cp.point_b);
  return cp.normal.dot(va - vb);
}

// Normal approach velocity of a contact point for the generalized velocity v
// (6 per body: linear world, angular body frame).
double normalVelocityOf(const Eigen::VectorXd& v, const State& s, int ia, int ib,
                        const ContactPoint& cp) {
  Vec3 va = Vec3::Zero(), vb = Vec3::Zero();
  if (ia != kGround) {
    const BodyState& a = s.bodies[ia];
    va = v.segment<3>(6 * ia) + (a.q * Vec3(v.segment<3>(6 * ia + 3))).cross(cp.point_a - a.x);
  }
  if (ib != kGround) {
    const BodyState& b = s.bodies[ib];
    vb = v.segment<3>(6 * ib) + (b.q * Vec3(v.segment<3>(6 * ib + 3))).cross(cp.point_b - b.x);
  }
  return cp.normal.dot(va - vb);
}

// The rows of one candidate: a frictional block (3 rows) or, in the projection
// modes or without friction, a normal row.
void appendContactRows(const Model& m, const State& s, const ContactCandidate& c,
                       bool normal_only, StepWorkspace& ws) {
  if (ws.rows + 3 > ws.max_rows) return;  // cannot happen: sized for the worst case
  ConstraintBlock blk;
  blk.contact = c;
  blk.body_a = c.body_a;
  blk.body_b = c.body_b;
  blk.row = ws.rows;
  if (normal_only || c.mu <= 0) {
    blk.kind = BlockKind::Frictionless;
    blk.size = 1;
  } else {
    blk.kind = BlockKind::Frictional;
    blk.size = 3;
  }
  const Vec3& n = c.row_cp.normal;
  if (normal_only) {
    // The projection modes' normal rows: no tangents are read (their blocks are
    // never reported: storeImpulses runs before the projection).
  } else if (m.settings.planar == PlanarMode::XY) {
    blk.t2 = Vec3::UnitZ();
    blk.t1 = blk.t2.cross(n);
    const double l = blk.t1.norm();
    blk.t1 = l > 1e-12 ? Vec3(blk.t1 / l) : anyOrthogonal(n);
  } else {
    blk.t1 = anyOrthogonal(n);
    blk.t2 = n.cross(blk.t1);
  }
  // The projection modes' rows are written only for a correction (projection.cpp):
  // most checks find nothing to correct and need the gaps alone.
  if (!normal_only) writeJacobianRows(c.row_ahead ? ws.predicted : s, blk, ws.G);
  ws.rows += blk.size;
  ws.blocks.push_back(blk);
}

}  // namespace

double activationTolerance(const Settings& set, CandidateMode mode) {
  return set.projection_tolerance + (mode == CandidateMode::Step ? set.activation_margin : 0.0);
}

void pushCandidate(const ContactPoint& cp, int body_a, int body_b, double mu, double e,
                   int source, bool clearance, int slot, const ContactPoint* ahead, int nahead,
                   StepWorkspace& ws) {
  ContactCandidate c{cp, cp, false, body_a, body_b, mu, e, source, clearance, slot};
  if (const ContactPoint* p = predictedFeature(cp, ahead, nahead)) {
    c.row_cp = *p;
    c.row_ahead = true;
  }
  ws.candidates.push_back(c);
}

void writeJacobianRows(const State& s, const ConstraintBlock& blk, Eigen::MatrixXd& G) {
  const ContactPoint& rc = blk.contact.row_cp;
  const Vec3 dirs[3] = {rc.normal, blk.t1, blk.t2};
  for (int k = 0; k < blk.size; ++k) {
    const int row = blk.row + k;
    const Vec3& d = dirs[k];
    // The row is zero outside these columns (clearConstraintRows).
    if (blk.body_a != kGround) {
      const BodyState& a = s.bodies[blk.body_a];
      G.block<1, 3>(row, 6 * blk.body_a) = d.transpose();
      G.block<1, 3>(row, 6 * blk.body_a + 3) =
          (a.q.conjugate() * (rc.point_a - a.x).cross(d)).transpose();
    }
    if (blk.body_b != kGround) {
      const BodyState& b = s.bodies[blk.body_b];
      G.block<1, 3>(row, 6 * blk.body_b) = -d.transpose();
      G.block<1, 3>(row, 6 * blk.body_b + 3) =
          -(b.q.conjugate() * (rc.point_b - b.x).cross(d)).transpose();
    }
  }
}

// `s` holds q_k and v_k; ws.predicted q_k + h v_k when predicting.
void findContactCandidates(const Model& m, const State& s, double h, CandidateMode mode,
                           double extra_margin, double* ring_hint, StepWorkspace& ws) {
  CandidatePass pass;
  pass.mode = mode;
  pass.h = h;
  pass.extra_margin = extra_margin;
  pass.eps_act = activationTolerance(m.settings, mode);
  pass.predict = mode == CandidateMode::Step && m.settings.contact_prediction > 0;
  // The projection's check at q_{k+1} is the next step's q_k unless something
  // moves the bodies first: it keeps its pairs' points for the step
  // (narrowphase_cache.hpp).
  if (mode == CandidateMode::Projection) {
    pass.cache = CacheUse::Fill;
    pass.next_h = m.settings.dt;
    pass.next_eps_act = activationTolerance(m.settings, CandidateMode::Step);
    ws.narrow.valid = false;
  } else if (mode == CandidateMode::Step && narrowphaseKeyMatches(ws.narrow, s)) {
    pass.cache = CacheUse::Read;
  }
  ws.candidates.clear();
  for (size_t p = 0; p < m.contacts.size(); ++p)
    appendPairCandidates(m, s, static_cast<int>(p), pass, ws);
  for (size_t c = 0; c < m.clearance_joints.size(); ++c)
    appendClearanceCandidates(m, s, static_cast<int>(c), pass, ring_hint + 2 * c, ws);
  if (pass.cache == CacheUse::Fill) storeNarrowphaseKey(s, ws.narrow);
}

void activateContacts(const Model& m, const State& s, double h, CandidateMode mode,
                      StepWorkspace& ws) {
  const Settings& set = m.settings;
  if (mode != CandidateMode::Step) {
    for (const ContactCandidate& c : ws.candidates) appendContactRows(m, s, c, true, ws);
    return;
  }
  const double eps_act = activationTolerance(set, mode);
  ws.deferred.clear();
  for (size_t i = 0; i < s.bodies.size(); ++i) ws.omega_world[i] = s.bodies[i].q * s.bodies[i].w;
  for (const ContactCandidate& c : ws.candidates) {
    // Activation: the gap predicted from v_k, or from the free motion, closes.
    const ContactPoint& cp = c.cp;
    const double un = normalVelocity(s, ws.omega_world, c.body_a, c.body_b, cp);
    const bool active = cp.gap + set.activation_gamma * h * un <= eps_act ||
                        cp.gap + h * normalVelocityOf(ws.vfree, s, c.body_a, c.body_b, cp) <= 0;
    if (active) {
      appendContactRows(m, s, c, false, ws);
    } else if (ws.deferred.size() < ws.deferred.capacity()) {
      // Kept: the impulses of the other contacts may still close it (then its
      // gap is the slack it has in the problem).
      ws.deferred.push_back(c);
      ws.deferred.back().late_slack = std::max(0.0, cp.gap);
    }
  }
}

int activateLateContacts(const Model& m, const State& s, double h, StepWorkspace& ws) {
  int added = 0;
  size_t keep = 0;
  for (size_t i = 0; i < ws.deferred.size(); ++i) {
    const ContactCandidate& c = ws.deferred[i];
    if (c.cp.gap + h * normalVelocityOf(ws.vnew, s, c.body_a, c.body_b, c.cp) <= 0) {
      appendContactRows(m, s, c, false, ws);
      ++added;
    } else {
      ws.deferred[keep++] = c;
    }
  }
  ws.deferred.resize(keep);
  return added;
}

}  // namespace nscd
