// A named contact between two shapes (<nscd><contact>): its candidates and gap.
#pragma once

#include "contact_candidates.hpp"

namespace nscd {

// Narrowphase of shape pair `p`: its points within reach of the pass, into
// ws.candidates (warm-start slot p * kMaxPointsPerPair + feature).
void appendPairCandidates(const Model& m, const State& s, int p, const CandidatePass& pass,
                          StepWorkspace& ws);

// Distance from the body origin beyond which no point of the shape lies.
double shapeReach(const Shape& sh);
// Smallest gap of the pair at the state (m; +inf if no point).
double contactPairGap(const State& s, const ContactPair& pair);

}  // namespace nscd
