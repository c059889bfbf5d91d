// Ring (or arc) against a face: the rectangle |x| <= sx/2, |y| <= sy/2 of B's
// xy plane, outward normal +z, material below it as for a plane.
//
// Rule at the edges: the ring is first taken against the face's unbounded plane
// (ring_plane_pair.cpp: its deepest point, or the arc's ends, or three points
// when parallel); each such point is kept only when its foot on the plane lies
// in the CLOSED rectangle (on an edge counts as on the face, no allowance).
// So a ring whose deepest point is beyond an edge gives no point, even if
// other parts of it lie over the face: what is past the edge is another
// contact's business (the edge itself, or the next face). A CAD edge-face
// distance would there be measured to the face's edge instead. The point
// vanishes with its gap unchanged: only the set of points jumps.
//
// Rule behind the face: a point deeper below the plane than its foot is far
// from the rectangle's nearest edge is dropped too. It came in from the side,
// behind the face (a part spinning round, a tooth passing under a tip), where
// B's other features are; pushing it out through the face would tear joints.
#include "shape_pairs.hpp"

namespace nscd {
namespace pairs {

int ringFace(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
             ContactPoint* out) {
  return arcAgainstPlane(pa.p, pa.rotate(Vec3::UnitX()), pa.rotate(Vec3::UnitY()), a.radius,
                         a.start, a.span, axisZ(pb), pb.p, &pb, b.half_extents.x(),
                         b.half_extents.y(), 0, margin, out, 0);
}

}  // namespace pairs
}  // namespace nscd
