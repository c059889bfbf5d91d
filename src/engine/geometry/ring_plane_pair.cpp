// Ring (a circle edge, or an arc of it) against an unbounded plane, and the
// core that ring-face and the arc-limited cylinder-plane pair share.
//
// The height of the ring point at angle t above the plane is
//   h(t) = m.(c - p0) + r (a cos t + b sin t),  a = m.e1, b = m.e2,
// a sinusoid of amplitude r rho (rho = |(a, b)|), lowest at t* = atan2(-b, -a).
// On an arc that does not contain t*, the sinusoid has no interior minimum, so
// its lowest point is an end of the arc: both ends are then given (each is an
// exact "point fixed in A against the plane" contact; the higher one is dropped
// by the margin or carries no force). When the ring is parallel to the plane
// (rho below 1e-6) t* is undefined and the whole ring is equally deep: three
// points carry it (the ends and the middle of an arc, or three points 120 deg
// apart on a full ring), as cylinder-plane does for a flat disc.
#include "shape_pairs.hpp"

namespace nscd {
namespace pairs {

namespace {

constexpr double kParallel = 1e-6;

int arcPoint(const Vec3& c, const Vec3& e1, const Vec3& e2, double r, double t, const Vec3& m,
             const Vec3& p0, const Pose* face, double hx, double hy, int feature, double margin,
             ContactPoint* out, int n) {
  const Vec3 p = c + r * (std::cos(t) * e1 + std::sin(t) * e2);
  const double s = m.dot(p - p0);
  const Vec3 foot = p - s * m;
  if (face) {
    // Closed rectangle, no allowance: a foot exactly on an edge counts as on the face.
    const Vec3 l = face->q.conjugate() * (foot - face->p);
    const double inside = std::min(hx - std::abs(l.x()), hy - std::abs(l.y()));
    if (!(inside >= 0)) return n;
    // Deeper below the face than its nearest edge is far: the point came in
    // from the side (behind the face), where other features of B lie.
    if (-s > inside) return n;
  }
  return emit(out, n, p, foot, m, s, feature, margin);
}

}  // namespace

int arcAgainstPlane(const Vec3& c, const Vec3& e1, const Vec3& e2, double r, double start,
                    double span, const Vec3& m, const Vec3& p0, const Pose* face, double hx,
                    double hy, int base, double margin, ContactPoint* out, int n) {
  const double a = m.dot(e1), b = m.dot(e2);
  const double rho = std::sqrt(a * a + b * b);
  // No point of the ring is lower than this: none within the margin (emit()
  // would keep none), so the points are not computed.
  const double lowest = m.dot(c - p0) - std::abs(r) * rho;
  if (lowest - margin > 1e-12 + 1e-9 * std::abs(r)) return n;
  const bool full = fullCircle(span);
  if (rho > kParallel) {
    const double deepest = std::atan2(-b, -a);
    if (angleInSpan(deepest, start, span))
      return arcPoint(c, e1, e2, r, deepest, m, p0, face, hx, hy, base, margin, out, n);
    n = arcPoint(c, e1, e2, r, start, m, p0, face, hx, hy, base + 1, margin, out, n);
    return arcPoint(c, e1, e2, r, start + span, m, p0, face, hx, hy, base + 2, margin, out, n);
  }
  if (full) {
    for (int k = 0; k < 3; ++k)
      n = arcPoint(c, e1, e2, r, start + k * (kTwoPi / 3), m, p0, face, hx, hy, base + 3 + k,
                   margin, out, n);
    return n;
  }
  n = arcPoint(c, e1, e2, r, start, m, p0, face, hx, hy, base + 1, margin, out, n);
  n = arcPoint(c, e1, e2, r, start + span, m, p0, face, hx, hy, base + 2, margin, out, n);
  return arcPoint(c, e1, e2, r, start + 0.5 * span, m, p0, face, hx, hy, base + 3, margin, out, n);
}

int ringPlane(const Shape& a, const Pose& pa, const Shape&, const Pose& pb, double margin,
              ContactPoint* out) {
  return arcAgainstPlane(pa.p, pa.rotate(Vec3::UnitX()), pa.rotate(Vec3::UnitY()), a.radius,
                         a.start, a.span, axisZ(pb), pb.p, nullptr, 0, 0, 0, margin, out, 0);
}

}  // namespace pairs
}  // namespace nscd
