// The revolute joint with clearance: which of its contacts may enter a step
// (two bearing rings against the journal, bumps against the flanges), with a
// margin from how far its bodies can move, and where the journal sits.
#include "clearance_joint.hpp"

#include <cmath>

namespace nscd {

void appendClearanceCandidates(const Model& m, const State& s, int c, const CandidatePass& pass,
                               double* hint, StepWorkspace& ws) {
  const ClearanceJoint& cj = m.clearance_joints[c];
  const bool planar = m.settings.planar == PlanarMode::XY;
  const BodyState& br = bodyOrGround(s, cj.bearing_body);
  const BodyState& jr = bodyOrGround(s, cj.journal_body);
  const double reach = std::max(cj.bearing_center.norm(), cj.journal_center.norm()) +
                       std::max(cj.bump_at, cj.radius + cj.radial) + cj.length;
  const double margin = pass.extra_margin + pass.eps_act +
                        2.0 * pass.h * (speedBound(br, reach) + speedBound(jr, reach));
  const int np = clearanceContacts(cj, poseOf(br), poseOf(jr), margin, planar, hint, ws.points);
  int nahead = 0;
  double hint_ahead[2] = {hint[0], hint[1]};  // a copy: q_k's hints stay
  if (pass.predict && np > 0)
    nahead = clearanceContacts(cj, poseOf(bodyOrGround(ws.predicted, cj.bearing_body)),
                               poseOf(bodyOrGround(ws.predicted, cj.journal_body)), margin,
                               planar, hint_ahead, ws.points_ahead);
  const int slot_base = ws.facts.contact_slot_base_clearance + c * kMaxClearancePoints;
  for (int k = 0; k < np; ++k) {
    const ContactPoint cp = ws.points[k];
    pushCandidate(cp, cj.bearing_body, cj.journal_body, cj.mu, cj.e, c, true,
                  slot_base + cp.feature, ws.points_ahead, nahead, ws);
    // Projection only: a penetrating ring also gets neighbouring facets of its disc.
    if (pass.mode == CandidateMode::Projection && cp.feature < 2 && cp.gap < 0) {
      ContactPoint facets[kRingFacets];
      const int nf = clearanceRingFacets(cj, poseOf(br), cp, margin, facets);
      for (int f = 0; f < nf; ++f)
        pushCandidate(facets[f], cj.bearing_body, cj.journal_body, cj.mu, cj.e, c, true, -1,
                      nullptr, 0, ws);
    }
  }
}

namespace {

// Journal axis offset from the bearing centre, in the bearing's mid-plane (world).
Vec3 eccentricityVector(const State& s, const ClearanceJoint& cj, Vec3* ref, Vec3* axis) {
  const Pose pb = cj.bearing_body == kGround ? Pose() : Pose{s.bodies[cj.bearing_body].x, s.bodies[cj.bearing_body].q};
  const Pose pj = cj.journal_body == kGround ? Pose() : Pose{s.bodies[cj.journal_body].x, s.bodies[cj.journal_body].q};
  const Vec3 c = pb.apply(cj.bearing_center), n = pb.rotate(cj.bearing_axis);
  const Vec3 o = pj.apply(cj.journal_center), a = pj.rotate(cj.journal_axis);
  const double an = a.dot(n);
  const Vec3 p = std::abs(an) > 1e-12 ? Vec3(o + ((c - o).dot(n) / an) * a) : o;
  Vec3 e = p - c;
  e -= e.dot(n) * n;
  if (ref) *ref = pb.rotate(cj.bearing_ref);
  if (axis) *axis = n;
  return e;
}

}  // namespace

double journalEccentricity(const State& s, const ClearanceJoint& cj) {
  return eccentricityVector(s, cj, nullptr, nullptr).norm() / cj.radial;
}

double journalEccentricityAngle(const State& s, const ClearanceJoint& cj) {
  Vec3 ref, n;
  const Vec3 e = eccentricityVector(s, cj, &ref, &n);
  return std::atan2(e.dot(n.cross(ref)), e.dot(ref));
}

}  // namespace nscd
