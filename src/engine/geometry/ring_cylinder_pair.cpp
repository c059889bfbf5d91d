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

// The minimum inside [lo, hi] when f' < 0 at lo and > 0 at hi: Newton on f' kept
// in the shrinking bracket (bisection when a step would leave it) down to ~1e-9
// rad, then polished; an end if it is lower (f flat to round-off).
Angle bracketedMinimum(const RingAcrossAxis& g, double lo, double hi, const Angle& xlo, const Angle& xhi) {
  double a = lo, b = hi;
  Angle x = angleAt(0.5 * (lo + hi));
  bool evaluated = true;  // x.c, x.s are of x.t (a step sets x.t alone)
  for (int it = 0; it < 100; ++it) {
    if (!evaluated) x = angleAt(x.t);
    evaluated = true;
    double d1 = 0, d2 = 0;
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

// Golden section on [lo, hi] down to ~1e-9 rad, the ends if lower, then the polish.
Angle goldenMinimum(const RingAcrossAxis& g, double lo, double hi, const Angle& xlo, const Angle& xhi) {
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

// The minimiser of f on [lo, hi]. When f' < 0 at lo and > 0 at hi, the minimum
// inside is found by Newton (bracketedMinimum): about 5 evaluations of cos and
// sin where the golden section takes 45, with the same answer to round-off.
// Otherwise (f flat to round-off, or a minimum at an end): golden section;
// skipped, with the same answer, when f is certainly monotone (certainMonotone).
Angle minimiseOn(const RingAcrossAxis& g, double lo, double hi) {
  const Angle xlo = angleAt(lo), xhi = angleAt(hi);
  double dlo = 0, dhi = 0, d2 = 0;
  g.derivatives(xlo, dlo, d2);
  g.derivatives(xhi, dhi, d2);
  if (dlo < 0 && dhi > 0) return bracketedMinimum(g, lo, hi, xlo, xhi);
  if (const int mono = certainMonotone(g, lo, hi, dlo, dhi)) return mono > 0 ? xlo : xhi;
  return goldenMinimum(g, lo, hi, xlo, xhi);
}

// The ring seen across the cylinder's axis (w(t), f = sign |w|^2) and the frames
// the candidates are placed with.
struct RingCylinderFrame {
  Vec3 u, o;    // the cylinder's axis and a point on it
  Vec3 e1, e2;  // the ring's plane
  double r, R;  // ring and cylinder radii
  double sign;  // +1 solid cylinder, -1 hollow
  RingAcrossAxis g;
};

// A pair that far apart emits nothing, certainly: skip the sampling. Seen across
// the axis, the whole ring lies within sigma of w0 (sigma: the larger singular
// value of [w1 w2], so exact for a ring coaxial with the cylinder), and along
// the axis within r |(u.e1, u.e2)| of the centre's coordinate. The slack is the
// early-out's in sampleRing, far above the round-off.
bool certainlyApart(const RingCylinderFrame& fr, const Pose& pa, const Shape& b, double margin) {
  const RingAcrossAxis& g = fr.g;
  const double q1 = g.w1.squaredNorm(), q2 = g.w2.squaredNorm(), q12 = g.w1.dot(g.w2);
  const double sigma =
      std::sqrt(0.5 * (q1 + q2) + std::sqrt(0.25 * (q1 - q2) * (q1 - q2) + q12 * q12));
  const double across = g.w0.norm();
  const double lower = fr.sign > 0 ? across - sigma - fr.R : fr.R - across - sigma;
  const double slack = 1e-12 + 1e-9 * (fr.R + fr.r);
  if (lower - margin > slack) return true;
  const double ue1 = fr.u.dot(fr.e1), ue2 = fr.u.dot(fr.e2);
  const double along = std::abs(fr.u.dot(pa.p - fr.o)) - fr.r * std::sqrt(ue1 * ue1 + ue2 * ue2);
  return along - 0.5 * b.length > slack + 1e-9 * b.length;
}

// f sampled at the cells' ends over the ring's arc, and the lowest sample.
struct RingSamples {
  bool full;    // the ring is a full circle (samples wrap around)
  double span;  // rad
  double step;  // rad, between samples
  int count;
  int best;
  double f[kCellsPerTurn + 1];
};

// Samples f; false when no gap on the ring can be below the margin (nothing to refine).
bool sampleRing(const Shape& a, const RingCylinderFrame& fr, double margin, RingSamples& sm) {
  const RingAcrossAxis& g = fr.g;
  sm.full = fullCircle(a.span);
  sm.span = sm.full ? kTwoPi : a.span;
  const int cells =
      sm.full ? kCellsPerTurn
              : std::max(8, static_cast<int>(std::ceil(kCellsPerTurn * sm.span / kTwoPi)));
  sm.count = sm.full ? cells : cells + 1;
  sm.step = sm.span / cells;
  {
    // Sample by rotating (cos, sin) with a fixed step: no sin/cos per sample.
    const double cs = std::cos(sm.step), sn = std::sin(sm.step);
    double ct = std::cos(a.start), st = std::sin(a.start);
    for (int i = 0; i < sm.count; ++i) {
      sm.f[i] = fr.sign * (g.w0 + ct * g.w1 + st * g.w2).squaredNorm();
      const double c2 = ct * cs - st * sn;
      st = st * cs + ct * sn;
      ct = c2;
    }
  }
  sm.best = 0;
  for (int i = 1; i < sm.count; ++i)
    if (sm.f[i] < sm.f[sm.best]) sm.best = i;
  // Every point refined below lies within one cell of a sample, and moving
  // along the ring by dt moves w(t) by at most r dt: no gap on the ring is
  // below the best sample's minus r * step. A pair that far apart emits
  // nothing (emit() keeps gap < margin only), so the refinements are skipped.
  const double reach = std::sqrt(fr.sign * sm.f[sm.best]);
  const double lower = fr.sign > 0 ? reach - fr.R - fr.r * sm.step : fr.R - reach - fr.r * sm.step;
  return !(lower - margin > 1e-12 + 1e-9 * (fr.R + fr.r));
}

struct RingCandidates {
  Angle x[kMaxCandidates];
  int feature[kMaxCandidates];
  int count = 0;
};

// Every discrete local minimum of the samples (and the best one), refined in its
// two cells; an end of the arc if the minimum lies past it; minima within 1e-9
// rad of one already found dropped. Features numbered as in the file's head.
void refineMinima(const Shape& a, const RingAcrossAxis& g, const RingSamples& sm, RingCandidates& cand) {
  const bool full = sm.full;
  const int samples = sm.count;
  const double* fv = sm.f;
  int interior = 0;
  cand.count = 0;
  for (int i = 0; i < samples && cand.count < kMaxCandidates; ++i) {
    bool local_min;
    if (full) local_min = fv[i] < fv[(i + samples - 1) % samples] && fv[i] <= fv[(i + 1) % samples];
    else if (i == 0) local_min = fv[0] <= fv[1];
    else if (i == samples - 1) local_min = fv[i] < fv[i - 1];
    else local_min = fv[i] < fv[i - 1] && fv[i] <= fv[i + 1];
    if (!local_min && i != sm.best) continue;
    const double lo = (full || i > 0) ? a.start + (i - 1) * sm.step : a.start;
    const double hi = (full || i < samples - 1) ? a.start + (i + 1) * sm.step : a.start + sm.span;
    Angle x = minimiseOn(g, lo, hi);
    const double t = x.t;
    int feature;
    if (!full && t <= a.start) {
      x = angleAt(a.start);
      feature = 1;
    } else if (!full && t >= a.start + sm.span) {
      x = angleAt(a.start + sm.span);
      feature = 2;
    } else {
      feature = -1;  // numbered below, once known to be new
    }
    bool seen = false;
    for (int k = 0; k < cand.count; ++k) {
      double d = std::fmod(std::abs(x.t - cand.x[k].t), kTwoPi);
      d = std::min(d, kTwoPi - d);
      seen = seen || d < 1e-9;
    }
    if (seen) continue;
    if (feature < 0) feature = interior == 0 ? 0 : 2 + interior;
    if (feature == 0 || feature > 2) ++interior;
    cand.x[cand.count] = x;
    cand.feature[cand.count] = feature;
    ++cand.count;
  }
}

// The contact point of the ring point at x, if it lies on the cylinder's patch
// and is no deeper than the patch's nearest side; the new count of points.
int emitOnPatch(const RingCylinderFrame& fr, const Pose& pa, const Shape& b, const Pose& pb, const Angle& x,
                int feature, double margin, int n, ContactPoint* out) {
  const Vec3& u = fr.u;
  const double half = 0.5 * b.length;
  const Vec3 p = pa.p + fr.r * (x.c * fr.e1 + x.s * fr.e2);
  const Vec3 rel = p - fr.o;
  const double along = u.dot(rel);
  if (!(std::abs(along) <= half)) return n;
  double inside = half - std::abs(along);  // distance to the patch's nearest side
  const Vec3 radial = rel - along * u;
  const double d = radial.norm();
  // On the axis (to round-off) the direction is noise: any normal to it.
  const double tiny = 1e-14 * (rel.norm() + fr.R + fr.r);
  const Vec3 dir = d > tiny ? Vec3(radial / d) : anyOrthogonal(u);
  if (!fullCircle(b.span)) {
    const Vec3 dl = pb.q.conjugate() * dir;
    const double angle = std::atan2(dl.y(), dl.x());
    if (!angleInSpan(angle, b.start, b.span)) return n;
    // Angle to the nearer end of the span; the point's distance to the
    // half-plane through the axis at that end.
    double rel_angle = std::fmod(angle - b.start, kTwoPi);
    if (rel_angle < 0) rel_angle += kTwoPi;
    if (rel_angle > b.span) rel_angle = 0;  // on the start, by round-off
    const double to_end = std::min(rel_angle, b.span - rel_angle);
    inside = std::min(inside, to_end < kTwoPi / 4 ? d * std::sin(to_end) : d);
  }
  // B's outward normal: away from the axis, towards it for a hollow cylinder.
  const Vec3 normal = fr.sign * dir;
  const double gap = fr.sign * (d - fr.R);
  // Deeper than the patch's nearest side is far: the point came in from the
  // side (behind the patch), where other features of B lie.
  if (-gap > inside) return n;
  return emit(out, n, p, fr.o + along * u + fr.R * dir, normal, gap, feature, margin);
}

}  // namespace

int ringCylinder(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
                 ContactPoint* out) {
  const Vec3 u = axisZ(pb), o = pb.p;
  const Vec3 e1 = pa.rotate(Vec3::UnitX()), e2 = pa.rotate(Vec3::UnitY());
  const double r = a.radius;
  auto perp = [&u](const Vec3& v) { return Vec3(v - u.dot(v) * u); };
  const double sign = b.hollow ? -1.0 : 1.0;
  const RingCylinderFrame fr{u, o, e1, e2, r, b.radius, sign,
                             RingAcrossAxis{perp(pa.p - o), r * perp(e1), r * perp(e2), sign}};
  if (certainlyApart(fr, pa, b, margin)) return 0;
  RingSamples samples;
  if (!sampleRing(a, fr, margin, samples)) return 0;
  RingCandidates cand;
  refineMinima(a, fr.g, samples, cand);
  int n = 0;
  for (int k = 0; k < cand.count; ++k)
    n = emitOnPatch(fr, pa, b, pb, cand.x[k], cand.feature[k], margin, n, out);
  return n;
}

}  // namespace pairs
}  // namespace nscd
