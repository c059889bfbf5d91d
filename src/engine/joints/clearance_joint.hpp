// The revolute joint with radial and axial clearance: its contact candidates
// (rings and bumps, geometry in clearance_geometry.cpp) and the journal's
// polarisation in its bearing.
#pragma once

#include "geometry/contact_candidates.hpp"

namespace nscd {

// Narrowphase of clearance joint `c`: its ring and bump points within reach of
// the pass, into ws.candidates; in Projection mode a penetrating ring also gets
// neighbouring facets of its disc. hint[0..1]: ring angles the searches start
// from, updated.
void appendClearanceCandidates(const Model& m, const State& s, int c, const CandidatePass& pass,
                               double* hint, StepWorkspace& ws);

// Eccentricity of the journal axis at mid-bearing, divided by c_r (0 centred,
// 1 touching), and its direction in the bearing frame (rad from bearing_ref).
double journalEccentricity(const State& s, const ClearanceJoint& cj);
double journalEccentricityAngle(const State& s, const ClearanceJoint& cj);

}  // namespace nscd
