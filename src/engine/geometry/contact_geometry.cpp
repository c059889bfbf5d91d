// Narrow phase: contact points between pairs of primitive shapes.
//
// Each pair routine takes its shapes in a canonical order (ring < sphere <
// capsule < cylinder < box < plane < face); collide() swaps the arguments when
// needed and flips the results back. The ring pairs live in files of their own
// (ring_*_pair.cpp, declared in shape_pairs.hpp); this file dispatches. Every point is "a point fixed in one shape against the
// nearest point of the other", so normal and points give the exact first-order
// change of the gap under rigid motions (the engine builds Jacobian rows from
// them).
#include "nscd_sim/contact_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "shape_pairs.hpp"

namespace nscd {
namespace {

int typeRank(ShapeType t) {
  switch (t) {
    case ShapeType::Ring: return 0;
    case ShapeType::Sphere: return 1;
    case ShapeType::Capsule: return 2;
    case ShapeType::Cylinder: return 3;
    case ShapeType::Box: return 4;
    case ShapeType::Plane: return 5;
    case ShapeType::Face: return 6;
  }
  return 7;
}

double clampd(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }

using pairs::emit;  // shape_pairs.hpp, shared with the ring pairs
using pairs::axisZ;

// Two balls (centres ca, cb; radii ra, rb): the core of sphere, capsule pairs.
// `fallback` is the normal when the centres coincide (deterministic, no NaN).
int balls(const Vec3& ca, double ra, const Vec3& cb, double rb, const Vec3& fallback, int feature,
          double margin, ContactPoint* out, int n) {
  const Vec3 d = ca - cb;
  const double d2 = d.squaredNorm();
  double dist = 0;
  Vec3 normal = fallback;
  // Below round-off of the coordinates the direction of d is noise.
  const double tiny = 1e-14 * (ca.cwiseAbs().maxCoeff() + cb.cwiseAbs().maxCoeff() + ra + rb);
  if (d2 > tiny * tiny) {
    dist = std::sqrt(d2);
    normal = d / dist;
  }
  return emit(out, n, ca - ra * normal, cb + rb * normal, normal, dist - ra - rb, feature, margin);
}

// A point fixed in A, of "radius" r (0 for a corner), against the plane of B.
int pointPlane(const Vec3& p, double r, const Vec3& m, const Vec3& p0, int feature, double margin,
               ContactPoint* out, int n) {
  const double s = m.dot(p - p0);
  return emit(out, n, p - r * m, p - s * m, m, s - r, feature, margin);
}


int spherePlane(const Shape& a, const Pose& pa, const Shape&, const Pose& pb, double margin,
                ContactPoint* out) {
  return pointPlane(pa.p, a.radius, axisZ(pb), pb.p, 0, margin, out, 0);
}

int sphereSphere(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
                 ContactPoint* out) {
  return balls(pa.p, a.radius, pb.p, b.radius, Vec3::UnitZ(), 0, margin, out, 0);
}

int sphereCapsule(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
                  ContactPoint* out) {
  const Vec3 u = axisZ(pb);
  const double h = 0.5 * b.length;
  const double t = clampd(u.dot(pa.p - pb.p), -h, h);
  return balls(pa.p, a.radius, pb.p + t * u, b.radius, anyOrthogonal(u), 0, margin, out, 0);
}

// A ball (centre c, radius r) against a box: the nearest point of the box, or,
// with the centre inside, the nearest face. Shared by sphere-box and capsule-box.
int ballBox(const Vec3& c, double r, const Shape& b, const Pose& pb, int feature, double margin,
            ContactPoint* out, int n) {
  const Vec3& h = b.half_extents;
  const Vec3 l = pb.q.conjugate() * (c - pb.p);  // ball centre in the box frame
  const Vec3 q(clampd(l.x(), -h.x(), h.x()), clampd(l.y(), -h.y(), h.y()),
               clampd(l.z(), -h.z(), h.z()));
  const Vec3 diff = l - q;
  const double d2 = diff.squaredNorm();
  if (d2 > 1e-280) {  // centre outside: nearest point of the box
    const double dist = std::sqrt(d2);
    const Vec3 normal = pb.rotate(diff / dist);
    return emit(out, n, c - r * normal, pb.apply(q), normal, dist - r, feature, margin);
  }
  // Centre inside (or on the surface): push out through the nearest face.
  int axis = 0;
  double depth = h.x() - std::abs(l.x());
  for (int i = 1; i < 3; ++i) {
    const double di = h[i] - std::abs(l[i]);
    if (di < depth) {
      depth = di;
      axis = i;
    }
  }
  const double sgn = l[axis] >= 0 ? 1.0 : -1.0;
  Vec3 nl = Vec3::Zero();
  nl[axis] = sgn;
  Vec3 onFace = l;
  onFace[axis] = sgn * h[axis];
  const Vec3 normal = pb.rotate(nl);
  return emit(out, n, c - r * normal, pb.apply(onFace), normal, -depth - r, feature, margin);
}

int sphereBox(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
              ContactPoint* out) {
  return ballBox(pa.p, a.radius, b, pb, 0, margin, out, 0);
}

// Capsule against box: the two ends of the capsule's segment, each as a ball.
// When the segment is parallel to a box edge (within 2.6 deg; pins and arcs of
// mechanisms whose axes are all parallel), the ends are first clamped to the
// box's extent along that edge, where the distance to the box does not vary
// along the segment: the two points then carry a line contact exactly. In
// other poses the ends are exact only when an end is the segment's nearest
// point (a segment crossing a box edge at its middle is missed).
int capsuleBox(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
               ContactPoint* out) {
  const Vec3 u = axisZ(pa);
  const double h = 0.5 * a.length;
  Vec3 e0 = pa.p - h * u, e1 = pa.p + h * u;
  const Vec3 ul = pb.q.conjugate() * u;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(ul[k]) < 0.999) continue;
    Vec3 l0 = pb.q.conjugate() * (e0 - pb.p), l1 = pb.q.conjugate() * (e1 - pb.p);
    const double hk = b.half_extents[k];
    if (std::max(l0[k], l1[k]) >= -hk && std::min(l0[k], l1[k]) <= hk) {
      l0[k] = clampd(l0[k], -hk, hk);
      l1[k] = clampd(l1[k], -hk, hk);
      e0 = pb.apply(l0);
      e1 = pb.apply(l1);
    }
    break;
  }
  const int n = ballBox(e0, a.radius, b, pb, 0, margin, out, 0);
  return ballBox(e1, a.radius, b, pb, 1, margin, out, n);
}

int capsulePlane(const Shape& a, const Pose& pa, const Shape&, const Pose& pb, double margin,
                 ContactPoint* out) {
  const Vec3 u = axisZ(pa);
  const Vec3 m = axisZ(pb);
  const double h = 0.5 * a.length;
  int n = pointPlane(pa.p - h * u, a.radius, m, pb.p, 0, margin, out, 0);
  return pointPlane(pa.p + h * u, a.radius, m, pb.p, 1, margin, out, n);
}

int boxPlane(const Shape& a, const Pose& pa, const Shape&, const Pose& pb, double margin,
             ContactPoint* out) {
  const Vec3 m = axisZ(pb);
  const Vec3& h = a.half_extents;
  // Keep the 4 deepest corners below margin, sorted by gap (ties: lower index).
  double gaps[4];
  int ids[4];
  Vec3 pts[4];
  int k = 0;
  for (int i = 0; i < 8; ++i) {
    const Vec3 local((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z());
    const Vec3 p = pa.apply(local);
    const double g = m.dot(p - pb.p);
    if (!(g < margin)) continue;
    if (k == 4 && !(g < gaps[3])) continue;
    int j = (k < 4) ? k++ : 3;
    while (j > 0 && g < gaps[j - 1]) {
      gaps[j] = gaps[j - 1];
      ids[j] = ids[j - 1];
      pts[j] = pts[j - 1];
      --j;
    }
    gaps[j] = g;
    ids[j] = i;
    pts[j] = p;
  }
  int n = 0;
  for (int j = 0; j < k; ++j) n = pointPlane(pts[j], 0.0, m, pb.p, ids[j], margin, out, n);
  return n;
}

int capsuleCapsule(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
                   ContactPoint* out) {
  const Vec3 u = axisZ(pa), v = axisZ(pb);
  const double ha = 0.5 * a.length, hb = 0.5 * b.length;
  const Vec3 r = pa.p - pb.p;
  const double bb = u.dot(v), c = u.dot(r), f = v.dot(r);
  const double denom = 1.0 - bb * bb;  // sin^2 of the angle between the axes
  // Closest points A(s) = pa.p + s u, B(t) = pb.p + t v minimise |r + s u - t v|:
  // s = b t - c, t = b s + f on the lines.
  if (denom > 1e-12) {
    double s = clampd((bb * f - c) / denom, -ha, ha);
    double t = bb * s + f;
    if (t < -hb || t > hb) {
      t = clampd(t, -hb, hb);
      s = clampd(bb * t - c, -ha, ha);
    }
    const Vec3 cross = u.cross(v) / std::sqrt(denom);
    return balls(pa.p + s * u, a.radius, pb.p + t * v, b.radius, cross, 0, margin, out, 0);
  }
  // Parallel axes: B's segment seen on A's parameter line is [lo, hi].
  const double e0 = -hb * bb - c, e1 = hb * bb - c;
  const double lo = std::max(std::min(e0, e1), -ha), hi = std::min(std::max(e0, e1), ha);
  const Vec3 fallback = anyOrthogonal(u);
  if (hi - lo > 1e-9 * (ha + hb)) {
    // Overlap: one point at each end. An end is either an end of A (fixed in A,
    // nearest point of B's segment) or an end of B (fixed in B, nearest of A's).
    int n = 0;
    const double ends[2] = {lo, hi};
    for (int k = 0; k < 2; ++k) {
      const double s0 = ends[k];
      Vec3 xa, xb;
      if (std::abs(s0) >= ha) {  // end of A
        xa = pa.p + s0 * u;
        xb = pb.p + clampd(v.dot(xa - pb.p), -hb, hb) * v;
      } else {  // end of B
        const double t = (k == 0) == (bb > 0) ? -hb : hb;
        xb = pb.p + t * v;
        xa = pa.p + clampd(u.dot(xb - pa.p), -ha, ha) * u;
      }
      n = balls(xa, a.radius, xb, b.radius, fallback, k, margin, out, n);
    }
    return n;
  }
  // Disjoint along the axis (or touching at one point): the nearest ends.
  double s = 0.5 * (lo + hi);
  if (hi < lo) s = std::max(e0, e1) < -ha ? -ha : ha;
  const double t = clampd(bb * s + f, -hb, hb);
  s = clampd(bb * t - c, -ha, ha);
  return balls(pa.p + s * u, a.radius, pb.p + t * v, b.radius, fallback, 0, margin, out, 0);
}

int cylinderPlane(const Shape& a, const Pose& pa, const Shape&, const Pose& pb, double margin,
                  ContactPoint* out) {
  const Vec3 u = axisZ(pa);
  const Vec3 m = axisZ(pb);
  const double h = 0.5 * a.length;
  if (!pairs::fullCircle(a.span)) {
    // Lateral surface limited to an arc: its lowest points lie on the two end
    // rims, each an arc against the plane (ring_plane_pair.cpp); features 0-3
    // for the rim at -length/2, 4-7 for the one at +length/2.
    const Vec3 x = pa.rotate(Vec3::UnitX()), y = pa.rotate(Vec3::UnitY());
    int n = 0;
    for (int k = 0; k < 2; ++k)
      n = pairs::arcAgainstPlane(pa.p + (k == 0 ? -h : h) * u, x, y, a.radius, a.start, a.span, m,
                                 pb.p, nullptr, 0, 0, 4 * k, margin, out, n);
    return n;
  }
  const Vec3 perp = m - m.dot(u) * u;
  const double pn = perp.norm();
  int n = 0;
  // Below this tilt (rad) a disc counts as parallel to the plane: its deepest
  // rim point is ill-defined, so three rim points carry it.
  constexpr double kParallel = 1e-6;
  if (pn > kParallel) {
    const Vec3 rim = -(a.radius / pn) * perp;  // towards the deepest rim point
    n = pointPlane(pa.p - h * u + rim, 0.0, m, pb.p, 0, margin, out, n);
    return pointPlane(pa.p + h * u + rim, 0.0, m, pb.p, 1, margin, out, n);
  }
  const Vec3 x = pa.rotate(Vec3::UnitX()), y = pa.rotate(Vec3::UnitY());
  const double c120 = -0.5, s120 = 0.8660254037844386;
  const Vec3 dirs[3] = {x, c120 * x + s120 * y, c120 * x - s120 * y};
  for (int k = 0; k < 2; ++k) {
    const Vec3 centre = pa.p + (k == 0 ? -h : h) * u;
    for (int j = 0; j < 3; ++j)
      n = pointPlane(centre + a.radius * dirs[j], 0.0, m, pb.p, 3 * k + j, margin, out, n);
  }
  return n;
}

using PairFn = int (*)(const Shape&, const Pose&, const Shape&, const Pose&, double, ContactPoint*);

// The routine for a canonically ordered pair, or nullptr.
PairFn pairFunction(ShapeType a, ShapeType b) {
  using T = ShapeType;
  if (a == T::Sphere) {
    if (b == T::Plane) return spherePlane;
    if (b == T::Sphere) return sphereSphere;
    if (b == T::Box) return sphereBox;
    if (b == T::Capsule) return sphereCapsule;
  }
  if (a == T::Capsule) {
    if (b == T::Plane) return capsulePlane;
    if (b == T::Capsule) return capsuleCapsule;
    if (b == T::Box) return capsuleBox;
  }
  if (a == T::Box && b == T::Plane) return boxPlane;
  if (a == T::Cylinder && b == T::Plane) return cylinderPlane;
  if (a == T::Ring) {
    if (b == T::Plane) return pairs::ringPlane;
    if (b == T::Face) return pairs::ringFace;
    if (b == T::Cylinder) return pairs::ringCylinder;
  }
  return nullptr;
}

}  // namespace

bool shapePairSupported(ShapeType a, ShapeType b) {
  if (typeRank(a) > typeRank(b)) std::swap(a, b);
  return pairFunction(a, b) != nullptr;
}

int collide(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
            ContactPoint* out) {
  if (typeRank(a.type) <= typeRank(b.type)) {
    PairFn fn = pairFunction(a.type, b.type);
    return fn ? fn(a, pa, b, pb, margin, out) : 0;
  }
  PairFn fn = pairFunction(b.type, a.type);
  if (!fn) return 0;
  const int n = fn(b, pb, a, pa, margin, out);
  for (int i = 0; i < n; ++i) {
    std::swap(out[i].point_a, out[i].point_b);
    out[i].normal = -out[i].normal;
  }
  return n;
}

}  // namespace nscd
