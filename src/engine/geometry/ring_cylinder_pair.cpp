// Ring (or arc) outside the lateral surface of a cylinder (B, convex: the ring
// is kept out of it), or inside it when the cylinder is hollow (B's material
// outside the surface: a bore, a concave guide; the ring is kept in). The
// cylinder's axis may make any angle with the ring's.
//
// Seen across the cylinder axis u (through o), the ring point at angle t is
//   w(t) = perp(c - o) + r cos t perp(e1) + r sin t perp(e2),  perp(v) = v - (u.v) u,
// an ellipse (a circle when the axes are parallel, a segment when they are
// perpendicular), and the gap of that point is |w(t)| - R (hollow: R - |w(t)|).
// Its minima over the arc are found by sampling f(t) = +-|w(t)|^2 (a trigonometric polynomial of
// degree 2: at most two local minima on the full circle, plus the arc's ends)
// on 64 cells per turn, then refining every discrete local minimum by golden
// section in its two cells and Newton on f'. Each minimum is a contact point
// when it lies on the cylinder's patch: its axial coordinate within +-length/2
// and its direction from the axis within the cylinder's start + [0, span]
// (both closed), and it is no deeper than its distance to the patch's nearest
// side (a flat end, or the half-plane through the axis at an end of the span):
// a deeper point came in from the side, behind the patch, where B's other
// features are. Two minima within 1e-9 rad are one.
//
// Features: an interior minimum 0 (a second one, e.g. a ring straddling the
// axis of a perpendicular cylinder, 3, a third 4...; counted from the ring's
// start angle, so they keep their ids while no minimum crosses it), the arc's
// start 1, its end 2.
//
// Not handled: the cylinder's flat ends, two minima closer than about one cell
// (1/64 turn) in angle, which the sampling may merge into one. (A full journal
// in a full bore is a clearance joint, clearance_geometry.cpp.)
#include <algorithm>

#include "shape_pairs.hpp"

namespace nscd {
namespace pairs {

namespace {

constexpr int kCellsPerTurn = 64;
constexpr int kMaxCandidates = 6;

// An angle with its cosine and sine: the searches below evaluate f and its
// derivatives at the same angles more than once (a bracket's ends, the last
// Newton iterate, the polish's start, the final point), and the cos/sin calls
// are most of their cost. The values are std::cos(t), std::sin(t), so every sum
// is bit for bit what it was with the calls repeated.
struct Angle {
  double t, c, s;
};

Angle angleAt(double t) { return Angle{t, std::cos(t), std::sin(t)}; }

struct RingAcrossAxis {
  Vec3 w0, w1, w2;  // w(t) = w0 + cos t w1 + sin t w2
  double sign;      // +1: gap grows with |w| (solid cylinder); -1: hollow
  double f(const Angle& x) const { return sign * (w0 + x.c * w1 + x.s * w2).squaredNorm(); }
  void derivatives(const Angle& x, double& d1, double& d2) const {
    const double ct = x.c, st = x.s;
    const Vec3 w = w0 + ct * w1 + st * w2;
    const Vec3 wp = -st * w1 + ct * w2;
    const Vec3 wpp = -ct * w1 - st * w2;
    d1 = 2 * sign * w.dot(wp);
    d2 = 2 * sign * (wp.squaredNorm() + w.dot(wpp));
  }
};

// Newton steps on f' from t, kept only while inside (lo, hi) and |f'| drops
// (near the minimum f is flat to round-off: the steps are judged by |f'|).
Angle polish(const RingAcrossAxis& g, Angle x, double lo, double hi) {
  double d1 = 0, d2 = 0;
  g.derivatives(x, d1, d2);
  for (int it = 0; it < 4 && d1 != 0; ++it) {
    if (!(d2 > 0)) break;
    const double tn = x.t - d1 / d2;
    if (!(tn > lo && tn < hi)) break;
    const Angle xn = angleAt(tn);
    double n1 = 0, n2 = 0;
    g.derivatives(xn, n1, n2);
    if (!(std::abs(n1) < std::abs(d1))) break;
    x = xn;
    d1 = n1;
    d2 = n2;
  }
  return x;
}

// +1 if f is certainly increasing on [lo, hi] by enough that every comparison
// the golden section below makes is decided as in exact arithmetic (it then ends
// at lo), -1 likewise decreasing (it ends at hi), 0 if not certain. The usual
// case: an arc's end against a cylinder, the minimum at the end, which the
// section takes 42 evaluations of cos and sin to find again. Bounds: f' departs
// from its chord between the ends by at most (hi - lo)^2 / 8 max|f3| (f3 the
// third derivative, |f3| <= 2 (3 S1^2 + S S1), S1 = |w1| + |w2|, S = |w0| + S1);
// f and f' as computed are within 1e-13 S^2 of exact (about 20 ulps of S^2 in
// fact); the section's points lie at least 0.2 (hi - lo) kG^40 apart and from
// the ends (kG^40 = 4.37e-9).
int certainMonotone(const RingAcrossAxis& g, double lo, double hi, double dlo, double dhi) {
  const double s1 = g.w1.norm() + g.w2.norm(), S = g.w0.norm() + s1;
  const double err = 1e-13 * S * S;
  const double bend = (hi - lo) * (hi - lo) / 8 * 2 * (3 * s1 * s1 + S * s1);
  const double spacing = 0.2 * (hi - lo) * 4.3e-9;
  if (!(spacing > 1e-12 * (1 + std::abs(lo) + std::abs(hi)))) return 0;
  const double rise = std::min(dlo, dhi) - err - bend;
  if (rise * spacing > 4 * err) return 1;
  const double fall = std::min(-dlo, -dhi) - err - bend;
  if (fall * spacing > 4 * err) return -1;
  return 0;
}

// The minimiser of f on [lo, hi]. When f' < 0 at lo and > 0 at hi, the minimum
// inside is found by Newton on f' kept in the shrinking bracket (bisection when a
// step would leave it) down to ~1e-9 rad, then polished: about 5 evaluations of
// cos and sin where the golden section below takes 45, with the same answer to
// round-off. Otherwise (f flat to round-off, or a minimum at an end): golden
// section down to ~1e-9 rad, the ends if lower, then the polish; skipped, with
// the same answer, when f is certainly monotone (certainMonotone).
Angle minimiseOn(const RingAcrossAxis& g, double lo, double hi) {
  const Angle xlo = angleAt(lo), xhi = angleAt(hi);
  double dlo = 0, dhi = 0, d2 = 0;
  g.derivatives(xlo, dlo, d2);
  g.derivatives(xhi, dhi, d2);
  if (dlo < 0 && dhi > 0) {
    double a = lo, b = hi;
    Angle x = angleAt(0.5 * (lo + hi));
    bool evaluated = true;  // x.c, x.s are of x.t (a step sets x.t alone)
    for (int it = 0; it < 100; ++it) {
      if (!evaluated) x = angleAt(x.t);
      evaluated = true;
      double d1 = 0;
      g.derivatives(x, d1, d2);
      if (d1 < 0) a = x.t;
      else if (d1 > 0) b = x.t;
      else break;
      const double tn = x.t - d1 / d2;
      const bool newton = d2 > 0 && tn > a && tn < b;
      const double next = newton ? tn : 0.5 * (a + b);
      const double step = next - x.t;
      x.t = next;
      evaluated = false;
      if ((newton && std::abs(step) < 1e-9) || b - a < 1e-9) break;
    }
    if (!evaluated) x = angleAt(x.t);
    const double ft = g.f(x), flo = g.f(xlo), fhi = g.f(xhi);
    if (flo <= ft || fhi < ft) return flo <= ft && !(fhi < flo) ? xlo : xhi;
    return polish(g, x, lo, hi);
  }
  if (const int mono = certainMonotone(g, lo, hi, dlo, dhi)) return mono > 0 ? xlo : xhi;
  const double kG = 0.6180339887498949;
  double a = lo, b = hi;
  Angle x1 = angleAt(b - kG * (b - a)), x2 = angleAt(a + kG * (b - a));
  double f1 = g.f(x1), f2 = g.f(x2);
  for (int it = 0; it < 40; ++it) {
    if (f1 <= f2) {
      b = x2.t;
      x2 = x1;
      f2 = f1;
      x1 = angleAt(b - kG * (b - a));
      f1 = g.f(x1);
    } else {
      a = x1.t;
      x1 = x2;
      f1 = f2;
      x2 = angleAt(a + kG * (b - a));
      f2 = g.f(x2);
    }
  }
  Angle x = f1 <= f2 ? x1 : x2;
  double ft = std::min(f1, f2);  // only to compare with the ends
  const double flo = g.f(xlo), fhi = g.f(xhi);
  if (flo <= ft) {
    x = xlo;
    ft = flo;
  }
  if (fhi < ft) {
    x = xhi;
    ft = fhi;
  }
  if (x.t == lo || x.t == hi) return x;
  return polish(g, x, lo, hi);
}

}  // namespace

int ringCylinder(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
                 ContactPoint* out) {
  const Vec3 u = axisZ(pb), o = pb.p;
  const Vec3 e1 = pa.rotate(Vec3::UnitX()), e2 = pa.rotate(Vec3::UnitY());
  const double r = a.radius, R = b.radius;
  auto perp = [&u](const Vec3& v) { return Vec3(v - u.dot(v) * u); };
  const double sign = b.hollow ? -1.0 : 1.0;
  const RingAcrossAxis g{perp(pa.p - o), r * perp(e1), r * perp(e2), sign};

  {
    // A pair that far apart emits nothing, certainly: skip the sampling. Seen
    // across the axis, the whole ring lies within sigma of w0 (sigma: the larger
    // singular value of [w1 w2], so exact for a ring coaxial with the cylinder),
    // and along the axis within r |(u.e1, u.e2)| of the centre's coordinate.
    // The slack is the early-out's below, far above the round-off.
    const double q1 = g.w1.squaredNorm(), q2 = g.w2.squaredNorm(), q12 = g.w1.dot(g.w2);
    const double sigma =
        std::sqrt(0.5 * (q1 + q2) + std::sqrt(0.25 * (q1 - q2) * (q1 - q2) + q12 * q12));
    const double across = g.w0.norm();
    const double lower = sign > 0 ? across - sigma - R : R - across - sigma;
    const double slack = 1e-12 + 1e-9 * (R + r);
    if (lower - margin > slack) return 0;
    const double ue1 = u.dot(e1), ue2 = u.dot(e2);
    const double along = std::abs(u.dot(pa.p - o)) - r * std::sqrt(ue1 * ue1 + ue2 * ue2);
    if (along - 0.5 * b.length > slack + 1e-9 * b.length) return 0;
  }

  const bool full = fullCircle(a.span);
  const double span = full ? kTwoPi : a.span;
  const int cells =
      full ? kCellsPerTurn
           : std::max(8, static_cast<int>(std::ceil(kCellsPerTurn * span / kTwoPi)));
  const int samples = full ? cells : cells + 1;
  const double step = span / cells;
  double fv[kCellsPerTurn + 1];
  {
    // Sample by rotating (cos, sin) with a fixed step: no sin/cos per sample.
    const double cs = std::cos(step), sn = std::sin(step);
    double ct = std::cos(a.start), st = std::sin(a.start);
    for (int i = 0; i < samples; ++i) {
      fv[i] = sign * (g.w0 + ct * g.w1 + st * g.w2).squaredNorm();
      const double c2 = ct * cs - st * sn;
      st = st * cs + ct * sn;
      ct = c2;
    }
  }
  int best = 0;
  for (int i = 1; i < samples; ++i)
    if (fv[i] < fv[best]) best = i;
  {
    // Every point refined below lies within one cell of a sample, and moving
    // along the ring by dt moves w(t) by at most r dt: no gap on the ring is
    // below the best sample's minus r * step. A pair that far apart emits
    // nothing (emit() keeps gap < margin only), so the refinements are skipped.
    const double reach = std::sqrt(sign * fv[best]);
    const double lower = sign > 0 ? reach - R - r * step : R - reach - r * step;
    if (lower - margin > 1e-12 + 1e-9 * (R + r)) return 0;
  }

  Angle cand_x[kMaxCandidates];
  int cand_feature[kMaxCandidates];
  int nc = 0, interior = 0;
  for (int i = 0; i < samples && nc < kMaxCandidates; ++i) {
    bool local_min;
    if (full) local_min = fv[i] < fv[(i + samples - 1) % samples] && fv[i] <= fv[(i + 1) % samples];
    else if (i == 0) local_min = fv[0] <= fv[1];
    else if (i == samples - 1) local_min = fv[i] < fv[i - 1];
    else local_min = fv[i] < fv[i - 1] && fv[i] <= fv[i + 1];
    if (!local_min && i != best) continue;
    const double lo = (full || i > 0) ? a.start + (i - 1) * step : a.start;
    const double hi = (full || i < samples - 1) ? a.start + (i + 1) * step : a.start + span;
    Angle x = minimiseOn(g, lo, hi);
    const double t = x.t;
    int feature;
    if (!full && t <= a.start) {
      x = angleAt(a.start);
      feature = 1;
    } else if (!full && t >= a.start + span) {
      x = angleAt(a.start + span);
      feature = 2;
    } else {
      feature = -1;  // numbered below, once known to be new
    }
    bool seen = false;
    for (int k = 0; k < nc; ++k) {
      double d = std::fmod(std::abs(x.t - cand_x[k].t), kTwoPi);
      d = std::min(d, kTwoPi - d);
      seen = seen || d < 1e-9;
    }
    if (seen) continue;
    if (feature < 0) feature = interior == 0 ? 0 : 2 + interior;
    if (feature == 0 || feature > 2) ++interior;
    cand_x[nc] = x;
    cand_feature[nc] = feature;
    ++nc;
  }

  int n = 0;
  const double half = 0.5 * b.length;
  for (int k = 0; k < nc; ++k) {
    const Angle& x = cand_x[k];
    const Vec3 p = pa.p + r * (x.c * e1 + x.s * e2);
    const Vec3 rel = p - o;
    const double along = u.dot(rel);
    if (!(std::abs(along) <= half)) continue;
    double inside = half - std::abs(along);  // distance to the patch's nearest side
    const Vec3 radial = rel - along * u;
    const double d = radial.norm();
    // On the axis (to round-off) the direction is noise: any normal to it.
    const double tiny = 1e-14 * (rel.norm() + R + r);
    const Vec3 dir = d > tiny ? Vec3(radial / d) : anyOrthogonal(u);
    if (!fullCircle(b.span)) {
      const Vec3 dl = pb.q.conjugate() * dir;
      const double angle = std::atan2(dl.y(), dl.x());
      if (!angleInSpan(angle, b.start, b.span)) continue;
      // Angle to the nearer end of the span; the point's distance to the
      // half-plane through the axis at that end.
      double rel_angle = std::fmod(angle - b.start, kTwoPi);
      if (rel_angle < 0) rel_angle += kTwoPi;
      if (rel_angle > b.span) rel_angle = 0;  // on the start, by round-off
      const double to_end = std::min(rel_angle, b.span - rel_angle);
      inside = std::min(inside, to_end < kTwoPi / 4 ? d * std::sin(to_end) : d);
    }
    // B's outward normal: away from the axis, towards it for a hollow cylinder.
    const Vec3 normal = sign * dir;
    const double gap = sign * (d - R);
    // Deeper than the patch's nearest side is far: the point came in from the
    // side (behind the patch), where other features of B lie.
    if (-gap > inside) continue;
    n = emit(out, n, p, o + along * u + R * dir, normal, gap, cand_feature[k], margin);
  }
  return n;
}

}  // namespace pairs
}  // namespace nscd
