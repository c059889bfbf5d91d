// Geometry of the revolute joint with clearance: bearing rings against the
// journal cylinder (radial) and face bumps against the journal flanges (axial).
// See design.md, appendix "Clearance ring gap".
#include "nscd_sim/clearance_geometry.hpp"

#include <cmath>

namespace nscd {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Squared distance from the ring point P(phi) to the journal axis is a
// trigonometric polynomial of degree 2:
//   f(phi) = A0 + A1 cos phi + B1 sin phi + A2 cos 2phi + B2 sin 2phi.
struct RingCoef {
  double A0, A1, B1, A2, B2;
  double f(double c1, double s1) const {
    return A0 + A1 * c1 + B1 * s1 + A2 * (c1 * c1 - s1 * s1) + B2 * (2 * s1 * c1);
  }
  // f' and f'' at (cos phi, sin phi) = (c1, s1).
  void derivs(double c1, double s1, double& d1, double& d2) const {
    const double c2 = c1 * c1 - s1 * s1, s2 = 2 * s1 * c1;
    d1 = -A1 * s1 + B1 * c1 - 2 * A2 * s2 + 2 * B2 * c2;
    d2 = -A1 * c1 - B1 * s1 - 4 * A2 * c2 - 4 * B2 * s2;
  }
};

// A ring angle together with its cosine and sine, so that Newton can rotate
// (c, s) by its steps instead of calling trig functions each iteration.
struct RingAngle {
  double phi, c, s;
};

RingAngle angleOf(double phi) { return RingAngle{phi, std::cos(phi), std::sin(phi)}; }

void rotateBy(RingAngle& x, double d) {
  double cd, sd;
  if (std::abs(d) < 1e-2) {  // series, error < 1e-20
    const double d2 = d * d;
    cd = 1 - 0.5 * d2 * (1 - d2 / 12 * (1 - d2 / 30));
    sd = d * (1 - d2 / 6 * (1 - d2 / 20 * (1 - d2 / 42)));
  } else {
    cd = std::cos(d);
    sd = std::sin(d);
  }
  const double c = x.c * cd - x.s * sd;
  x.s = x.s * cd + x.c * sd;
  x.c = c;
  x.phi += d;
}

// Newton on f' = 0 from x, kept inside the bracket [lo, hi] of angles
// travelled from x, where f'(lo) < 0 < f'(hi): a step that would leave the
// bracket is replaced by bisection (rtsafe).
RingAngle newtonInBracket(const RingCoef& k, RingAngle x, double lo, double hi) {
  double t = 0;
  for (int it = 0; it < 60; ++it) {
    double d1, d2;
    k.derivs(x.c, x.s, d1, d2);
    if (d1 < 0) lo = t; else hi = t;
    double step = 0.5 * (lo + hi) - t;
    bool newton = false;
    if (d2 > 0) {
      const double ns = -d1 / d2;
      if (t + ns > lo && t + ns < hi) {
        step = ns;
        newton = true;
      }
    }
    rotateBy(x, step);
    t += step;
    // A Newton step this small leaves an error ~step^2: converged.
    if ((newton && std::abs(step) < 1e-11) || hi - lo < 1e-11) break;
  }
  const double norm = std::sqrt(x.c * x.c + x.s * x.s);  // undo rotation round-off
  x.c /= norm;
  x.s /= norm;
  return x;
}

// Coarse scan of the ring at fixed angles (table built once, no trig per call).
constexpr int kScan = 32;
constexpr double kScanStep = 2 * kPi / kScan;
struct ScanTable {
  double c[kScan], s[kScan];
  ScanTable() {
    for (int k = 0; k < kScan; ++k) {
      c[k] = std::cos(k * kScanStep);
      s[k] = std::sin(k * kScanStep);
    }
  }
};
const ScanTable kTable;

// Minimiser of f around sample i, in the bracket of its two neighbours: Newton
// when f' changes sign across it, else golden section (f flat to round-off,
// where any point of the bracket does).
RingAngle sampleMin(const RingCoef& k, int i) {
  const int ip = (i + kScan - 1) % kScan, in = (i + 1) % kScan;
  double d1lo, d1hi, d2;
  k.derivs(kTable.c[ip], kTable.s[ip], d1lo, d2);
  k.derivs(kTable.c[in], kTable.s[in], d1hi, d2);
  const RingAngle at{i * kScanStep, kTable.c[i], kTable.s[i]};
  if (d1lo < 0 && d1hi > 0) return newtonInBracket(k, at, -kScanStep, kScanStep);
  const double g = 0.3819660112501051;  // 2 - golden ratio
  double lo = at.phi - kScanStep, hi = at.phi + kScanStep;
  double x1 = lo + g * (hi - lo), x2 = hi - g * (hi - lo);
  RingAngle a1 = angleOf(x1), a2 = angleOf(x2);
  double f1 = k.f(a1.c, a1.s), f2 = k.f(a2.c, a2.s);
  for (int it = 0; it < 45; ++it) {
    if (f1 <= f2) {
      hi = x2; x2 = x1; f2 = f1; a2 = a1;
      x1 = lo + g * (hi - lo); a1 = angleOf(x1); f1 = k.f(a1.c, a1.s);
    } else {
      lo = x1; x1 = x2; f1 = f2; a1 = a2;
      x2 = hi - g * (hi - lo); a2 = angleOf(x2); f2 = k.f(a2.c, a2.s);
    }
  }
  return f1 <= f2 ? a1 : a2;
}

// Bump directions: cos and sin of 2 pi i / bumps for every count up to kMaxBumps,
// computed once exactly as the loop below computed them per call (the angle
// laundered through a volatile so that the compiler cannot fold the trig calls
// into differently rounded constants).
struct BumpTable {
  double c[kMaxBumps + 1][kMaxBumps], s[kMaxBumps + 1][kMaxBumps];
  BumpTable() {
    for (int bumps = 1; bumps <= kMaxBumps; ++bumps)
      for (int i = 0; i < bumps; ++i) {
        volatile double th = 2 * kPi * i / bumps;
        const double t = th;
        c[bumps][i] = std::cos(t);
        s[bumps][i] = std::sin(t);
      }
  }
};
const BumpTable kBumpDirs;

// Facet directions of clearanceRingFacets, +-15, +-30, +-60 deg from the ring
// point's (the +-15 deg pair because with only +-30 and +-60 a journal cocked in
// its bearing, the two ring ends touching opposite sides, saw its contact
// directions swing by ~15 deg between passes and the passes stall: stress case
// 455). Their cos and sin made once, as BumpTable's (laundered through a volatile).
struct FacetTable {
  double c[kRingFacets], s[kRingFacets];
  FacetTable() {
    const double angles[kRingFacets] = {kPi / 12, -kPi / 12, kPi / 6, -kPi / 6, kPi / 3, -kPi / 3};
    for (int f = 0; f < kRingFacets; ++f) {
      volatile double th = angles[f];
      const double t = th;
      c[f] = std::cos(t);
      s[f] = std::sin(t);
    }
  }
};
const FacetTable kFacetDirs;

double angleDistance(double a, double b) { return std::abs(std::remainder(a - b, 2 * kPi)); }

// Global minimiser of f; the hint (if finite) starts Newton and breaks ties.
RingAngle ringMinimiser(const RingCoef& k, double hint) {
  // Offset dominates tilt (M1 > 5 M2, the usual case): f has a single minimum,
  // near the direction u of the axis offset (the first harmonic's minimiser).
  // Around u, where |sin(phi - u)| <= 2.2 M2/M1, f'' > 0 and f' changes sign:
  // a certified bracket for Newton, started from the hint when inside.
  const double m1 = k.A1 * k.A1 + k.B1 * k.B1, m2 = k.A2 * k.A2 + k.B2 * k.B2;
  if (m1 > 25 * m2) {
    const double M1 = std::sqrt(m1);
    const double ux = -k.A1 / M1, uy = -k.B1 / M1;
    const double sin_half = 2.2 * std::sqrt(m2 / m1);
    const double half = std::asin(sin_half);
    if (std::isfinite(hint)) {
      RingAngle x = angleOf(hint);
      const double sin_off = x.s * ux - x.c * uy, cos_off = x.c * ux + x.s * uy;
      if (cos_off > 0 && std::abs(sin_off) < sin_half) {
        const double off = std::asin(sin_off);  // hint - u
        return newtonInBracket(k, x, -off - half, -off + half);
      }
    }
    const RingAngle u{std::atan2(uy, ux), ux, uy};
    if (!(half > 1e-14)) return u;
    return newtonInBracket(k, u, -half, half);
  }

  // Sample, and keep the two lowest discrete local minima: f has at most two
  // local minima, and a basin too narrow to hold a sample is a shallow one,
  // far above the global minimum.
  double fs[kScan];
  for (int i = 0; i < kScan; ++i) fs[i] = k.f(kTable.c[i], kTable.s[i]);
  int cand[2] = {-1, -1};
  for (int i = 0; i < kScan; ++i) {
    const double fp = fs[(i + kScan - 1) % kScan], fn = fs[(i + 1) % kScan];
    if (!(fs[i] <= fp && fs[i] < fn)) continue;
    if (cand[0] < 0 || fs[i] < fs[cand[0]]) {
      cand[1] = cand[0];
      cand[0] = i;
    } else if (cand[1] < 0 || fs[i] < fs[cand[1]]) {
      cand[1] = i;
    }
  }
  if (cand[0] < 0) {  // f constant to round-off: any angle, the hint's if any
    return std::isfinite(hint) ? angleOf(hint) : RingAngle{0, 1, 0};
  }
  RingAngle best = sampleMin(k, cand[0]);
  if (cand[1] < 0) return best;
  const RingAngle other = sampleMin(k, cand[1]);
  const double fb = k.f(best.c, best.s), fo = k.f(other.c, other.s);
  // Equal minima (to round-off): keep the one nearer the hint, for continuity.
  const double tie = 1e-14 * std::abs(k.A0);
  if (fo < fb - tie) return other;
  if (fo <= fb + tie && std::isfinite(hint) &&
      angleDistance(other.phi, hint) < angleDistance(best.phi, hint))
    return other;
  return best;
}

}  // namespace

ContactPoint ringJournalContact(const Vec3& c, const Vec3& n, const Vec3& e1, double R,
                                const Vec3& o, const Vec3& a, double rj, double& phi,
                                bool track_angle) {
  const Vec3 e2 = n.cross(e1);
  const Vec3 w0 = c - o;
  if (n.cross(a).squaredNorm() < 1e-24) {
    // Axis normal to the ring plane (tilt below 1e-12): the nearest ring point
    // lies in the direction of the axis crossing e from the centre, and
    // g = R - |e| - rj exactly.
    const Vec3 e = -w0 + (n.dot(w0) / n.dot(a)) * a;
    const double ex = e.dot(e1), ey = e.dot(e2);
    const double enorm = std::sqrt(ex * ex + ey * ey);
    Vec3 dir;
    if (enorm > 0) {
      if (track_angle) phi = std::atan2(ey, ex);
      dir = (ex / enorm) * e1 + (ey / enorm) * e2;
    } else {  // concentric: every ring point; keep the hint's
      phi = std::isfinite(phi) ? std::remainder(phi, 2 * kPi) : 0.0;
      dir = std::cos(phi) * e1 + std::sin(phi) * e2;
    }
    ContactPoint cp;
    const double d = R - enorm;  // signed: the axis is inside the ring when d > 0
    cp.point_a = c + R * dir;
    cp.normal = d >= 0 ? dir : Vec3(-dir);
    const Vec3 foot = cp.point_a - std::abs(d) * cp.normal;
    cp.point_b = foot + rj * cp.normal;
    cp.gap = std::abs(d) - rj;
    return cp;
  }

  // Components orthogonal to the journal axis: d(phi)^2 = |u0 + cos u1 + sin u2|^2.
  const Vec3 u0 = w0 - w0.dot(a) * a;
  const Vec3 u1 = R * (e1 - e1.dot(a) * a);
  const Vec3 u2 = R * (e2 - e2.dot(a) * a);
  const double q1 = u1.squaredNorm(), q2 = u2.squaredNorm();
  RingCoef k;
  k.A0 = u0.squaredNorm() + 0.5 * (q1 + q2);
  k.A1 = 2 * u0.dot(u1);
  k.B1 = 2 * u0.dot(u2);
  k.A2 = 0.5 * (q1 - q2);
  k.B2 = u1.dot(u2);
  const RingAngle x = ringMinimiser(k, phi);
  phi = std::abs(x.phi) <= kPi ? x.phi : std::remainder(x.phi, 2 * kPi);

  // Final geometry straight from the points (not from f) for full precision.
  ContactPoint cp;
  cp.point_a = c + R * (x.c * e1 + x.s * e2);
  const Vec3 w = cp.point_a - o;
  const Vec3 foot = o + w.dot(a) * a;
  Vec3 dv = cp.point_a - foot;
  dv -= dv.dot(a) * a;  // again: round-off when the ring point is near the axis
  const double d = dv.norm();
  cp.normal = d > 0 ? Vec3(dv / d) : anyOrthogonal(a);
  cp.point_b = foot + rj * cp.normal;
  cp.gap = d - rj;
  return cp;
}

namespace {

// A clearance joint's frames at the current poses, in world coordinates.
struct ClearanceFrames {
  Vec3 nb, cb, e1, e2;  // bearing: axis, centre, reference direction, nb x e1
  Vec3 aj, oj;          // journal: axis, centre
};

// Axial: the bumps on the journal's end face `side` (0: at -L/2, 1: at +L/2)
// against the facing flange plane; the new count of points in out.
int addBumpContacts(const ClearanceJoint& cj, const ClearanceFrames& f, int side, int bumps,
                    double margin, int n, ContactPoint* out) {
  const Vec3 &nb = f.nb, &e1 = f.e1, &e2 = f.e2, &aj = f.aj;
  const double half = 0.5 * cj.length;
  const double rho = cj.bump_radius;
  const double s = side == 0 ? -1.0 : 1.0;
  const Vec3 flange = f.oj + (s * (half + 0.5 * cj.axial)) * aj;
  const Vec3 m = -s * aj;  // flange normal, towards the bearing
  // Centre of the section circles' plane offset: bump_radius inside the face.
  const Vec3 faceIn = f.cb + (s * (half - rho)) * nb;
  const double mn = m.dot(nb);
  // No bump of this side within the margin (the usual case: the journal's
  // axial play is far larger): skip them. Each bump's gap is at least this,
  // as |m.ui| <= |(m.e1, m.e2)| and its section point is within rho of centre.
  const double me1 = m.dot(e1), me2 = m.dot(e2);
  const double tilt = std::sqrt(me1 * me1 + me2 * me2);
  const double at = std::abs(cj.bump_at), r = std::abs(rho);
  const double lower = m.dot(faceIn - flange) - at * tilt - r * (std::abs(mn) + tilt);
  if (lower - margin > 1e-12 + 1e-9 * (at + r)) return n;
  for (int i = 0; i < bumps; ++i) {
    const Vec3 ui = kBumpDirs.c[bumps][i] * e1 + kBumpDirs.s[bumps][i] * e2;
    const Vec3 centre = faceIn + cj.bump_at * ui;
    // Point of the section circle (plane nb, ui) lowest along m, kept on the
    // outer half (s nb side); an end of the half circle otherwise.
    const double mu = m.dot(ui);
    double x = -mn, y = -mu;  // direction -m projected, in (nb, ui)
    const double len = std::sqrt(x * x + y * y);
    if (len > 0 && s * x >= 0) {
      x /= len;
      y /= len;
    } else {
      x = 0;
      y = mu > 0 ? -1.0 : 1.0;
    }
    const Vec3 pa = centre + rho * (x * nb + y * ui);
    const double gap = m.dot(pa - flange);
    if (!(gap < margin)) continue;
    ContactPoint& cp = out[n++];
    cp.point_a = pa;
    cp.point_b = pa - gap * m;
    cp.normal = m;
    cp.gap = gap;
    cp.feature = 2 + side * bumps + i;
  }
  return n;
}

}  // namespace

int clearanceContacts(const ClearanceJoint& cj, const Pose& bearing, const Pose& journal,
                      double margin, bool planar, double* phi_hint, ContactPoint* out) {
  ClearanceFrames f;
  f.nb = bearing.rotate(cj.bearing_axis);
  f.cb = bearing.apply(cj.bearing_center);
  f.e1 = bearing.rotate(cj.bearing_ref);
  f.aj = journal.rotate(cj.journal_axis);
  f.oj = journal.apply(cj.journal_center);
  const double R = cj.radius + cj.radial;
  const double half = 0.5 * cj.length;
  int n = 0;

  // Radial: rings at -L/2 (feature 0) and +L/2 (feature 1); one mid ring if planar.
  const int rings = planar ? 1 : 2;
  for (int k = 0; k < rings; ++k) {
    const double at = planar ? 0.0 : (k == 0 ? -half : half);
    ContactPoint cp =
        ringJournalContact(f.cb + at * f.nb, f.nb, f.e1, R, f.oj, f.aj, cj.radius, phi_hint[k], !planar);
    cp.feature = k;
    if (cp.gap < margin) out[n++] = cp;
  }
  if (planar) return n;

  // Axial: bumps on each end face against the facing flange plane.
  const int bumps = cj.bumps < 0 ? 0 : (cj.bumps > kMaxBumps ? kMaxBumps : cj.bumps);
  f.e2 = f.nb.cross(f.e1);
  for (int side = 0; side < 2; ++side) n = addBumpContacts(cj, f, side, bumps, margin, n, out);
  return n;
}

int clearanceRingFacets(const ClearanceJoint& cj, const Pose& bearing,
                        const ContactPoint& ring_point, double margin, ContactPoint* out) {
  const Vec3 nb = bearing.rotate(cj.bearing_axis);
  const Vec3 cb = bearing.apply(cj.bearing_center);
  const double R = cj.radius + cj.radial;
  // Ring centre: the bearing-axis point level with the ring point.
  const Vec3 c = cb + nb.dot(ring_point.point_a - cb) * nb;
  const Vec3 foot = ring_point.point_b - cj.radius * ring_point.normal;
  Vec3 n0 = ring_point.normal - ring_point.normal.dot(nb) * nb;
  if (n0.squaredNorm() < 1e-24) return 0;
  n0.normalize();
  const Vec3 m0 = nb.cross(n0);
  // Directions +-15, +-30, +-60 deg from the ring point's (kFacetDirs).
  int n = 0;
  for (int f = 0; f < kRingFacets; ++f) {
    const Vec3 dir = kFacetDirs.c[f] * n0 + kFacetDirs.s[f] * m0;
    ContactPoint cp;
    cp.point_a = c + R * dir;
    cp.point_b = foot + cj.radius * dir;
    cp.normal = dir;
    cp.gap = (cp.point_a - cp.point_b).dot(dir);
    cp.feature = ring_point.feature;
    if (cp.gap < margin) out[n++] = cp;
  }
  return n;
}

}  // namespace nscd
