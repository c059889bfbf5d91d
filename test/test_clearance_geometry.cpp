// Clearance joint geometry: the ring-journal gap against brute-force sampling
// of the ring angle, the exact aligned formula, near-concentric poses, the
// bumps against brute-force sampling of their section circles, the nominal
// configurations of a joint, and the first-order consistency of normal and
// points with the gap under rigid displacements of either body.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "nscd_sim/clearance_geometry.hpp"
#include "test_support.hpp"

using namespace nscd;

namespace {

constexpr double kPi = 3.14159265358979323846;
const double kNaN = std::numeric_limits<double>::quiet_NaN();

double uni(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}
double logUni(std::mt19937_64& rng, double lo, double hi) {
  return std::exp(uni(rng, std::log(lo), std::log(hi)));
}
Vec3 randUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> nd;
  return Vec3(nd(rng), nd(rng), nd(rng)).normalized();
}
Quat randQuat(std::mt19937_64& rng) {
  std::normal_distribution<double> nd;
  return Quat(nd(rng), nd(rng), nd(rng), nd(rng)).normalized();
}
Vec3 randVec(std::mt19937_64& rng, double s) {
  return Vec3(uni(rng, -s, s), uni(rng, -s, s), uni(rng, -s, s));
}

// Distance from the ring point at angle phi to the journal axis: the
// definition, evaluated independently of the code under test.
struct Ring {
  Vec3 c, n, e1;
  double R;
  Vec3 o, a;
  double rj;
  Vec3 point(double phi) const {
    return c + R * (std::cos(phi) * e1 + std::sin(phi) * n.cross(e1));
  }
  double dist(double phi) const {
    const Vec3 w = point(phi) - o;
    return (w - w.dot(a) * a).norm();
  }
};

// Brute force: dense sampling, then golden section around every sampled local
// minimum (the distance is smooth in phi; golden converges to round-off in the
// value since the function is flat at its minimum).
double bruteGap(const Ring& r, double* phi_out = nullptr) {
  constexpr int N = 720;
  const double h = 2 * kPi / N;
  double ds[N];
  for (int i = 0; i < N; ++i) ds[i] = r.dist(i * h);
  double best = HUGE_VAL, best_phi = 0;
  for (int i = 0; i < N; ++i) {
    if (!(ds[i] <= ds[(i + N - 1) % N] && ds[i] <= ds[(i + 1) % N])) continue;
    double lo = (i - 1) * h, hi = (i + 1) * h;
    const double g = 0.3819660112501051;
    double x1 = lo + g * (hi - lo), x2 = hi - g * (hi - lo);
    double f1 = r.dist(x1), f2 = r.dist(x2);
    for (int it = 0; it < 80; ++it) {
      if (f1 <= f2) {
        hi = x2; x2 = x1; f2 = f1; x1 = lo + g * (hi - lo); f1 = r.dist(x1);
      } else {
        lo = x1; x1 = x2; f1 = f2; x2 = hi - g * (hi - lo); f2 = r.dist(x2);
      }
    }
    const double v = std::min({f1, f2, ds[i]});
    if (v < best) {
      best = v;
      best_phi = f1 <= f2 ? x1 : x2;
    }
  }
  if (phi_out) *phi_out = best_phi;
  return best - r.rj;
}

// Draws, in this order, the journal radius rj (log-uniform in [1e-3, 1e-2]),
// the radial clearance cr = R - rj (log-uniform in [cr_min, 1e-3]) and the
// ring normal n (uniform); sets e1 = anyOrthogonal(n). Returns cr.
double drawRingSize(std::mt19937_64& rng, double cr_min, Ring& r) {
  r.rj = logUni(rng, 1e-3, 1e-2);
  const double cr = logUni(rng, cr_min, 1e-3);
  r.R = r.rj + cr;
  r.n = randUnit(rng);
  r.e1 = anyOrthogonal(r.n);
  return cr;
}

// A random ring around a journal: rj in [1e-3, 1e-2], R - rj in [1e-6, 1e-3],
// tilt up to 2 sqrt(cr/R) (the ring then dips about cr into the journal),
// axis offset up to 1.5 cr, a random ring frame, centres anywhere in 10 cm.
// `concentric`: offset below 1e-9 m (the minimiser is then ill-defined).
Ring randomRing(std::mt19937_64& rng, bool concentric) {
  Ring r;
  const double cr = drawRingSize(rng, 1e-6, r);
  r.e1 = Quat(Eigen::AngleAxisd(uni(rng, 0, 2 * kPi), r.n)) * r.e1;
  r.c = randVec(rng, 0.05);
  const double tilt = std::min(0.5, uni(rng, 0, 2 * std::sqrt(cr / r.R)));
  const Vec3 tilt_axis = anyOrthogonal(r.n);
  r.a = Quat(Eigen::AngleAxisd(tilt, Quat(Eigen::AngleAxisd(uni(rng, 0, 2 * kPi), r.n)) * tilt_axis)) * r.n;
  if (uni(rng, 0, 1) < 0.5) r.a = -r.a;
  const double off = concentric ? (uni(rng, 0, 1) < 0.2 ? 0.0 : logUni(rng, 1e-18, 1e-9))
                                : uni(rng, 0, 1.5 * cr);
  const Vec3 e_dir = anyOrthogonal(r.a);
  const Vec3 e = off * (Quat(Eigen::AngleAxisd(uni(rng, 0, 2 * kPi), r.a)) * e_dir);
  r.o = r.c + e + uni(rng, -0.01, 0.01) * r.a;
  return r;
}

ContactPoint call(const Ring& r, double& phi) {
  return ringJournalContact(r.c, r.n, r.e1, r.R, r.o, r.a, r.rj, phi);
}

// Invariants of a ring contact: A on the ring, B on the journal surface, N
// orthogonal to the axis, gap = (pa - pb).N, phi locates point_a.
void expectRingContact(const Ring& r, const ContactPoint& cp, double phi) {
  ASSERT_TRUE(cp.point_a.allFinite() && cp.point_b.allFinite() && cp.normal.allFinite());
  ASSERT_TRUE(std::isfinite(cp.gap) && std::isfinite(phi));
  EXPECT_LE(std::abs(phi), kPi);  // kept wrapped: hints never grow
  EXPECT_NEAR(cp.normal.norm(), 1.0, 1e-14);
  EXPECT_NEAR(cp.normal.dot(r.a), 0.0, 1e-12);
  EXPECT_NEAR((cp.point_a - cp.point_b).dot(cp.normal), cp.gap, 1e-15);
  EXPECT_LE((cp.point_a - r.point(phi)).norm(), 1e-15);
  const Vec3 wb = cp.point_b - r.o;
  EXPECT_NEAR((wb - wb.dot(r.a) * r.a).norm(), r.rj, 1e-15);
}

// Frame with origin `centre`, z along `axis`, x along `ref` (orthogonal to axis).
Pose frameOf(const Vec3& centre, const Vec3& axis, const Vec3& ref) {
  Mat3 m;
  m.col(0) = ref;
  m.col(1) = axis.cross(ref);
  m.col(2) = axis;
  return Pose{centre, Quat(m).normalized()};
}

ClearanceJoint c60Joint(std::mt19937_64& rng) {
  ClearanceJoint cj;
  cj.bearing_axis = randUnit(rng);
  cj.bearing_ref = anyOrthogonal(cj.bearing_axis);
  cj.bearing_center = randVec(rng, 0.01);
  cj.journal_axis = randUnit(rng);
  cj.journal_center = randVec(rng, 0.01);
  cj.radius = 1.5e-3;
  cj.radial = 0.085e-3;
  cj.length = 3e-3;
  cj.axial = 0.1e-3;
  cj.bumps = 3;
  cj.bump_radius = 0.2e-3;
  cj.bump_at = 1.5 * (cj.radius + cj.radial);
  return cj;
}

// Journal body pose for a relative joint displacement `rel` (journal joint
// frame in the bearing joint frame; identity = centred and aligned).
Pose journalPose(const ClearanceJoint& cj, const Pose& bearing, const Pose& rel) {
  const Pose xb = frameOf(cj.bearing_center, cj.bearing_axis, cj.bearing_ref);
  const Pose xj = frameOf(cj.journal_center, cj.journal_axis, anyOrthogonal(cj.journal_axis));
  return bearing * xb * rel * xj.inverse();
}

// Second-order remainder allowed for the first-order prediction of the gap
// change under a rigid displacement (dt, dw) about `origin`, for a contact whose
// two points are within `lever` of the origin: those points move by
// s = |dt| + |dw| lever, the gap has curvature <= curv (1/m) along that motion,
// the rotation itself is second order beyond its linear part by
// lever |dw|^2 / 2, and a rotating normal couples with the translation (|dt||dw|).
double secondOrder(double curv, const Vec3& dt, const Vec3& dw, const ContactPoint& cp,
                          const Vec3& origin) {
  const double lever = std::max((cp.point_a - origin).norm(), (cp.point_b - origin).norm());
  const double s = dt.norm() + dw.norm() * lever;
  return curv * s * s + lever * dw.squaredNorm() + dt.norm() * dw.norm();
}

const ContactPoint* byFeature(const ContactPoint* pts, int n, int feature) {
  for (int i = 0; i < n; ++i)
    if (pts[i].feature == feature) return &pts[i];
  return nullptr;
}

}  // namespace

TEST(RingJournal, AlignedMatchesClosedForm) {
  std::mt19937_64 rng(1);
  double worst = 0;
  for (int trial = 0; trial < 500; ++trial) {
    Ring r = randomRing(rng, false);
    r.a = uni(rng, 0, 1) < 0.5 ? r.n : Vec3(-r.n);
    const Vec3 e = logUni(rng, 1e-9, 1.5 * (r.R - r.rj)) * anyOrthogonal(r.n);
    r.o = r.c + e + uni(rng, -0.002, 0.002) * r.n;
    const Vec3 oc = r.o - r.c;
    const Vec3 e_true = oc - oc.dot(r.n) * r.n;  // what the doubles actually hold
    double phi = trial % 2 ? kNaN : uni(rng, -10, 10);
    const ContactPoint cp = call(r, phi);
    expectRingContact(r, cp, phi);
    const double want = r.R - e_true.norm() - r.rj;
    EXPECT_NEAR(cp.gap, want, 1e-15 * r.R);
    worst = std::max(worst, std::abs(cp.gap - want) / r.R);
    // The minimiser is the ring point in the direction of e (a direction known
    // to round-off of |o - c| relative to |e|).
    EXPECT_LE((cp.point_a - (r.c + r.R * e_true.normalized())).norm(),
              1e-15 + 1e-15 * r.R * oc.norm() / e_true.norm());
  }
  std::printf("aligned: max |gap - (R - |e| - rj)| / R = %.2g\n", worst);
  // Concentric and aligned: every ring point is at R; the hint is kept.
  Ring r = randomRing(rng, false);
  r.a = r.n;
  r.o = r.c;  // exactly: o = c + s n would leave a round-off offset
  double phi = 1.25;
  ContactPoint cp = call(r, phi);
  EXPECT_EQ(phi, 1.25);
  EXPECT_NEAR(cp.gap, r.R - r.rj, 1e-15 * r.R);
  phi = kNaN;
  cp = call(r, phi);
  expectRingContact(r, cp, phi);
  EXPECT_NEAR(cp.gap, r.R - r.rj, 1e-15 * r.R);
}

TEST(RingJournal, MatchesBruteForceOnRandomPoses) {
  std::mt19937_64 rng(2);
  double worst = 0, worst_hint = 0;
  const int poses = 2500;
  for (int trial = 0; trial < poses; ++trial) {
    const Ring r = randomRing(rng, trial % 10 == 0);
    const double brute = bruteGap(r);
    double phi = kNaN;
    const ContactPoint cp = call(r, phi);
    expectRingContact(r, cp, phi);
    EXPECT_NEAR(cp.gap, brute, 1e-12) << "trial " << trial;
    worst = std::max(worst, std::abs(cp.gap - brute));
    // Any hint (random, or the answer itself) gives the same gap.
    double phi2 = uni(rng, -20, 20);
    const ContactPoint cp2 = call(r, phi2);
    EXPECT_NEAR(cp2.gap, cp.gap, 1e-15);
    double phi3 = phi;
    const ContactPoint cp3 = call(r, phi3);
    EXPECT_NEAR(cp3.gap, cp.gap, 1e-15);
    worst_hint = std::max({worst_hint, std::abs(cp2.gap - cp.gap), std::abs(cp3.gap - cp.gap)});
  }
  std::printf("ring vs brute force over %d poses: max |gap - brute| = %.3g m, hint effect %.3g m\n",
              poses, worst, worst_hint);
}

TEST(RingJournal, NearConcentricPosesDoNotFail) {
  std::mt19937_64 rng(3);
  double worst = 0;
  for (int trial = 0; trial < 500; ++trial) {
    Ring r = randomRing(rng, true);
    if (trial % 3 == 0) {  // tiny tilt too: the distance is flat in phi
      const double tilt = logUni(rng, 1e-14, 1e-6);
      r.a = Quat(Eigen::AngleAxisd(tilt, anyOrthogonal(r.n))) * r.n;
      r.o = r.c + uni(rng, -0.01, 0.01) * r.a;
    }
    double phi = trial % 2 ? kNaN : uni(rng, -4, 4);
    const ContactPoint cp = call(r, phi);
    expectRingContact(r, cp, phi);
    const double brute = bruteGap(r);
    EXPECT_NEAR(cp.gap, brute, 1e-12);
    worst = std::max(worst, std::abs(cp.gap - brute));
  }
  std::printf("near-concentric: max |gap - brute| = %.3g m\n", worst);
  // The journal axis through the ring itself (d = 0 somewhere): finite.
  Ring r = randomRing(rng, false);
  r.a = r.n;
  r.o = r.point(0.7);
  double phi = kNaN;
  const ContactPoint cp = call(r, phi);
  expectRingContact(r, cp, phi);
  EXPECT_NEAR(cp.gap, -r.rj, 1e-15);
}

// Gap change under a rigid displacement (dt, dw) of the body about origin:
// A (bearing): +N.dt + ((point_a - origin) x N).dw; B (journal): the negative,
// with point_b. Second-order remainder bounded by K h^2.
TEST(RingJournal, NormalAndPointsMatchFiniteDifferences) {
  std::mt19937_64 rng(4);
  const double h = 1e-7, lever = 0.01;
  double worst = 0;
  int checked = 0, teeth = 0;
  for (int trial = 0; trial < 400; ++trial) {
    // Well-defined minimiser: offset 0.3..1.5 cr, second harmonic (R tilt^2)
    // well below the first (|e|), clearance >= 3e-5 m.
    Ring r;
    const double cr = drawRingSize(rng, 3e-5, r);
    r.c = randVec(rng, 0.05);
    const double off = uni(rng, 0.3, 1.5) * cr;
    const double tilt = uni(rng, 0, 0.3 * std::sqrt(off / r.R));
    r.a = Quat(Eigen::AngleAxisd(tilt, Quat(Eigen::AngleAxisd(uni(rng, 0, 7), r.n)) * r.e1)) * r.n;
    const Vec3 e = off * (Quat(Eigen::AngleAxisd(uni(rng, 0, 7), r.a)) * anyOrthogonal(r.a));
    r.o = r.c + e + uni(rng, -0.005, 0.005) * r.a;
    double phi = kNaN;
    const ContactPoint cp = call(r, phi);
    for (int side = 0; side < 2; ++side) {
      const Vec3 origin = (side == 0 ? r.c : r.o) + randVec(rng, lever);
      const Vec3 dt = h * randUnit(rng), dw = (h / lever) * randUnit(rng);
      const Quat q = expMap(dw);
      Ring m = r;
      if (side == 0) {
        m.c = origin + dt + q * (r.c - origin);
        m.n = q * r.n;
        m.e1 = q * r.e1;
      } else {
        m.o = origin + dt + q * (r.o - origin);
        m.a = q * r.a;
      }
      double phi2 = phi;
      const ContactPoint moved = call(m, phi2);
      const Vec3& pt = side == 0 ? cp.point_a : cp.point_b;
      const double pred = (side == 0 ? 1 : -1) *
                          (cp.normal.dot(dt) + (pt - origin).cross(cp.normal).dot(dw));
      const double err = std::abs(moved.gap - cp.gap - pred);
      // Curvature of the gap: 1/|e| (the minimiser turns with the offset)
      // plus 1/rj; factor 2 spare, 1e-16 m round-off floor.
      const double bound = secondOrder(1.0 / off + 1.0 / r.rj, dt, dw, cp, origin);
      EXPECT_LT(err, 2 * bound + 1e-16) << "side " << side << " trial " << trial;
      worst = std::max(worst, err / bound);
      // Teeth: the same check with a lever arm wrong by 1 mm fails.
      const double wrong = pred + (side == 0 ? 1 : -1) * 1e-3 * cp.normal.cross(dw).norm();
      teeth += std::abs(moved.gap - cp.gap - wrong) > 2 * bound + 1e-16;
      ++checked;
    }
  }
  EXPECT_GT(teeth, 0.95 * checked);
  std::printf("ring FD: %d checks, max |error| / second-order bound = %.3g; wrong lever caught %d\n",
              checked, worst, teeth);
}

TEST(Clearance, CentredAndAlignedNominalGaps) {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const ClearanceJoint cj = c60Joint(rng);
    const Pose bearing{randVec(rng, 0.05), randQuat(rng)};
    const Pose journal = journalPose(cj, bearing, Pose{});
    double phi[2] = {kNaN, kNaN};
    ContactPoint out[kMaxClearancePoints];
    const int n = clearanceContacts(cj, bearing, journal, 1.0, false, phi, out);
    ASSERT_EQ(n, 2 + 2 * cj.bumps);
    const Vec3 nb = bearing.rotate(cj.bearing_axis), e1 = bearing.rotate(cj.bearing_ref);
    const Vec3 cb = bearing.apply(cj.bearing_center);
    for (int f = 0; f < n; ++f) {
      const ContactPoint* cp = byFeature(out, n, f);
      ASSERT_TRUE(cp) << f;
      EXPECT_NEAR((cp->point_a - cp->point_b).dot(cp->normal), cp->gap, 1e-15);
      if (f < 2) {
        EXPECT_NEAR(cp->gap, cj.radial, 1e-15);
        EXPECT_NEAR(nb.dot(cp->point_a - cb), f == 0 ? -1.5e-3 : 1.5e-3, 1e-15);
      } else {
        EXPECT_NEAR(cp->gap, 0.5 * cj.axial, 1e-15);
        // Bump apex: in the face plane at pitch radius, at 0/120/240 deg from ref.
        const int side = (f - 2) / cj.bumps, i = (f - 2) % cj.bumps;
        const double s = side == 0 ? -1 : 1, th = 2 * kPi * i / cj.bumps;
        const Vec3 u = std::cos(th) * e1 + std::sin(th) * nb.cross(e1);
        const Vec3 apex = cb + s * 0.5 * cj.length * nb + cj.bump_at * u;
        EXPECT_LE((cp->point_a - apex).norm(), 1e-15);
        EXPECT_LE((cp->normal + s * nb).norm(), 1e-14);  // towards the bearing
      }
    }
    EXPECT_TRUE(std::isfinite(phi[0]) && std::isfinite(phi[1]));
  }
}

TEST(Clearance, AxialShiftClosesOneFace) {
  std::mt19937_64 rng(6);
  const ClearanceJoint cj = c60Joint(rng);
  const Pose bearing{randVec(rng, 0.05), randQuat(rng)};
  for (double s : {-1.0, 1.0}) {
    // Journal moved by s ca/2 along the axis: its flange on the -s side meets
    // the -s face (the +s flange moves away by the same amount).
    const Pose rel{Vec3(0, 0, s * 0.5 * cj.axial), Quat::Identity()};
    double phi[2] = {kNaN, kNaN};
    ContactPoint out[kMaxClearancePoints];
    const int n = clearanceContacts(cj, bearing, journalPose(cj, bearing, rel), 1.0, false, phi, out);
    ASSERT_EQ(n, 8);
    for (int i = 0; i < 3; ++i) {
      const int closing = (s < 0 ? 5 : 2) + i, opening = (s < 0 ? 2 : 5) + i;
      EXPECT_NEAR(byFeature(out, n, closing)->gap, 0.0, 1e-15);
      EXPECT_NEAR(byFeature(out, n, opening)->gap, cj.axial, 1e-15);
    }
    EXPECT_NEAR(byFeature(out, n, 0)->gap, cj.radial, 1e-15);
    EXPECT_NEAR(byFeature(out, n, 1)->gap, cj.radial, 1e-15);
  }
}

TEST(Clearance, RadialOffsetClosesBothRings) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const ClearanceJoint cj = c60Joint(rng);
    const Pose bearing{randVec(rng, 0.05), randQuat(rng)};
    const double th = uni(rng, 0, 2 * kPi);
    const Pose rel{cj.radial * Vec3(std::cos(th), std::sin(th), 0), Quat(Eigen::AngleAxisd(uni(rng, 0, 7), Vec3::UnitZ()))};
    double phi[2] = {kNaN, kNaN};
    ContactPoint out[kMaxClearancePoints];
    const int n = clearanceContacts(cj, bearing, journalPose(cj, bearing, rel), 1.0, false, phi, out);
    ASSERT_EQ(n, 8);
    for (int f = 0; f < 2; ++f) {
      EXPECT_NEAR(byFeature(out, n, f)->gap, 0.0, 1e-16);  // round-off of world poses
      // Contact at the ring angle of the offset.
      EXPECT_NEAR(std::remainder(phi[f] - th, 2 * kPi), 0.0, 1e-9);
    }
    for (int f = 2; f < 8; ++f) EXPECT_NEAR(byFeature(out, n, f)->gap, 0.5 * cj.axial, 1e-15);
    // Margin filtering: only the two ring contacts are below 0.4 ca.
    const int m = clearanceContacts(cj, bearing, journalPose(cj, bearing, rel), 0.4 * cj.axial,
                                    false, phi, out);
    ASSERT_EQ(m, 2);
    EXPECT_TRUE(byFeature(out, m, 0) && byFeature(out, m, 1));
  }
}

TEST(Clearance, MarginKeepsOnlyTheCloseFace) {
  std::mt19937_64 rng(8);
  const ClearanceJoint cj = c60Joint(rng);
  const Pose bearing{randVec(rng, 0.05), randQuat(rng)};
  const Pose rel{Vec3(0, 0, 0.25 * cj.axial), Quat::Identity()};
  double phi[2] = {kNaN, kNaN};
  ContactPoint out[kMaxClearancePoints];
  // - face gaps are ca/4, + face 3ca/4, radial cr = 0.85 ca.
  const int n = clearanceContacts(cj, bearing, journalPose(cj, bearing, rel), 0.5 * cj.axial, false,
                                  phi, out);
  ASSERT_EQ(n, 3);
  for (int i = 0; i < n; ++i) {
    EXPECT_TRUE(out[i].feature >= 2 && out[i].feature <= 4);
    EXPECT_NEAR(out[i].gap, 0.25 * cj.axial, 1e-15);
  }
  EXPECT_TRUE(std::isfinite(phi[0]) && std::isfinite(phi[1]));  // hints updated anyway
}

TEST(Clearance, PlanarGivesOneMidRingPoint) {
  std::mt19937_64 rng(9);
  const ClearanceJoint cj = c60Joint(rng);
  const Pose bearing{randVec(rng, 0.05), randQuat(rng)};
  double phi[2] = {kNaN, kNaN};
  ContactPoint out[kMaxClearancePoints];
  const int n = clearanceContacts(cj, bearing, journalPose(cj, bearing, Pose{}), 1.0, true, phi, out);
  ASSERT_EQ(n, 1);
  EXPECT_EQ(out[0].feature, 0);
  EXPECT_NEAR(out[0].gap, cj.radial, 1e-15);
  const Vec3 nb = bearing.rotate(cj.bearing_axis);
  EXPECT_NEAR(nb.dot(out[0].point_a - bearing.apply(cj.bearing_center)), 0.0, 1e-15);
  // Offset in-plane by 0.6 cr: gap 0.4 cr.
  const Pose rel{Vec3(0.6 * cj.radial, 0, 0), Quat::Identity()};
  ASSERT_EQ(clearanceContacts(cj, bearing, journalPose(cj, bearing, rel), 1.0, true, phi, out), 1);
  EXPECT_NEAR(out[0].gap, 0.4 * cj.radial, 1e-15);
}

// Random tilted and offset poses: every bump gap equals the brute-force minimum
// over its half section circle of the signed distance to its flange plane, and
// ring gaps match ringJournalContact's brute force.
TEST(Clearance, BumpsMatchBruteForceOnTiltedPoses) {
  std::mt19937_64 rng(10);
  double worst = 0;
  for (int trial = 0; trial < 200; ++trial) {
    ClearanceJoint cj = c60Joint(rng);
    cj.bumps = 1 + trial % kMaxBumps;
    const Pose bearing{randVec(rng, 0.05), randQuat(rng)};
    const Vec3 tilt_axis(uni(rng, -1, 1), uni(rng, -1, 1), 0);
    const Pose rel{Vec3(uni(rng, -0.5, 0.5) * cj.radial, uni(rng, -0.5, 0.5) * cj.radial,
                        uni(rng, -0.5, 0.5) * cj.axial),
                   expMap(uni(rng, 0, 0.03) * tilt_axis.normalized()) *
                       Quat(Eigen::AngleAxisd(uni(rng, 0, 7), Vec3::UnitZ()))};
    const Pose journal = journalPose(cj, bearing, rel);
    double phi[2] = {kNaN, kNaN};
    ContactPoint out[kMaxClearancePoints];
    const int n = clearanceContacts(cj, bearing, journal, 1.0, false, phi, out);
    ASSERT_EQ(n, 2 + 2 * cj.bumps);
    const Vec3 nb = bearing.rotate(cj.bearing_axis), e1 = bearing.rotate(cj.bearing_ref);
    const Vec3 cb = bearing.apply(cj.bearing_center);
    const Vec3 aj = journal.rotate(cj.journal_axis), oj = journal.apply(cj.journal_center);
    for (int f = 2; f < n; ++f) {
      const int side = (f - 2) / cj.bumps, i = (f - 2) % cj.bumps;
      const double s = side == 0 ? -1 : 1, th = 2 * kPi * i / cj.bumps;
      const Vec3 u = std::cos(th) * e1 + std::sin(th) * nb.cross(e1);
      const Vec3 centre = cb + s * (0.5 * cj.length - cj.bump_radius) * nb + cj.bump_at * u;
      const Vec3 fl = oj + s * (0.5 * cj.length + 0.5 * cj.axial) * aj, m = -s * aj;
      // Half circle: angle psi in [-pi/2, pi/2] from the face normal s nb.
      auto sd = [&](double psi) {
        return m.dot(centre + cj.bump_radius * (std::cos(psi) * s * nb + std::sin(psi) * u) - fl);
      };
      double best = HUGE_VAL;
      for (int k = 0; k <= 2000; ++k) best = std::min(best, sd(-kPi / 2 + kPi * k / 2000));
      double lo = -kPi / 2, hi = kPi / 2;
      for (int it = 0; it < 100; ++it) {  // sd is unimodal on the half circle here
        const double x1 = lo + 0.382 * (hi - lo), x2 = hi - 0.382 * (hi - lo);
        if (sd(x1) <= sd(x2)) hi = x2; else lo = x1;
      }
      best = std::min(best, sd(0.5 * (lo + hi)));
      const ContactPoint* cp = byFeature(out, n, f);
      ASSERT_TRUE(cp);
      EXPECT_NEAR(cp->gap, best, 1e-15);
      EXPECT_NEAR(sd(0) - cp->gap, sd(0) - best, 1e-15);
      EXPECT_LE((cp->normal - m).norm(), 1e-15);
      worst = std::max(worst, std::abs(cp->gap - best));
    }
    for (int k = 0; k < 2; ++k) {
      Ring r{cb + (k == 0 ? -0.5 : 0.5) * cj.length * nb, nb, e1, cj.radius + cj.radial, oj, aj,
             cj.radius};
      EXPECT_NEAR(byFeature(out, n, k)->gap, bruteGap(r), 1e-12);
    }
  }
  std::printf("bumps vs brute force: max |gap - brute| = %.3g m\n", worst);
}

// Every clearance contact (rings and bumps), both bodies, against finite
// rigid displacements of the body frames.
TEST(Clearance, NormalAndPointsMatchFiniteDifferences) {
  std::mt19937_64 rng(11);
  const double h = 1e-7, lever = 0.02;
  double worst = 0;
  int checked = 0, bumps_checked = 0, teeth = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const ClearanceJoint cj = c60Joint(rng);
    const Pose bearing{randVec(rng, 0.01), randQuat(rng)};
    // Radial offset 0.3..0.9 cr (well-defined ring minimisers), small tilt.
    const double off = uni(rng, 0.3, 0.9) * cj.radial, th = uni(rng, 0, 7);
    const Pose rel{Vec3(off * std::cos(th), off * std::sin(th), uni(rng, -0.4, 0.4) * cj.axial),
                   expMap(Vec3(uni(rng, -1, 1), uni(rng, -1, 1), 0) * 1e-3)};
    const Pose journal = journalPose(cj, bearing, rel);
    double phi[2] = {kNaN, kNaN};
    ContactPoint base[kMaxClearancePoints], moved[kMaxClearancePoints];
    const int n = clearanceContacts(cj, bearing, journal, 1.0, false, phi, base);
    ASSERT_EQ(n, 8);
    for (int side = 0; side < 2; ++side) {
      const Pose& body = side == 0 ? bearing : journal;
      const Vec3 dt = h * randUnit(rng), dw = (h / lever) * randUnit(rng);
      const Pose disp{body.p + dt, (expMap(dw) * body.q).normalized()};
      double phi2[2] = {phi[0], phi[1]};
      const int m = clearanceContacts(cj, side == 0 ? disp : bearing, side == 1 ? disp : journal,
                                      1.0, false, phi2, moved);
      ASSERT_EQ(m, 8);
      for (int i = 0; i < n; ++i) {
        const ContactPoint* mv = byFeature(moved, m, base[i].feature);
        ASSERT_TRUE(mv);
        const Vec3& pt = side == 0 ? base[i].point_a : base[i].point_b;
        const double pred = (side == 0 ? 1 : -1) *
                            (base[i].normal.dot(dt) + (pt - body.p).cross(base[i].normal).dot(dw));
        const double err = std::abs(mv->gap - base[i].gap - pred);
        // Curvature 1/|e| + 1/rj for rings (|e| >= 0.3 cr), 1/bump_radius for
        // bumps; factor 2 spare, 1e-16 m round-off floor.
        const double curv = base[i].feature < 2 ? 1.0 / off + 1.0 / cj.radius : 1.0 / cj.bump_radius;
        const double bound = secondOrder(curv, dt, dw, base[i], body.p);
        EXPECT_LT(err, 2 * bound + 1e-16) << "feature " << base[i].feature << " side " << side;
        worst = std::max(worst, err / bound);
        ++checked;
        bumps_checked += base[i].feature >= 2;
        // Teeth: the same check with a lever arm wrong by 1 mm fails.
        const double wrong = pred + 1e-3 * base[i].normal.cross(dw).norm();
        teeth += std::abs(mv->gap - base[i].gap - wrong) > 2 * bound + 1e-16;
      }
    }
  }
  EXPECT_EQ(bumps_checked, 100 * 2 * 6);
  EXPECT_GT(teeth, 0.95 * checked);
  std::printf("clearance FD: %d checks, max |error| / second-order bound = %.3g; wrong lever caught %d\n",
              checked, worst, teeth);
}

TEST(Clearance, AllocatesNothing) {
  std::mt19937_64 rng(12);
  const ClearanceJoint cj = c60Joint(rng);
  const Pose bearing{randVec(rng, 0.05), randQuat(rng)};
  Pose poses[4];
  for (Pose& p : poses)
    p = journalPose(cj, bearing, Pose{randVec(rng, 5e-5), expMap(randVec(rng, 1e-2))});
  Ring rings[4];
  for (int i = 0; i < 4; ++i) rings[i] = randomRing(rng, i == 0);
  ContactPoint out[kMaxClearancePoints];
  double phi[2] = {kNaN, kNaN}, sum = 0;
  const long before = nscd_test::allocationCount();
  for (int i = 0; i < 4; ++i) {
    sum += clearanceContacts(cj, bearing, poses[i], 1.0, false, phi, out);
    sum += clearanceContacts(cj, bearing, poses[i], 1.0, true, phi, out);
    double p = kNaN;
    sum += call(rings[i], p).gap;
  }
  EXPECT_EQ(nscd_test::allocationCount(), before);
  std::vector<int> v(10);  // the counter itself works
  EXPECT_GT(nscd_test::allocationCount(), before);
  EXPECT_TRUE(std::isfinite(sum));
}
