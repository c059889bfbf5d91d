// The narrowphase memo's key (narrowphase_cache.hpp): the poses, compared bit
// for bit.
#include "narrowphase_cache.hpp"

#include <cstring>

namespace nscd {

void initNarrowphaseCache(int bodies, int pairs, int clearance_joints, NarrowphaseCache& c) {
  c.valid = false;
  c.x.assign(bodies, Vec3::Zero());
  c.q.assign(bodies, Quat::Identity());
  c.margin.assign(pairs, 0.0);
  c.count.assign(pairs, 0);
  c.points.assign(static_cast<size_t>(pairs) * kMaxPointsPerPair, ContactPoint());
  c.cj_margin.assign(clearance_joints, 0.0);
  c.cj_hint_in.assign(2 * clearance_joints, 0.0);
  c.cj_hint_out.assign(2 * clearance_joints, 0.0);
  c.cj_count.assign(clearance_joints, 0);
  c.cj_points.assign(static_cast<size_t>(clearance_joints) * kMaxClearancePoints, ContactPoint());
}

void storeNarrowphaseKey(const State& s, NarrowphaseCache& c) {
  for (size_t i = 0; i < c.x.size(); ++i) {
    c.x[i] = s.bodies[i].x;
    c.q[i] = s.bodies[i].q;
  }
  c.valid = true;
}

bool narrowphaseKeyMatches(const NarrowphaseCache& c, const State& s) {
  if (!c.valid || s.bodies.size() != c.x.size()) return false;
  for (size_t i = 0; i < c.x.size(); ++i)
    if (std::memcmp(c.x[i].data(), s.bodies[i].x.data(), 3 * sizeof(double)) != 0 ||
        std::memcmp(c.q[i].coeffs().data(), s.bodies[i].q.coeffs().data(), 4 * sizeof(double)) != 0)
      return false;
  return true;
}

}  // namespace nscd
