// What the narrowphase of a contact source (contact_pair.cpp, clearance_joint.cpp)
// shares with the candidate stage (contact_candidates.cpp). Internal.
#pragma once

#include "narrowphase_cache.hpp"
#include "step/step_stages.hpp"

namespace nscd {

// One geometry pass over the contact sources.
struct CandidatePass {
  CandidateMode mode = CandidateMode::Step;
  double h = 0;             // step length (0 in the projection modes)
  double extra_margin = 0;  // projection: reach of the correction
  double eps_act = 0;       // gap under which a contact counts as closed
  bool predict = false;     // rows at ws.predicted where the feature is there too
  // The shape pairs' memo (narrowphase_cache.hpp): the projection fills it wide
  // enough for the next step's margins (h and eps_act below), the step reads it.
  CacheUse cache = CacheUse::None;
  double next_h = 0, next_eps_act = 0;
};

// The gap under which a contact counts as closed in this mode.
double activationTolerance(const Settings& set, CandidateMode mode);

inline Pose poseOf(const BodyState& b) { return Pose{b.x, b.q}; }

// Upper bound of the speed of any point within `reach` of the body origin.
inline double speedBound(const BodyState& b, double reach) {
  return b.v.norm() + b.w.norm() * reach;
}

// Appends the candidate of point cp to ws.candidates; `ahead` holds the same
// source's points at ws.predicted (nahead of them, 0 without prediction).
void pushCandidate(const ContactPoint& cp, int body_a, int body_b, double mu, double e,
                   int source, bool clearance, int slot, const ContactPoint* ahead, int nahead,
                   StepWorkspace& ws);

}  // namespace nscd
