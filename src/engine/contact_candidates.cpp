// Stage 2b: unilateral contact candidates. Shape pairs and clearance joints give
// gaps, contact frames and Jacobian rows; only the points that can close within
// the step (predicted gap) become constraint blocks.
#include <cmath>

#include "step_workspace.hpp"

namespace nscd {
namespace {


Pose poseOf(const BodyState& b) { return Pose{b.x, b.q}; }

// Upper bound of the speed of any point within `reach` of the body origin.
double speedBound(const BodyState& b, double reach) { return b.v.norm() + b.w.norm() * reach; }

double shapeReach(const Shape& sh) {
  double ext = 0;
  switch (sh.type) {
    case ShapeType::Sphere: ext = sh.radius; break;
    case ShapeType::Capsule: ext = sh.radius + 0.5 * sh.length; break;
    case ShapeType::Cylinder: ext = std::hypot(sh.radius, 0.5 * sh.length); break;
    case ShapeType::Box: ext = sh.half_extents.norm(); break;
    case ShapeType::Plane: ext = 0; break;
  }
  return sh.pose.p.norm() + ext;
}

Vec3 pointVelocity(const BodyState& b, const Vec3& p_world) {
  return b.v + (b.q * b.w).cross(p_world - b.x);
}

// Normal approach velocity of a contact point for the velocities in `st`.
double normalVelocity(const State& st, int ia, int ib, const ContactPoint& cp) {
  const Vec3 va = pointVelocity(bodyOrGround(st, ia), cp.point_a);
  const Vec3 vb = pointVelocity(bodyOrGround(st, ib), cp.point_b);
  return cp.normal.dot(va - vb);
}

}  // namespace

void writeJacobianRows(const State& s, const ConstraintBlock& blk, Eigen::MatrixXd& G) {
  const Vec3 dirs[3] = {blk.row_cp.normal, blk.t1, blk.t2};
  for (int k = 0; k < blk.size; ++k) {
    const int row = blk.row + k;
    const Vec3& d = dirs[k];
    G.row(row).setZero();
    if (blk.body_a != kGround) {
      const BodyState& a = s.bodies[blk.body_a];
      G.block<1, 3>(row, 6 * blk.body_a) = d.transpose();
      G.block<1, 3>(row, 6 * blk.body_a + 3) =
          (a.q.conjugate() * (blk.row_cp.point_a - a.x).cross(d)).transpose();
    }
    if (blk.body_b != kGround) {
      const BodyState& b = s.bodies[blk.body_b];
      G.block<1, 3>(row, 6 * blk.body_b) = -d.transpose();
      G.block<1, 3>(row, 6 * blk.body_b + 3) =
          -(b.q.conjugate() * (blk.row_cp.point_b - b.x).cross(d)).transpose();
    }
  }
}

namespace {

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

void pushContactBlock(const Model& m, const State& s, const DeferredContact& c, bool normal_only,
                      StepWorkspace& ws) {
  if (ws.rows + 3 > ws.max_rows) return;  // cannot happen: sized for the worst case
  ConstraintBlock blk;
  blk.cp = c.cp;
  blk.row_cp = c.row_cp;
  blk.row_ahead = c.row_ahead;
  blk.body_a = c.body_a;
  blk.body_b = c.body_b;
  blk.mu = c.mu;
  blk.e = c.e;
  blk.source = c.source;
  blk.clearance = c.clearance;
  blk.slot = c.slot;
  blk.row = ws.rows;
  if (normal_only || c.mu <= 0) {
    blk.kind = BlockKind::Frictionless;
    blk.size = 1;
  } else {
    blk.kind = BlockKind::Frictional;
    blk.size = 3;
  }
  const Vec3& n = c.row_cp.normal;
  if (m.settings.planar == PlanarMode::XY) {
    blk.t2 = Vec3::UnitZ();
    blk.t1 = blk.t2.cross(n);
    const double l = blk.t1.norm();
    blk.t1 = l > 1e-12 ? Vec3(blk.t1 / l) : anyOrthogonal(n);
  } else {
    blk.t1 = anyOrthogonal(n);
    blk.t2 = n.cross(blk.t1);
  }
  writeJacobianRows(c.row_ahead ? ws.predicted : s, blk, ws.G);
  ws.rows += blk.size;
  ws.blocks.push_back(blk);
}

// The point of `ahead[0..na)` with the feature of `cp`, if its normal turns by
// less than kMaxPredictedTurn; null otherwise. A larger turn means the motion
// within the step is not small against the local curvature (a light body
// crossing a tight clearance in one step): the prediction is then no better
// than q_k, and can be far worse (a normal that flips).
const double kMinPredictedCos = std::cos(kMaxPredictedTurn);
const ContactPoint* predictedFeature(const ContactPoint& cp, const ContactPoint* ahead, int na) {
  for (int i = 0; i < na; ++i)
    if (ahead[i].feature == cp.feature)
      return ahead[i].normal.dot(cp.normal) >= kMinPredictedCos ? &ahead[i] : nullptr;
  return nullptr;
}

}  // namespace

// `s` holds q_k and v_k; ws.vfree the free velocity (may be unused: normal_only);
// ws.predicted q_k + h v_k when `predict`.
void appendContactBlocks(const Model& m, const State& s, double h, bool normal_only,
                         double extra_margin, bool predict, StepWorkspace& ws) {
  const Settings& set = m.settings;
  const bool planar = set.planar == PlanarMode::XY;
  const double eps_act = set.projection_tolerance + (normal_only ? 0.0 : set.activation_margin);
  const int npairs = static_cast<int>(m.contacts.size());
  if (!normal_only) ws.deferred.clear();
  predict = predict && !normal_only;
  int nahead = 0;  // points of the current pair or joint at ws.predicted

  auto addBlock = [&](const ContactPoint& cp, int ia, int ib, double mu, double e, int source,
                      bool clearance, int slot) {
    DeferredContact c{cp, cp, false, ia, ib, mu, e, source, clearance, slot};
    if (predict) {
      if (const ContactPoint* p = predictedFeature(cp, ws.points_ahead, nahead)) {
        c.row_cp = *p;
        c.row_ahead = true;
      }
    }
    if (!normal_only) {
      // Activation: the gap predicted from v_k, or from the free motion, closes.
      const double un = normalVelocity(s, ia, ib, cp);
      const bool active = cp.gap + set.activation_gamma * h * un <= eps_act ||
                          cp.gap + h * normalVelocityOf(ws.vfree, s, ia, ib, cp) <= 0;
      if (!active) {
        // Kept: the impulses of the other contacts may still close it (see
        // activateLateContacts).
        if (ws.deferred.size() < ws.deferred.capacity()) ws.deferred.push_back(c);
        return;
      }
    }
    pushContactBlock(m, s, c, normal_only, ws);
  };

  for (int p = 0; p < npairs; ++p) {
    const ContactPair& pair = m.contacts[p];
    const BodyState& a = bodyOrGround(s, pair.a.body);
    const BodyState& b = bodyOrGround(s, pair.b.body);
    const double margin = extra_margin + eps_act +
                          2.0 * h * (speedBound(a, shapeReach(pair.a)) + speedBound(b, shapeReach(pair.b)));
    const Pose pa = poseOf(a) * pair.a.pose;
    const Pose pb = poseOf(b) * pair.b.pose;
    const int np = collide(pair.a, pa, pair.b, pb, margin, ws.points);
    nahead = 0;
    if (predict && np > 0) {
      const Pose qa = poseOf(bodyOrGround(ws.predicted, pair.a.body)) * pair.a.pose;
      const Pose qb = poseOf(bodyOrGround(ws.predicted, pair.b.body)) * pair.b.pose;
      nahead = collide(pair.a, qa, pair.b, qb, margin, ws.points_ahead);
    }
    for (int k = 0; k < np; ++k)
      addBlock(ws.points[k], pair.a.body, pair.b.body, pair.mu, pair.e, p, false,
               p * kMaxPointsPerPair + ws.points[k].feature);
  }
  for (size_t c = 0; c < m.clearance_joints.size(); ++c) {
    const ClearanceJoint& cj = m.clearance_joints[c];
    const BodyState& br = bodyOrGround(s, cj.bearing_body);
    const BodyState& jr = bodyOrGround(s, cj.journal_body);
    const double reach = std::max(cj.bearing_center.norm(), cj.journal_center.norm()) +
                         std::max(cj.bump_at, cj.radius + cj.radial) + cj.length;
    const double margin =
        extra_margin + eps_act + 2.0 * h * (speedBound(br, reach) + speedBound(jr, reach));
    const int np = clearanceContacts(cj, poseOf(br), poseOf(jr), margin, planar,
                                     &ws.phi_hint[2 * c], ws.points);
    nahead = 0;
    double hint[2] = {ws.phi_hint[2 * c], ws.phi_hint[2 * c + 1]};  // a copy: q_k's stay
    if (predict && np > 0)
      nahead = clearanceContacts(cj, poseOf(bodyOrGround(ws.predicted, cj.bearing_body)),
                                 poseOf(bodyOrGround(ws.predicted, cj.journal_body)), margin,
                                 planar, hint, ws.points_ahead);
    for (int k = 0; k < np; ++k) {
      const ContactPoint cp = ws.points[k];
      addBlock(cp, cj.bearing_body, cj.journal_body, cj.mu, cj.e, static_cast<int>(c), true,
               ws.contact_slot_base_clearance + static_cast<int>(c) * kMaxClearancePoints +
                   cp.feature);
      // Projection only: a penetrating ring also gets neighbouring facets of its disc.
      if (normal_only && ws.ring_facets && cp.feature < 2 && cp.gap < 0) {
        ContactPoint facets[kRingFacets];
        const int nf = clearanceRingFacets(cj, poseOf(br), cp, margin, facets);
        for (int f = 0; f < nf; ++f)
          addBlock(facets[f], cj.bearing_body, cj.journal_body, cj.mu, cj.e,
                   static_cast<int>(c), true, -1);
      }
    }
  }
}

int activateLateContacts(const Model& m, const State& s, double h, StepWorkspace& ws) {
  int added = 0;
  size_t keep = 0;
  for (size_t i = 0; i < ws.deferred.size(); ++i) {
    const DeferredContact& c = ws.deferred[i];
    if (c.cp.gap + h * normalVelocityOf(ws.vnew, s, c.body_a, c.body_b, c.cp) <= 0) {
      pushContactBlock(m, s, c, false, ws);
      ++added;
    } else {
      ws.deferred[keep++] = c;
    }
  }
  ws.deferred.resize(keep);
  return added;
}

}  // namespace nscd
