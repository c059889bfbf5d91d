// A named contact between two shapes: the narrowphase of the pair (contact
// geometry in contact_geometry.cpp), with a margin from how far its shapes can
// move in the step.
#include "contact_pair.hpp"

#include <cmath>
#include <limits>

namespace nscd {

double shapeReach(const Shape& sh) {
  double ext = 0;
  switch (sh.type) {
    case ShapeType::Sphere: ext = sh.radius; break;
    case ShapeType::Capsule: ext = sh.radius + 0.5 * sh.length; break;
    case ShapeType::Cylinder: ext = std::hypot(sh.radius, 0.5 * sh.length); break;
    case ShapeType::Box: ext = sh.half_extents.norm(); break;
    case ShapeType::Plane: ext = 0; break;
    case ShapeType::Ring: ext = sh.radius; break;
    case ShapeType::Face: ext = sh.half_extents.norm(); break;
  }
  return sh.pose.p.norm() + ext;
}

void appendPairCandidates(const Model& m, const State& s, int p, const CandidatePass& pass,
                          StepWorkspace& ws) {
  const ContactPair& pair = m.contacts[p];
  const BodyState& a = bodyOrGround(s, pair.a.body);
  const BodyState& b = bodyOrGround(s, pair.b.body);
  const std::array<double, 2>& reach = ws.facts.pair_reach[p];
  const double speeds = speedBound(a, reach[0]) + speedBound(b, reach[1]);
  const double margin = pass.extra_margin + pass.eps_act + 2.0 * pass.h * speeds;
  const double next_margin = 0.0 + pass.next_eps_act + 2.0 * pass.next_h * speeds;  // as a Step pass
  // The shapes' poses only where the points are computed, not taken from the cache.
  const int np = cachedPairPoints(ws.narrow, pass.cache, p, margin, next_margin, ws.points,
                                  [&](double mg, ContactPoint* out) {
                                    return collide(pair.a, poseOf(a) * pair.a.pose, pair.b,
                                                   poseOf(b) * pair.b.pose, mg, out);
                                  });
  int nahead = 0;
  if (pass.predict && np > 0) {
    const Pose qa = poseOf(bodyOrGround(ws.predicted, pair.a.body)) * pair.a.pose;
    const Pose qb = poseOf(bodyOrGround(ws.predicted, pair.b.body)) * pair.b.pose;
    nahead = collide(pair.a, qa, pair.b, qb, margin, ws.points_ahead);
  }
  for (int k = 0; k < np; ++k)
    pushCandidate(ws.points[k], pair.a.body, pair.b.body, pair.mu, pair.e, p, false,
                  p * kMaxPointsPerPair + ws.points[k].feature, ws.points_ahead, nahead, ws);
}

double contactPairGap(const State& s, const ContactPair& pair) {
  const Pose pa = poseOf(bodyOrGround(s, pair.a.body)) * pair.a.pose;
  const Pose pb = poseOf(bodyOrGround(s, pair.b.body)) * pair.b.pose;
  ContactPoint pts[kMaxPointsPerPair];
  const int np = collide(pair.a, pa, pair.b, pb, 1e300, pts);
  double g = std::numeric_limits<double>::infinity();
  for (int k = 0; k < np; ++k) g = std::min(g, pts[k].gap);
  return g;
}

}  // namespace nscd
