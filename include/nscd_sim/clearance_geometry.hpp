// Geometry of the revolute joint with clearance: bearing ring vs journal cylinder
// (radial contacts) and face bumps vs journal flange planes (axial contacts).
#pragma once

#include "nscd_sim/contact_geometry.hpp"

namespace nscd {

constexpr int kMaxBumps = 8;
constexpr int kMaxClearancePoints = 2 + 2 * kMaxBumps;

// Gap between a bearing ring (circle: centre c, unit normal n, radius R) and a
// journal cylinder (axis through o with unit direction a, radius rj), all world.
// gap = min over the ring of (distance to the journal axis) - rj.
// Result as a ContactPoint with A = bearing (point_a on the ring), B = journal
// (point_b on the cylinder surface), normal from the journal axis to the ring point.
// phi (in/out) is the ring angle of the minimiser, measured from the unit vector
// e1 (orthogonal to n) about n; pass the previous value as a hint, or NaN. With
// track_angle false, an untilted journal (the only kind in planar scenes) leaves
// phi as it was: its minimiser needs no hint, and atan2 is a tenth of the call.
ContactPoint ringJournalContact(const Vec3& c, const Vec3& n, const Vec3& e1, double R,
                                const Vec3& o, const Vec3& a, double rj, double& phi, bool track_angle = true);

// Contact points of one clearance joint: up to 2 radial + 2*bumps axial points
// with gap below margin. A = bearing body, B = journal body. Features: 0,1 radial
// (ring at -L/2, +L/2); 2.. axial bumps. bearing/journal: world poses of the two
// body frames. phi_hint: 2 ring angles (in/out). out must hold kMaxClearancePoints.
int clearanceContacts(const ClearanceJoint& cj, const Pose& bearing, const Pose& journal,
                      double margin, bool planar, double* phi_hint, ContactPoint* out);

// For the position projection: the radial constraint of a ring is the disc
// |e| <= R - rj, and one half-plane (the deepest direction, `ring_point`) is a
// poor model of it when the correction is comparable to the clearance: passes
// then oscillate around the circle. This adds the half-planes at +-15, +-30 and
// +-60 degrees about the ring axis (tangent lines of the same disc, each a
// necessary condition), those with gap below margin. The journal axis point of
// `ring_point` is kept (exact for an untilted journal). out must hold
// kRingFacets points.
constexpr int kRingFacets = 6;
int clearanceRingFacets(const ClearanceJoint& cj, const Pose& bearing,
                        const ContactPoint& ring_point, double margin, ContactPoint* out);

}  // namespace nscd
