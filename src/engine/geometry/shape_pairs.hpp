// Narrow-phase pair routines kept out of contact_geometry.cpp (the dispatcher),
// one file each, and the small helpers they share. Internal to the engine.
//
// Every routine has the signature and contract of collide() for its canonical
// order (ring first): normal unit from B towards A, gap = (point_a - point_b) .
// normal, only points with gap < margin, at most kMaxPointsPerPair points, each
// with a feature id in [0, kMaxPointsPerPair) that is stable while the
// configuration changes smoothly, and no heap allocation.
#pragma once

#include <cmath>

#include "nscd_sim/contact_geometry.hpp"

namespace nscd {
namespace pairs {

constexpr double kTwoPi = 6.283185307179586;

// Appends a point when its gap is below margin and there is room; returns the new count.
inline int emit(ContactPoint* out, int n, const Vec3& pa, const Vec3& pb, const Vec3& normal,
                double gap, int feature, double margin) {
  if (!(gap < margin) || n >= kMaxPointsPerPair) return n;
  ContactPoint& cp = out[n];
  cp.point_a = pa;
  cp.point_b = pb;
  cp.normal = normal;
  cp.gap = gap;
  cp.feature = feature;
  return n + 1;
}

inline Vec3 axisZ(const Pose& p) { return p.rotate(Vec3::UnitZ()); }

// A shape's angular extent covers the whole circle (span given up to round-off).
inline bool fullCircle(double span) { return span >= kTwoPi * (1 - 1e-12); }

// Angle (rad, any value) lies in start + [0, span]; span in (0, 2 pi]. The
// ends belong to the arc, with a round-off allowance of 1e-12 rad.
inline bool angleInSpan(double angle, double start, double span) {
  if (fullCircle(span)) return true;
  double d = std::fmod(angle - start, kTwoPi);
  if (d < 0) d += kTwoPi;
  return d <= span + 1e-12 || d >= kTwoPi - 1e-12;
}

// A circle arc (centre c, unit in-plane axes e1, e2, radius r, angles
// start + [0, span]) of shape A against the plane through p0 of unit normal m,
// B's side below. `face` (may be null) is the pose of a bounded face of half
// sizes hx, hy in its xy plane: a point is then kept only when its foot on the
// plane lies in the closed rectangle. Features start at `base`: deepest point
// base, arc start base + 1, arc end base + 2, arc middle base + 3; a full ring
// parallel to the plane base + 3..5. Appends to out from n; returns the count.
int arcAgainstPlane(const Vec3& c, const Vec3& e1, const Vec3& e2, double r, double start,
                    double span, const Vec3& m, const Vec3& p0, const Pose* face, double hx,
                    double hy, int base, double margin, ContactPoint* out, int n);

int ringPlane(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
              ContactPoint* out);
int ringFace(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
             ContactPoint* out);
int ringCylinder(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
                 ContactPoint* out);

}  // namespace pairs
}  // namespace nscd
