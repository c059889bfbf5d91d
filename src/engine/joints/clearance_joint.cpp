// The revolute joint with clearance: which of its contacts may enter a step
// (two bearing rings against the journal, bumps against the flanges), with a
// margin from how far its bodies can move, and where the journal sits.
#include "clearance_joint.hpp"

#include <cmath>
#include <cstring>

namespace nscd {

void appendClearanceCandidates(const Model& m, const State& s, int c, const CandidatePass& pass,
                               double* hint, StepWorkspace& ws) {
  const ClearanceJoint& cj = m.clearance_joints[c];
  const bool planar = m.settings.planar == PlanarMode::XY;
  const BodyState& br = bodyOrGround(s, cj.bearing_body);
  const BodyState& jr = bodyOrGround(s, cj.journal_body);
  const double reach = std::max(cj.bearing_center.norm(), cj.journal_center.norm()) +
                       std::max(cj.bump_at, cj.radius + cj.radial) + cj.length;
  const double speeds = speedBound(br, reach) + speedBound(jr, reach);
  const double margin = pass.extra_margin + pass.eps_act + 2.0 * pass.h * speeds;
  // The projection's check keeps its points for the next step, wide enough for
  // that step's margin, with the hints (narrowphase_cache.hpp).
  NarrowphaseCache& memo = ws.narrow;
  ContactPoint* slots = memo.cj_points.data() + c * kMaxClearancePoints;
  double* hint_in = memo.cj_hint_in.data() + 2 * c;
  double* hint_out = memo.cj_hint_out.data() + 2 * c;
  int np = 0;
  if (pass.cache == CacheUse::Read && margin <= memo.cj_margin[c] &&
      std::memcmp(hint, hint_in, 2 * sizeof(double)) == 0) {
    for (int k = 0; k < memo.cj_count[c]; ++k)
      if (slots[k].gap < margin) ws.points[np++] = slots[k];
    hint[0] = hint_out[0];
    hint[1] = hint_out[1];
  } else if (pass.cache == CacheUse::Fill) {
    const double next_margin = 0.0 + pass.next_eps_act + 2.0 * pass.next_h * speeds;  // as a Step pass
    const double wide = next_margin > margin ? next_margin : margin;
    memo.cj_margin[c] = wide;
    hint_in[0] = hint[0];
    hint_in[1] = hint[1];
    memo.cj_count[c] = clearanceContacts(cj, poseOf(br), poseOf(jr), wide, planar, hint, slots);
    hint_out[0] = hint[0];
    hint_out[1] = hint[1];
    for (int k = 0; k < memo.cj_count[c]; ++k)
      if (slots[k].gap < margin) ws.points[np++] = slots[k];
  } else {
    np = clearanceContacts(cj, poseOf(br), poseOf(jr), margin, planar, hint, ws.points);
  }
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
