// A memo of the shape pairs' narrowphase at one configuration. The projection's
// check at q_{k+1} and the next step's pass at q_k look at the same poses whenever
// nothing moved the bodies in between (the projection made no correction, no
// setState): the step then takes its points at q_k from here instead of computing
// them again. Internal to the engine.
//
// Exact by construction: an entry is used only when every body's pose is bit for
// bit the one the projection's pass saw, and a pair's narrowphase at margin M is
// the one at a larger margin M' with the points of gap >= M dropped (the margin is
// a filter; the ring-cylinder early-out is a lower bound), unless the wider pass
// filled all kMaxPointsPerPair points (then it is computed again).
//
// Clearance joints too: their ring search starts Newton from a hint and leaves
// its answer there, so an entry also keys on the hints the search started from
// and keeps the hints it left. The projection's last check leaves the state's
// hints where it found them (projection.cpp), so the next step's search would
// start from the same hints: reading the entry is then exact, and a state handed
// to another simulator (no cache) steps to the same bits. Their points are never
// capped (kMaxClearancePoints).
#pragma once

#include <vector>

#include "nscd_sim/clearance_geometry.hpp"
#include "nscd_sim/contact_geometry.hpp"
#include "nscd_sim/simulator.hpp"

namespace nscd {

struct NarrowphaseCache {
  bool valid = false;
  // Key: the poses the pass that filled the cache saw.
  std::vector<Vec3> x;
  std::vector<Quat> q;
  // Per contact pair: the margin its points were gathered with and how many
  // (kMaxPointsPerPair slots each).
  std::vector<double> margin;
  std::vector<int> count;
  std::vector<ContactPoint> points;
  // Per clearance joint, the same (kMaxClearancePoints slots each), and its 2
  // ring hints before and after the search.
  std::vector<double> cj_margin, cj_hint_in, cj_hint_out;
  std::vector<int> cj_count;
  std::vector<ContactPoint> cj_points;
};

// Sizes the cache for a model's bodies, contact pairs and clearance joints (invalid).
void initNarrowphaseCache(int bodies, int pairs, int clearance_joints, NarrowphaseCache& c);
// Records the key: the state's poses.
void storeNarrowphaseKey(const State& s, NarrowphaseCache& c);
// True if the cache is valid and keyed exactly on these poses.
bool narrowphaseKeyMatches(const NarrowphaseCache& c, const State& s);

// What a geometry pass does with the cache.
enum class CacheUse { None, Fill, Read };

// The points of contact pair `pair` at `margin` into out, via the cache:
// - Read: from the cache if its entry has them (see the header comment), else computed;
// - Fill: computed at max(margin, fill_margin), kept in the cache, filtered to margin;
// - None: computed.
// compute(margin, out) runs the pair's narrowphase and returns the count.
template <class Compute>
int cachedPairPoints(NarrowphaseCache& c, CacheUse use, int pair, double margin,
                     double fill_margin, ContactPoint* out, Compute compute) {
  constexpr int cap = kMaxPointsPerPair;  // a pass that kept this many may have dropped some
  ContactPoint* slots = c.points.data() + pair * kMaxPointsPerPair;
  const double cached = c.margin[pair];
  if (use == CacheUse::Read && (margin == cached || (margin < cached && c.count[pair] < cap))) {
    int n = 0;
    for (int k = 0; k < c.count[pair]; ++k)
      if (slots[k].gap < margin) out[n++] = slots[k];
    return n;
  }
  if (use != CacheUse::Fill) return compute(margin, out);
  const double wide = fill_margin > margin ? fill_margin : margin;
  c.margin[pair] = wide;
  c.count[pair] = compute(wide, slots);
  if (wide != margin && c.count[pair] >= cap) return compute(margin, out);
  int n = 0;
  for (int k = 0; k < c.count[pair]; ++k)
    if (slots[k].gap < margin) out[n++] = slots[k];
  return n;
}

}  // namespace nscd
