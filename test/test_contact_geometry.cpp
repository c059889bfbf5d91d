// Narrow phase: every supported shape pair against analytic configurations,
// symmetry under swapping A and B, margin filtering, degenerate inputs, and the
// first-order consistency of normal and points with the gap (what the engine
// builds Jacobian rows from) against finite rigid displacements.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cstdio>
#include <cmath>
#include <random>
#include <vector>

#include "nscd_sim/contact_geometry.hpp"
#include "test_support.hpp"

using namespace nscd;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTol = 1e-12;

// A sphere, capsule or cylinder of radius r and length len (0 for a sphere).
Shape roundShape(ShapeType type, double r, double len) {
  Shape s;
  s.type = type;
  s.radius = r;
  s.length = len;
  return s;
}
Shape sphere(double r) { return roundShape(ShapeType::Sphere, r, 0); }
Shape capsule(double r, double len) { return roundShape(ShapeType::Capsule, r, len); }
Shape cylinder(double r, double len) { return roundShape(ShapeType::Cylinder, r, len); }
Shape box(const Vec3& h) {
  Shape s;
  s.type = ShapeType::Box;
  s.half_extents = h;
  return s;
}
Shape plane() {
  Shape s;
  s.type = ShapeType::Plane;
  return s;
}

// A ring (circle edge) of radius r, limited to the arc start + [0, span].
Shape ring(double r, double start = 0, double span = 2 * kPi) {
  Shape s;
  s.type = ShapeType::Ring;
  s.radius = r;
  s.start = start;
  s.span = span;
  return s;
}
// A face: the rectangle |x| <= sx/2, |y| <= sy/2 of its frame's xy plane.
Shape face(double sx, double sy) {
  Shape s;
  s.type = ShapeType::Face;
  s.half_extents = Vec3(0.5 * sx, 0.5 * sy, 0);
  return s;
}
// A cylinder whose lateral surface is limited to the arc start + [0, span].
Shape cylinderArc(double r, double len, double start, double span) {
  Shape s = roundShape(ShapeType::Cylinder, r, len);
  s.start = start;
  s.span = span;
  return s;
}
// The same with the material outside the surface (a bore, a concave guide).
Shape hollowArc(double r, double len, double start = 0, double span = 2 * kPi) {
  Shape s = cylinderArc(r, len, start, span);
  s.hollow = true;
  return s;
}

Pose at(const Vec3& p, const Quat& q = Quat::Identity()) { return Pose{p, q}; }
Quat rotAbout(const Vec3& axis, double angle) {
  return Quat(Eigen::AngleAxisd(angle, axis.normalized()));
}

Vec3 randUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> nd;
  Vec3 v(nd(rng), nd(rng), nd(rng));
  return v.normalized();
}
Quat randQuat(std::mt19937_64& rng) {
  std::normal_distribution<double> nd;
  Quat q(nd(rng), nd(rng), nd(rng), nd(rng));
  return q.normalized();
}
double uni(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// Invariants every contact point must satisfy.
void expectWellFormed(const ContactPoint& cp, double margin) {
  ASSERT_TRUE(cp.point_a.allFinite());
  ASSERT_TRUE(cp.point_b.allFinite());
  ASSERT_TRUE(cp.normal.allFinite());
  ASSERT_TRUE(std::isfinite(cp.gap));
  EXPECT_NEAR(cp.normal.norm(), 1.0, 1e-14);
  EXPECT_NEAR((cp.point_a - cp.point_b).dot(cp.normal), cp.gap, 1e-13);
  EXPECT_LT(cp.gap, margin);
}

int run(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
        ContactPoint* out) {
  for (int i = 0; i < kMaxPointsPerPair; ++i) out[i].gap = std::nan("");  // poison
  const int n = collide(a, pa, b, pb, margin, out);
  EXPECT_GE(n, 0);
  EXPECT_LE(n, kMaxPointsPerPair);
  for (int i = 0; i < n; ++i) expectWellFormed(out[i], margin);
  return n;
}

const ContactPoint* byFeature(const ContactPoint* pts, int n, int feature) {
  for (int i = 0; i < n; ++i)
    if (pts[i].feature == feature) return &pts[i];
  return nullptr;
}

void expectVecNear(const Vec3& a, const Vec3& b, double tol) {
  EXPECT_LE((a - b).norm(), tol) << "got " << a.transpose() << " expected " << b.transpose();
}

}  // namespace

TEST(ContactGeometry, SupportedPairs) {
  using T = ShapeType;
  const T yes[][2] = {{T::Sphere, T::Plane},  {T::Sphere, T::Sphere},   {T::Sphere, T::Box},
                      {T::Sphere, T::Capsule}, {T::Capsule, T::Plane},  {T::Box, T::Plane},
                      {T::Capsule, T::Capsule}, {T::Cylinder, T::Plane}, {T::Capsule, T::Box},
                      {T::Ring, T::Plane},     {T::Ring, T::Face},      {T::Ring, T::Cylinder}};
  for (auto& p : yes) {
    EXPECT_TRUE(shapePairSupported(p[0], p[1]));
    EXPECT_TRUE(shapePairSupported(p[1], p[0]));
  }
  const T no[][2] = {{T::Plane, T::Plane},     {T::Box, T::Box},         {T::Cylinder, T::Cylinder},
                     {T::Sphere, T::Cylinder}, {T::Capsule, T::Cylinder},
                     {T::Cylinder, T::Box},    {T::Ring, T::Ring},       {T::Ring, T::Sphere},
                     {T::Ring, T::Box},        {T::Ring, T::Capsule},    {T::Face, T::Face},
                     {T::Face, T::Plane},      {T::Face, T::Sphere},     {T::Face, T::Cylinder}};
  for (auto& p : no) {
    EXPECT_FALSE(shapePairSupported(p[0], p[1]));
    EXPECT_FALSE(shapePairSupported(p[1], p[0]));
  }
  ContactPoint out[kMaxPointsPerPair];
  EXPECT_EQ(collide(box(Vec3(1, 1, 1)), Pose{}, box(Vec3(1, 1, 1)), Pose{}, 1.0, out), 0);
}

TEST(ContactGeometry, SpherePlaneOnTiltedPlane) {
  const Quat qp = rotAbout(Vec3(1, 2, 0.5), 0.7);
  const Vec3 p0(0.3, -0.2, 0.1);
  const Vec3 m = qp * Vec3::UnitZ();
  const Vec3 t = anyOrthogonal(m);
  const double r = 0.05;
  ContactPoint out[kMaxPointsPerPair];
  for (double g : {0.0, 0.01, -0.003}) {
    const Vec3 c = p0 + 0.4 * t + (r + g) * m;
    ASSERT_EQ(run(sphere(r), at(c), plane(), at(p0, qp), 0.02, out), 1);
    EXPECT_NEAR(out[0].gap, g, kTol);
    expectVecNear(out[0].normal, m, kTol);
    expectVecNear(out[0].point_a, c - r * m, kTol);
    expectVecNear(out[0].point_b, p0 + 0.4 * t, kTol);
    EXPECT_EQ(out[0].feature, 0);
  }
  // Separated beyond the margin: nothing.
  EXPECT_EQ(run(sphere(r), at(p0 + (r + 0.03) * m), plane(), at(p0, qp), 0.02, out), 0);
  // Centre below the plane surface: still one point, deeply negative.
  ASSERT_EQ(run(sphere(r), at(p0 - 0.2 * m), plane(), at(p0, qp), 0.0, out), 1);
  EXPECT_NEAR(out[0].gap, -0.25, kTol);
}

TEST(ContactGeometry, SphereSphere) {
  ContactPoint out[kMaxPointsPerPair];
  const Vec3 cb(0.1, 0.2, 0.3), dir = Vec3(1, -2, 2) / 3.0;
  for (double g : {0.0, 0.02, -0.05}) {
    const Vec3 ca = cb + (0.3 + 0.2 + g) * dir;
    ASSERT_EQ(run(sphere(0.3), at(ca), sphere(0.2), at(cb), 0.05, out), 1);
    EXPECT_NEAR(out[0].gap, g, kTol);
    expectVecNear(out[0].normal, dir, kTol);
    expectVecNear(out[0].point_a, ca - 0.3 * dir, kTol);
    expectVecNear(out[0].point_b, cb + 0.2 * dir, kTol);
  }
  EXPECT_EQ(run(sphere(0.3), at(cb + 0.6 * dir), sphere(0.2), at(cb), 0.05, out), 0);
  // Concentric: some unit normal, gap = -(ra + rb), same answer every time.
  ASSERT_EQ(run(sphere(0.3), at(cb), sphere(0.2), at(cb), 0.0, out), 1);
  EXPECT_NEAR(out[0].gap, -0.5, kTol);
  ContactPoint again[kMaxPointsPerPair];
  ASSERT_EQ(run(sphere(0.3), at(cb), sphere(0.2), at(cb), 0.0, again), 1);
  EXPECT_EQ(out[0].normal, again[0].normal);
}

TEST(ContactGeometry, SphereBoxFaceEdgeCornerInside) {
  const Vec3 h(0.1, 0.2, 0.3);
  const Quat qb = rotAbout(Vec3(0.3, -1, 0.4), 1.1);
  const Vec3 pb(0.5, 0.1, -0.2);
  const Pose box_pose = at(pb, qb);
  const double r = 0.05;
  ContactPoint out[kMaxPointsPerPair];
  auto W = [&](const Vec3& l) { return box_pose.apply(l); };
  auto D = [&](const Vec3& l) { return Vec3(qb * l); };
  // Face +y, separated by 0.01.
  {
    const Vec3 c = W(Vec3(0.03, 0.2 + r + 0.01, -0.1));
    ASSERT_EQ(run(sphere(r), at(c), box(h), box_pose, 0.1, out), 1);
    EXPECT_NEAR(out[0].gap, 0.01, kTol);
    expectVecNear(out[0].normal, D(Vec3::UnitY()), kTol);
    expectVecNear(out[0].point_b, W(Vec3(0.03, 0.2, -0.1)), kTol);
  }
  // Edge (+x, -z), diagonal direction, penetrating by 0.02.
  {
    const Vec3 dl = Vec3(1, 0, -1).normalized();
    const Vec3 edge(0.1, 0.05, -0.3);
    const Vec3 c = W(edge + (r - 0.02) * dl);
    ASSERT_EQ(run(sphere(r), at(c), box(h), box_pose, 0.0, out), 1);
    EXPECT_NEAR(out[0].gap, -0.02, kTol);
    expectVecNear(out[0].normal, D(dl), kTol);
    expectVecNear(out[0].point_b, W(edge), kTol);
  }
  // Corner (-x, +y, +z).
  {
    const Vec3 dl = Vec3(-1, 2, 2) / 3.0;
    const Vec3 corner(-0.1, 0.2, 0.3);
    const Vec3 c = W(corner + (r + 0.004) * dl);
    ASSERT_EQ(run(sphere(r), at(c), box(h), box_pose, 0.01, out), 1);
    EXPECT_NEAR(out[0].gap, 0.004, kTol);
    expectVecNear(out[0].normal, D(dl), kTol);
    expectVecNear(out[0].point_b, W(corner), kTol);
  }
  // Centre inside, nearest face is -x (depth 0.03): gap = -0.03 - r.
  {
    const Vec3 c = W(Vec3(-0.07, 0.05, 0.1));
    ASSERT_EQ(run(sphere(r), at(c), box(h), box_pose, 0.0, out), 1);
    EXPECT_NEAR(out[0].gap, -0.03 - r, kTol);
    expectVecNear(out[0].normal, D(-Vec3::UnitX()), kTol);
    expectVecNear(out[0].point_b, W(Vec3(-0.1, 0.05, 0.1)), kTol);
    expectVecNear(out[0].point_a, c - r * D(-Vec3::UnitX()), kTol);
  }
  // Centre exactly at the centre of a cube: finite, depth = half extent.
  ASSERT_EQ(run(sphere(r), at(pb), box(Vec3(0.1, 0.1, 0.1)), box_pose, 0.0, out), 1);
  EXPECT_NEAR(out[0].gap, -0.1 - r, kTol);
  // Far away: nothing.
  EXPECT_EQ(run(sphere(r), at(W(Vec3(0, 0, 0.5))), box(h), box_pose, 0.1, out), 0);
}

TEST(ContactGeometry, SphereCapsule) {
  const Quat qc = rotAbout(Vec3(1, 1, 0), 0.6);
  const Vec3 pc(0, 0.1, 0.2);
  const Vec3 u = qc * Vec3::UnitZ(), t = anyOrthogonal(u);
  const double rs = 0.02, rc = 0.03, len = 0.4;
  ContactPoint out[kMaxPointsPerPair];
  // Beside the cylindrical part.
  {
    const Vec3 c = pc + 0.1 * u + (rs + rc + 0.005) * t;
    ASSERT_EQ(run(sphere(rs), at(c), capsule(rc, len), at(pc, qc), 0.01, out), 1);
    EXPECT_NEAR(out[0].gap, 0.005, kTol);
    expectVecNear(out[0].normal, t, kTol);
    expectVecNear(out[0].point_b, pc + 0.1 * u + rc * t, kTol);
  }
  // Beyond the -z end cap, along a slanted direction.
  {
    const Vec3 dir = (-u + 0.5 * t).normalized();
    const Vec3 end = pc - 0.5 * len * u;
    const Vec3 c = end + (rs + rc - 0.01) * dir;
    ASSERT_EQ(run(sphere(rs), at(c), capsule(rc, len), at(pc, qc), 0.0, out), 1);
    EXPECT_NEAR(out[0].gap, -0.01, kTol);
    expectVecNear(out[0].normal, dir, kTol);
    expectVecNear(out[0].point_b, end + rc * dir, kTol);
  }
  // Centre on the axis: finite normal orthogonal to the axis.
  ASSERT_EQ(run(sphere(rs), at(pc + 0.05 * u), capsule(rc, len), at(pc, qc), 0.0, out), 1);
  EXPECT_NEAR(out[0].gap, -rs - rc, kTol);
  EXPECT_NEAR(out[0].normal.dot(u), 0.0, kTol);
}

TEST(ContactGeometry, CapsulePlaneFlatAndTilted) {
  const double r = 0.01, len = 0.2;
  ContactPoint out[kMaxPointsPerPair];
  // Lying flat along x on z = 0: two points, gap 0, features 0 (-L/2) and 1 (+L/2).
  const Quat lying = rotAbout(Vec3::UnitY(), kPi / 2);  // capsule z -> world x
  ASSERT_EQ(run(capsule(r, len), at(Vec3(0, 0, r), lying), plane(), Pose{}, 1e-6, out), 2);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(out[i].gap, 0.0, kTol);
    expectVecNear(out[i].normal, Vec3::UnitZ(), kTol);
  }
  const ContactPoint* f0 = byFeature(out, 2, 0);
  const ContactPoint* f1 = byFeature(out, 2, 1);
  ASSERT_TRUE(f0 && f1);
  expectVecNear(f0->point_a, Vec3(-0.1, 0, 0), kTol);  // lying maps capsule -z to world -x
  expectVecNear(f1->point_a, Vec3(0.1, 0, 0), kTol);
  // Tilted by 30 deg: end heights zc -/+ (L/2) sin30.
  const Quat tilt = rotAbout(Vec3::UnitY(), kPi / 2 - kPi / 6);
  const double zc = 0.06;
  ASSERT_EQ(run(capsule(r, len), at(Vec3(0, 0, zc), tilt), plane(), Pose{}, 1.0, out), 2);
  const double lo = zc - 0.1 * std::sin(kPi / 6) - r, hi = zc + 0.1 * std::sin(kPi / 6) - r;
  ASSERT_TRUE(byFeature(out, 2, 0) && byFeature(out, 2, 1));
  // Capsule +z points to world +x and up: feature 1 is the high end.
  EXPECT_NEAR(byFeature(out, 2, 0)->gap, lo, kTol);
  EXPECT_NEAR(byFeature(out, 2, 1)->gap, hi, kTol);
  // Margin between the two gaps keeps only the low end.
  ASSERT_EQ(run(capsule(r, len), at(Vec3(0, 0, zc), tilt), plane(), Pose{}, 0.5 * (lo + hi), out), 1);
  EXPECT_EQ(out[0].feature, 0);
}

TEST(ContactGeometry, BoxPlaneRestingFlatGivesFourPoints) {
  const Vec3 h(0.1, 0.2, 0.05);
  ContactPoint out[kMaxPointsPerPair];
  const int n = run(box(h), at(Vec3(0.3, -0.4, 0.05)), plane(), Pose{}, 1e-3, out);
  ASSERT_EQ(n, 4);
  int seen = 0;
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(out[i].gap, 0.0);
    EXPECT_GE(out[i].feature, 0);
    EXPECT_LE(out[i].feature, 3);  // the -z corners: index bit 2 clear
    seen |= 1 << out[i].feature;
    expectVecNear(out[i].normal, Vec3::UnitZ(), 0);
  }
  EXPECT_EQ(seen, 0xF);
  // Rotated plane and box together: still 4 points at gap ~0.
  const Quat q = rotAbout(Vec3(0.2, 1, -0.3), 0.9);
  const Pose pp = at(Vec3(1, 2, 3), q);
  const Pose pbx = pp * at(Vec3(0.3, -0.4, 0.05), rotAbout(Vec3::UnitZ(), 0.4));
  ASSERT_EQ(run(box(h), pbx, plane(), pp, 1e-3, out), 4);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(out[i].gap, 0.0, kTol);
  // Lifted above the margin: nothing.
  EXPECT_EQ(run(box(h), at(Vec3(0, 0, 0.0511)), plane(), Pose{}, 1e-3, out), 0);
}

TEST(ContactGeometry, BoxPlaneTiltedDeepestCorners) {
  const Vec3 h(0.1, 0.2, 0.05);
  const double th = 0.1;
  ContactPoint out[kMaxPointsPerPair];
  // Rotation about y by +th lowers the +x corners: z' = -x sin th + z cos th.
  const Quat q = rotAbout(Vec3::UnitY(), th);
  const double zc = h.x() * std::sin(th) + h.z() * std::cos(th) - 0.002;  // 2 mm deep
  const int n = run(box(h), at(Vec3(0, 0, zc), q), plane(), Pose{}, 0.01, out);
  ASSERT_EQ(n, 2);  // -x bottom corners are 2 hx sin th - 2mm = 18 mm up: filtered
  for (int i = 0; i < n; ++i) {
    EXPECT_TRUE(out[i].feature == 1 || out[i].feature == 3) << out[i].feature;
    EXPECT_NEAR(out[i].gap, -0.002, kTol);
  }
  // Random orientations: the 4 deepest of the brute-force corner list.
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const Pose pb = at(Vec3(uni(rng, -1, 1), uni(rng, -1, 1), uni(rng, -1, 1)), randQuat(rng));
    const Pose pa = pb * at(Vec3(uni(rng, -1, 1), uni(rng, -1, 1), uni(rng, -0.1, 0.2)), randQuat(rng));
    const double margin = uni(rng, -0.1, 0.3);
    std::vector<std::pair<double, int>> all;
    for (int i = 0; i < 8; ++i) {
      const Vec3 l((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z());
      const double g = (pb.q.conjugate() * (pa.apply(l) - pb.p)).z();
      if (g < margin) all.push_back({g, i});
    }
    std::sort(all.begin(), all.end());
    const int want = std::min<int>(4, all.size());
    const int got = run(box(h), pa, plane(), pb, margin, out);
    ASSERT_EQ(got, want);
    for (int j = 0; j < want; ++j) {
      const ContactPoint* cp = byFeature(out, got, all[j].second);
      ASSERT_TRUE(cp) << "corner " << all[j].second;
      EXPECT_NEAR(cp->gap, all[j].first, kTol);
    }
  }
}

// Distance between two segments by brute force: the distance from A(s) to
// segment B is convex in s, so golden section over s finds the minimum.
static double segmentDistance(const Vec3& pa, const Vec3& u, double ha, const Vec3& pb,
                              const Vec3& v, double hb) {
  auto dist = [&](double s) {
    const Vec3 x = pa + s * u;
    const double t = std::clamp(v.dot(x - pb), -hb, hb);
    return (x - pb - t * v).norm();
  };
  double lo = -ha, hi = ha;
  const double g = 0.3819660112501051;
  for (int it = 0; it < 120; ++it) {
    const double x1 = lo + g * (hi - lo), x2 = hi - g * (hi - lo);
    if (dist(x1) <= dist(x2)) hi = x2; else lo = x1;
  }
  return std::min({dist(0.5 * (lo + hi)), dist(-ha), dist(ha)});
}

TEST(ContactGeometry, CapsuleCapsuleAgainstBruteForce) {
  std::mt19937_64 rng(11);
  ContactPoint out[kMaxPointsPerPair];
  for (int trial = 0; trial < 500; ++trial) {
    const Shape a = capsule(uni(rng, 0.01, 0.05), uni(rng, 0.0, 0.4));
    const Shape b = capsule(uni(rng, 0.01, 0.05), uni(rng, 0.0, 0.4));
    const Pose pa = at(Vec3(uni(rng, -0.2, 0.2), uni(rng, -0.2, 0.2), uni(rng, -0.2, 0.2)), randQuat(rng));
    const Pose pb = at(Vec3(uni(rng, -0.2, 0.2), uni(rng, -0.2, 0.2), uni(rng, -0.2, 0.2)), randQuat(rng));
    const int n = run(a, pa, b, pb, 1.0, out);
    ASSERT_EQ(n, 1);
    const double d = segmentDistance(pa.p, pa.rotate(Vec3::UnitZ()), 0.5 * a.length, pb.p,
                                     pb.rotate(Vec3::UnitZ()), 0.5 * b.length);
    EXPECT_NEAR(out[0].gap, d - a.radius - b.radius, 1e-12);
  }
}

TEST(ContactGeometry, CapsuleCapsuleCrossedAndParallel) {
  ContactPoint out[kMaxPointsPerPair];
  const double r = 0.01;
  // Perpendicular, crossing above each other at height 0.025.
  const Pose pa = at(Vec3(0, 0, 0.025), rotAbout(Vec3::UnitY(), kPi / 2));  // along x
  const Pose pb = at(Vec3::Zero(), rotAbout(Vec3::UnitX(), kPi / 2));       // along y
  ASSERT_EQ(run(capsule(r, 0.2), pa, capsule(r, 0.2), pb, 0.1, out), 1);
  EXPECT_NEAR(out[0].gap, 0.005, kTol);
  expectVecNear(out[0].normal, Vec3::UnitZ(), kTol);
  expectVecNear(out[0].point_a, Vec3(0, 0, 0.015), kTol);
  expectVecNear(out[0].point_b, Vec3(0, 0, 0.01), kTol);
  // Parallel along x, B 0.02 below A, A spans [-0.1, 0.1], B spans [0.05, 0.35]:
  // overlap [0.05, 0.1] -> two points, gap 0.
  const Quat alongX = rotAbout(Vec3::UnitY(), kPi / 2);
  const Pose qa = at(Vec3(0, 0, 0.02), alongX);
  const Pose qb = at(Vec3(0.2, 0, 0), alongX);
  ASSERT_EQ(run(capsule(r, 0.2), qa, capsule(r, 0.3), qb, 1e-6, out), 2);
  std::vector<double> xs;
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(out[i].gap, 0.0, kTol);
    expectVecNear(out[i].normal, Vec3::UnitZ(), kTol);
    EXPECT_NEAR(out[i].point_a.z(), 0.01, kTol);
    EXPECT_NEAR(out[i].point_b.z(), 0.01, kTol);
    EXPECT_NEAR(out[i].point_a.x(), out[i].point_b.x(), kTol);
    xs.push_back(out[i].point_a.x());
  }
  std::sort(xs.begin(), xs.end());
  EXPECT_NEAR(xs[0], 0.05, kTol);
  EXPECT_NEAR(xs[1], 0.1, kTol);
  EXPECT_NE(out[0].feature, out[1].feature);
  // B reversed (antiparallel): the same two points.
  const Pose qbr = at(Vec3(0.2, 0, 0), rotAbout(Vec3::UnitY(), -kPi / 2));
  ASSERT_EQ(run(capsule(r, 0.2), qa, capsule(r, 0.3), qbr, 1e-6, out), 2);
  xs = {out[0].point_a.x(), out[1].point_a.x()};
  std::sort(xs.begin(), xs.end());
  EXPECT_NEAR(xs[0], 0.05, kTol);
  EXPECT_NEAR(xs[1], 0.1, kTol);
  // Parallel, disjoint along the axis: one point between the facing ends.
  const Pose qfar = at(Vec3(0.5, 0, 0), alongX);
  ASSERT_EQ(run(capsule(r, 0.2), qa, capsule(r, 0.3), qfar, 1.0, out), 1);
  const double dx = 0.35 - 0.1;
  EXPECT_NEAR(out[0].gap, std::hypot(dx, 0.02) - 2 * r, kTol);
  // Coaxial overlapping: finite, normal orthogonal to the axis.
  const int n = run(capsule(r, 0.2), at(Vec3::Zero(), alongX), capsule(r, 0.3), qb, 0.0, out);
  ASSERT_EQ(n, 2);
  for (int i = 0; i < n; ++i) {
    EXPECT_NEAR(out[i].gap, -2 * r, kTol);
    EXPECT_NEAR(out[i].normal.x(), 0.0, kTol);
  }
  // Axes intersecting (not parallel): finite, gap = -(ra + rb).
  ASSERT_EQ(run(capsule(r, 0.2), at(Vec3::Zero(), alongX), capsule(r, 0.2), pb, 0.0, out), 1);
  EXPECT_NEAR(out[0].gap, -2 * r, kTol);
}

// Capsule vs box: a pin lying along a box face (axes parallel, as in a planar
// mechanism), a pin longer than the face (ends clamped to the face), a pin end
// over an edge (rounded normal), and a tilted pin (ends as balls, brute force).
TEST(ContactGeometry, CapsuleBox) {
  ContactPoint out[kMaxPointsPerPair];
  const Shape bx = box(Vec3(0.02, 0.01, 0.03));  // face x = +0.02, z in [-0.03, 0.03]
  const double r = 0.005, g = 0.001;
  const Quat along_z = Quat::Identity();
  // Parallel to the +x face, inside its z extent: two points at the ends.
  ASSERT_EQ(run(capsule(r, 0.04), at(Vec3(0.02 + r + g, 0.003, 0.0), along_z), bx, Pose{}, 0.01, out), 2);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(out[i].gap, g, kTol);
    expectVecNear(out[i].normal, Vec3::UnitX(), kTol);
    EXPECT_NEAR(out[i].point_b.x(), 0.02, kTol);
    EXPECT_NEAR(std::abs(out[i].point_b.z()), 0.02, kTol);
  }
  EXPECT_NE(out[0].feature, out[1].feature);
  // Longer than the face: the ends are clamped to the box's z extent, the gap
  // is still the face distance (the ends themselves would see the edges).
  ASSERT_EQ(run(capsule(r, 0.2), at(Vec3(0.02 + r + g, 0.0, 0.01), along_z), bx, Pose{}, 0.01, out), 2);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(out[i].gap, g, kTol);
    expectVecNear(out[i].normal, Vec3::UnitX(), kTol);
    EXPECT_NEAR(std::abs(out[i].point_b.z()), 0.03, kTol);
  }
  // Over the edge x = 0.02, y = 0.01 (diagonally outside): rounded normal.
  const Vec3 c(0.02 + 0.003, 0.01 + 0.004, 0.0);
  ASSERT_EQ(run(capsule(r, 0.02), at(c, along_z), bx, Pose{}, 0.01, out), 2);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(out[i].gap, 0.005 - r, kTol);
    expectVecNear(out[i].normal, Vec3(0.6, 0.8, 0), 1e-12);
  }
  // Tilted and rotated: each point is the ball-box distance of a segment end,
  // checked by brute force over the box surface (samples of each face).
  std::mt19937_64 rng(21);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose pb = at(Vec3(uni(rng, -0.01, 0.01), 0, 0), randQuat(rng));
    const Pose pa = at(pb.apply(Vec3(0.045, uni(rng, -0.01, 0.01), 0)), randQuat(rng));
    const Shape cap = capsule(r, 0.03);
    const int n = run(cap, pa, bx, pb, 1.0, out);
    ASSERT_EQ(n, 2);
    for (int i = 0; i < n; ++i) {
      const Vec3 end = pa.p + (out[i].feature == 0 ? -0.015 : 0.015) * pa.rotate(Vec3::UnitZ());
      const Vec3 l = pb.q.conjugate() * (end - pb.p);
      double best = 1e9;
      const int S = 60;
      for (int ax = 0; ax < 3; ++ax)
        for (int sg = -1; sg <= 1; sg += 2)
          for (int i1 = 0; i1 <= S; ++i1)
            for (int i2 = 0; i2 <= S; ++i2) {
              Vec3 q;
              q[ax] = sg * bx.half_extents[ax];
              const int a1 = (ax + 1) % 3, a2 = (ax + 2) % 3;
              q[a1] = bx.half_extents[a1] * (2.0 * i1 / S - 1);
              q[a2] = bx.half_extents[a2] * (2.0 * i2 / S - 1);
              best = std::min(best, (l - q).norm());
            }
      if (std::abs(pa.rotate(Vec3::UnitZ()).dot(pb.rotate(Vec3::UnitZ()))) < 0.999 &&
          std::abs(pa.rotate(Vec3::UnitZ()).dot(pb.rotate(Vec3::UnitX()))) < 0.999 &&
          std::abs(pa.rotate(Vec3::UnitZ()).dot(pb.rotate(Vec3::UnitY()))) < 0.999) {
        // Grid spacing 1/30 of a half extent bounds the brute-force error.
        EXPECT_NEAR(out[i].gap, best - r, 0.03 * 0.02 / 30 + 1e-12);
        EXPECT_LE(out[i].gap, best - r + 1e-12);
      }
    }
  }
}

TEST(ContactGeometry, CylinderPlane) {
  const double r = 0.03, len = 0.1;
  ContactPoint out[kMaxPointsPerPair];
  // Lying on its side along x: the bottom rim point of each end disc, gap 0.
  const Quat lying = rotAbout(Vec3::UnitY(), kPi / 2);
  ASSERT_EQ(run(cylinder(r, len), at(Vec3(0, 0, r), lying), plane(), Pose{}, 1e-6, out), 2);
  for (int k = 0; k < 2; ++k) {
    const ContactPoint* cp = byFeature(out, 2, k);
    ASSERT_TRUE(cp);
    EXPECT_NEAR(cp->gap, 0.0, kTol);
    expectVecNear(cp->point_a, Vec3(k == 0 ? -0.05 : 0.05, 0, 0), kTol);
  }
  // Tilted: axis at angle th from the vertical; lowest rim point of the lower
  // disc at zc - (L/2) cos th - r sin th, of the upper disc at zc + (L/2) cos th - r sin th.
  const double th = 0.3, zc = 0.2;
  const Quat q = rotAbout(Vec3::UnitY(), th);
  ASSERT_EQ(run(cylinder(r, len), at(Vec3(0, 0, zc), q), plane(), Pose{}, 1.0, out), 2);
  EXPECT_NEAR(byFeature(out, 2, 0)->gap, zc - 0.05 * std::cos(th) - r * std::sin(th), kTol);
  EXPECT_NEAR(byFeature(out, 2, 1)->gap, zc + 0.05 * std::cos(th) - r * std::sin(th), kTol);
  // Standing on its end disc: three rim points (0/120/240 deg), gap 0; the top
  // disc adds three more with a large margin.
  ASSERT_EQ(run(cylinder(r, len), at(Vec3(0, 0, 0.05)), plane(), Pose{}, 1e-6, out), 3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(out[i].gap, 0.0, kTol);
    EXPECT_EQ(out[i].feature, i);
    EXPECT_NEAR(out[i].point_a.head<2>().norm(), r, kTol);
  }
  EXPECT_NEAR(out[0].point_a.x(), r, kTol);  // 0 deg = shape frame x
  ASSERT_EQ(run(cylinder(r, len), at(Vec3(0, 0, 0.05)), plane(), Pose{}, 1.0, out), 6);
  for (int i = 3; i < 6; ++i) {
    EXPECT_EQ(out[i].feature, i);
    EXPECT_NEAR(out[i].gap, len, kTol);
  }
  // Upside down (axis = -normal): the same, no NaN.
  ASSERT_EQ(run(cylinder(r, len), at(Vec3(0, 0, 0.05), rotAbout(Vec3::UnitX(), kPi)), plane(),
                Pose{}, 1e-6, out), 3);
}

// Random configurations for every supported pair, near contact.
struct PairCase {
  Shape a, b;
  Pose pa, pb;
};

static std::vector<PairCase> randomCases(std::mt19937_64& rng, int per_pair) {
  std::vector<PairCase> cases;
  auto pose = [&](double s) {
    return at(Vec3(uni(rng, -s, s), uni(rng, -s, s), uni(rng, -s, s)), randQuat(rng));
  };
  for (int i = 0; i < per_pair; ++i) {
    const Pose p0 = pose(0.5);
    const Vec3 m = p0.rotate(Vec3::UnitZ());
    auto abovePlane = [&](double h) {
      return at(p0.p + anyOrthogonal(m) * uni(rng, -0.3, 0.3) + h * m, randQuat(rng));
    };
    cases.push_back({sphere(0.05), plane(), abovePlane(uni(rng, 0.0, 0.1)), p0});
    cases.push_back({capsule(0.03, 0.2), plane(), abovePlane(uni(rng, 0.0, 0.15)), p0});
    cases.push_back({box(Vec3(0.05, 0.1, 0.07)), plane(), abovePlane(uni(rng, 0.0, 0.15)), p0});
    cases.push_back({cylinder(0.04, 0.12), plane(), abovePlane(uni(rng, 0.0, 0.12)), p0});
    const Pose q = pose(0.1);
    cases.push_back({sphere(0.05), sphere(0.07), pose(0.1), q});
    cases.push_back({sphere(0.05), box(Vec3(0.05, 0.1, 0.07)), pose(0.15), q});
    cases.push_back({sphere(0.05), capsule(0.03, 0.2), pose(0.15), q});
    cases.push_back({capsule(0.02, 0.15), capsule(0.03, 0.2), pose(0.1), q});
    cases.push_back({capsule(0.02, 0.15), box(Vec3(0.05, 0.1, 0.07)), pose(0.15), q});
  }
  // Ring pairs, drawn after the others (whose draws stay as they were): a
  // half-ring on a plane, a ring over the middle of a face, a ring beside a long
  // cylinder (its deepest point always on the patch).
  for (int i = 0; i < per_pair; ++i) {
    const Pose p0 = pose(0.5);
    const Vec3 m = p0.rotate(Vec3::UnitZ());
    auto abovePlane = [&](double h) {
      return at(p0.p + anyOrthogonal(m) * uni(rng, -0.3, 0.3) + h * m, randQuat(rng));
    };
    const Pose q = pose(0.1);
    cases.push_back({ring(0.04, uni(rng, -kPi, kPi), kPi), plane(), abovePlane(uni(rng, -0.03, 0.03)), p0});
    cases.push_back({ring(0.04), face(0.8, 0.8), abovePlane(uni(rng, 0.0, 0.05)), p0});
    {
      const Vec3 u = q.rotate(Vec3::UnitZ()), side = anyOrthogonal(u);
      const Vec3 dir = rotAbout(u, uni(rng, -kPi, kPi)) * side;
      const Vec3 c = q.p + (0.05 + uni(rng, 0.02, 0.07)) * dir + uni(rng, -0.2, 0.2) * u;
      cases.push_back({ring(0.03), cylinder(0.05, 2.0), at(c, randQuat(rng)), q});
    }
  }
  return cases;
}

TEST(ContactGeometry, SwappingFlipsNormalAndSwapsPoints) {
  std::mt19937_64 rng(3);
  ContactPoint ab[kMaxPointsPerPair], ba[kMaxPointsPerPair];
  int compared = 0;
  for (const PairCase& c : randomCases(rng, 50)) {
    const int n = run(c.a, c.pa, c.b, c.pb, 0.05, ab);
    const int m = run(c.b, c.pb, c.a, c.pa, 0.05, ba);
    ASSERT_EQ(n, m);
    for (int i = 0; i < n; ++i) {
      const ContactPoint* s = byFeature(ba, m, ab[i].feature);
      ASSERT_TRUE(s);
      EXPECT_NEAR(s->gap, ab[i].gap, 1e-14);
      expectVecNear(s->normal, -ab[i].normal, 1e-12);
      expectVecNear(s->point_a, ab[i].point_b, 1e-12);
      expectVecNear(s->point_b, ab[i].point_a, 1e-12);
      ++compared;
    }
  }
  EXPECT_GT(compared, 200);
}

TEST(ContactGeometry, MarginFiltersEveryPair) {
  std::mt19937_64 rng(5);
  ContactPoint all[kMaxPointsPerPair], some[kMaxPointsPerPair];
  const std::vector<PairCase> cases = randomCases(rng, 30);
  int filtered = 0;
  for (const PairCase& c : cases) {
    const int n = run(c.a, c.pa, c.b, c.pb, 10.0, all);
    if (n == 0) continue;
    ++filtered;
    // A margin between the gaps keeps exactly the points below it.
    std::vector<double> g;
    for (int i = 0; i < n; ++i) g.push_back(all[i].gap);
    std::sort(g.begin(), g.end());
    const double cut = g.size() > 1 && g[1] > g[0] + 1e-9 ? 0.5 * (g[0] + g[1]) : g[0] - 1e-9;
    const int m = run(c.a, c.pa, c.b, c.pb, cut, some);
    int want = 0;
    for (int i = 0; i < n; ++i) want += all[i].gap < cut;
    if (c.a.type == ShapeType::Box) want = std::min(want, 4);
    EXPECT_EQ(m, want);
    for (int i = 0; i < m; ++i) EXPECT_LT(some[i].gap, cut);
  }
  // Every case has points within a 10 m margin: the loop above checked each.
  EXPECT_EQ(filtered, static_cast<int>(cases.size()));
}

// Second-order remainder allowed for the first-order prediction of the gap
// change under a rigid displacement (dt, dw) about `origin`, for a contact whose
// two points are within `lever` of the origin: those points move by
// s = |dt| + |dw| lever, the gap has curvature <= curv (1/m) along that motion,
// the rotation itself is second order beyond its linear part by
// lever |dw|^2 / 2, and a rotating normal couples with the translation (|dt||dw|).
static double secondOrder(double curv, const Vec3& dt, const Vec3& dw, const ContactPoint& cp,
                          const Vec3& origin) {
  const double lever = std::max((cp.point_a - origin).norm(), (cp.point_b - origin).norm());
  const double s = dt.norm() + dw.norm() * lever;
  return curv * s * s + lever * dw.squaredNorm() + dt.norm() * dw.norm();
}

// Radius swept around the core (point or segment) of round shapes.
static double roundRadius(const Shape& s) {
  return (s.type == ShapeType::Sphere || s.type == ShapeType::Capsule) ? s.radius : 0.0;
}

// First-order consistency of (normal, points) with the gap: for small rigid
// displacements (dt, dw) of body A about its origin oA,
//   gap' - gap = N.dt + ((point_a - oA) x N).dw + O(h^2),
// and for body B the same with the opposite sign using point_b. The shapes sit
// in their bodies at random offsets (lever arms up to ~0.3 m).
TEST(ContactGeometry, NormalAndPointsMatchFiniteDifferences) {
  std::mt19937_64 rng(9);
  const double h = 1e-7;  // |dt|, and |dw| * 0.1 m
  double worst = 0;
  int checked = 0;
  int per_pair[7][7] = {};
  const std::vector<PairCase> cases = randomCases(rng, 25);
  for (const PairCase& c : cases) {
    ContactPoint base[kMaxPointsPerPair], moved[kMaxPointsPerPair];
    const int n = run(c.a, c.pa, c.b, c.pb, 0.05, base);
    // Skip configurations where a feature is at a switch (parallel pairs, ties).
    const Pose bodyA = c.pa * at(Vec3(uni(rng, -0.2, 0.2), uni(rng, -0.2, 0.2), uni(rng, -0.2, 0.2)), randQuat(rng));
    const Pose bodyB = c.pb * at(Vec3(uni(rng, -0.2, 0.2), uni(rng, -0.2, 0.2), uni(rng, -0.2, 0.2)), randQuat(rng));
    const Pose shapeInA = bodyA.inverse() * c.pa, shapeInB = bodyB.inverse() * c.pb;
    for (int side = 0; side < 2; ++side) {
      for (int rep = 0; rep < 3; ++rep) {
        const Vec3 dt = h * randUnit(rng), dw = (h / 0.1) * randUnit(rng);
        const Pose& body = side == 0 ? bodyA : bodyB;
        const Pose disp{body.p + dt, (expMap(dw) * body.q).normalized()};
        const Pose pa2 = side == 0 ? disp * shapeInA : c.pa;
        const Pose pb2 = side == 1 ? disp * shapeInB : c.pb;
        const int m = collide(c.a, pa2, c.b, pb2, 0.05, moved);
        for (int i = 0; i < n; ++i) {
          const ContactPoint* mv = byFeature(moved, m, base[i].feature);
          if (!mv) continue;  // left the margin
          const Vec3& pt = side == 0 ? base[i].point_a : base[i].point_b;
          const double pred = (side == 0 ? 1 : -1) *
                              (base[i].normal.dot(dt) + (pt - body.p).cross(base[i].normal).dot(dw));
          const double err = std::abs(mv->gap - base[i].gap - pred);
          // The gap's curvature is at most 1/D (D = distance of the cores:
          // segment, point, box; none when they overlap, the gap is then
          // piecewise linear). Factor 2 spare, 1e-15 m round-off floor.
          const double D = base[i].gap + roundRadius(c.a) + roundRadius(c.b);
          const double bound = secondOrder(D > 0 ? 1.0 / D : 0.0, dt, dw, base[i], body.p);
          EXPECT_LT(err, 2 * bound + 1e-15) << "types " << int(c.a.type) << "," << int(c.b.type)
                                            << " feature " << base[i].feature;
          worst = std::max(worst, err / bound);
          ++checked;
          ++per_pair[int(c.a.type)][int(c.b.type)];
        }
      }
    }
  }
  EXPECT_GT(checked, 500);
  for (const PairCase& c : cases)  // every pair type was exercised
    EXPECT_GT(per_pair[int(c.a.type)][int(c.b.type)], 20) << int(c.a.type) << "," << int(c.b.type);
  std::printf("collide FD: %d checks, max |error| / second-order bound = %.3g (|dt| = %.0e m)\n",
              checked, worst, h);
}

// The same check must fail when the lever arm is wrong: it has teeth.
TEST(ContactGeometry, FiniteDifferenceCheckDetectsWrongLeverArm) {
  ContactPoint base[kMaxPointsPerPair], moved[kMaxPointsPerPair];
  const Pose pa = at(Vec3(0.05, 0.02, 0.049), rotAbout(Vec3(1, 0, 0), 0.3));
  ASSERT_EQ(run(sphere(0.05), pa, plane(), Pose{}, 0.01, base), 1);
  const double h = 1e-7;
  const Vec3 dw = (h / 0.1) * Vec3(0, 1, 0);
  const Vec3 body(0.25, 0, 0.049);  // body origin off the sphere centre
  const Pose disp{body, Quat::Identity()};
  const Pose moved_body{body, expMap(dw)};
  const Pose shape_in_body = disp.inverse() * pa;
  ASSERT_EQ(collide(sphere(0.05), moved_body * shape_in_body, plane(), Pose{}, 0.01, moved), 1);
  const Vec3 N = base[0].normal;
  const double right = (base[0].point_a - body).cross(N).dot(dw);
  const double wrong = (pa.p - body).cross(N).dot(dw) + (Vec3(0.001, 0, 0)).cross(N).dot(dw);
  EXPECT_LT(std::abs(moved[0].gap - base[0].gap - right), 100 * h * h);
  EXPECT_GT(std::abs(moved[0].gap - base[0].gap - wrong), 100 * h * h);
}

TEST(ContactGeometry, AllocatesNothing) {
  std::mt19937_64 rng(13);
  const std::vector<PairCase> cases = randomCases(rng, 5);
  ContactPoint out[kMaxPointsPerPair];
  int total = 0;
  const long before = nscd_test::allocationCount();
  for (const PairCase& c : cases) {
    total += collide(c.a, c.pa, c.b, c.pb, 1.0, out);
    total += collide(c.b, c.pb, c.a, c.pa, 1.0, out);
  }
  EXPECT_EQ(nscd_test::allocationCount(), before);
  std::vector<int> v(10);  // the counter itself works
  EXPECT_GT(nscd_test::allocationCount(), before);
  EXPECT_GT(total, 0);
}

// ------------------------------------------------------------------ ring pairs
// Brute force: the ring (or arc) sampled at kSamples points, ends included.
// For a gap that is a smooth function g(t) of the ring angle with |g''| <= G,
// the lowest sample lies at most G (dt/2)^2 / 2 above the true minimum
// (dt = span / (kSamples - 1)); each test states its G.

namespace {

constexpr int kSamples = 20000;

struct RingFrame {
  Vec3 c, e1, e2, n;
  explicit RingFrame(const Pose& p)
      : c(p.p), e1(p.rotate(Vec3::UnitX())), e2(p.rotate(Vec3::UnitY())), n(p.rotate(Vec3::UnitZ())) {}
  Vec3 at(double r, double t) const { return c + r * (std::cos(t) * e1 + std::sin(t) * e2); }
};

// The point lies on the ring (radius r, frame f) within tol, at an angle of its arc.
void expectOnArc(const Vec3& p, const Shape& s, const RingFrame& f, double tol) {
  const Vec3 d = p - f.c;
  EXPECT_NEAR(d.dot(f.n), 0.0, tol);
  EXPECT_NEAR(d.norm(), s.radius, tol);
  const double angle = std::atan2(d.dot(f.e2), d.dot(f.e1));
  double rel = std::fmod(angle - s.start, 2 * kPi);
  if (rel < 0) rel += 2 * kPi;
  EXPECT_TRUE(rel <= s.span + 1e-9 || rel >= 2 * kPi - 1e-9)
      << "angle " << angle << " outside start " << s.start << " span " << s.span;
}

// Lowest sample of g over the arc of s; writes its angle.
template <class G>
double bruteMin(const Shape& s, G g, double* argmin = nullptr) {
  double best = 1e300, at = s.start;
  for (int i = 0; i < kSamples; ++i) {
    const double t = s.start + s.span * i / (kSamples - 1);
    const double v = g(t);
    if (v < best) {
      best = v;
      at = t;
    }
  }
  if (argmin) *argmin = at;
  return best;
}

double minGap(const ContactPoint* pts, int n) {
  double g = 1e300;
  for (int i = 0; i < n; ++i) g = std::min(g, pts[i].gap);
  return g;
}

// A random arc: a full ring one time in three, else a random start and span.
Shape randomRing(std::mt19937_64& rng, double r) {
  if (uni(rng, 0, 1) < 1.0 / 3) return ring(r);
  return ring(r, uni(rng, -kPi, kPi), uni(rng, 0.05, 2 * kPi));
}

}  // namespace

// Ring against a plane at random poses (mm-scale rings): the lowest emitted gap
// equals the brute-force minimum of the height over the arc. The height is
// h0 + r rho cos(t - t0), so G = r and the sampling error is below
// r dt^2 / 8 < 1e-10 m for r <= 6 mm; the routine may only be lower than the
// samples (by round-off, 1e-15 m).
TEST(ContactGeometry, RingPlaneAgainstBruteForce) {
  std::mt19937_64 rng(101);
  ContactPoint out[kMaxPointsPerPair];
  int ends = 0, interior = 0;
  for (int it = 0; it < 400; ++it) {
    const double r = uni(rng, 0.3e-3, 6e-3);
    const Shape s = randomRing(rng, r);
    const Pose pb = at(Vec3(uni(rng, -0.02, 0.02), uni(rng, -0.02, 0.02), uni(rng, -0.02, 0.02)), randQuat(rng));
    const Vec3 m = pb.rotate(Vec3::UnitZ());
    const Pose pa = at(pb.p + uni(rng, -r, r) * m + uni(rng, -0.01, 0.01) * anyOrthogonal(m), randQuat(rng));
    const RingFrame f(pa);
    const double brute = bruteMin(s, [&](double t) { return m.dot(f.at(r, t) - pb.p); });
    const int n = run(s, pa, plane(), pb, 1.0, out);
    ASSERT_GE(n, 1);
    const double dt = s.span / (kSamples - 1);
    const double tol = r * dt * dt / 8 + 1e-15;
    EXPECT_NEAR(minGap(out, n), brute, tol) << "it " << it;
    EXPECT_LE(minGap(out, n), brute + 1e-15);
    for (int i = 0; i < n; ++i) {
      expectOnArc(out[i].point_a, s, f, 1e-15);
      EXPECT_NEAR(m.dot(out[i].point_b - pb.p), 0.0, 1e-15);
      expectVecNear(out[i].normal, m, 1e-15);
      (out[i].feature == 0 ? interior : ends) += 1;
    }
  }
  EXPECT_GT(interior, 100);
  EXPECT_GT(ends, 100);
}

// Arc limits on a vertical ring (frame y = world z) over the plane z = 0: its
// deepest point is at t = -pi/2.
TEST(ContactGeometry, RingPlaneArcSpanLimits) {
  const double r = 0.5e-3, h = 0.7e-3;
  const Pose pa = at(Vec3(1e-3, 2e-3, h), rotAbout(Vec3::UnitX(), kPi / 2));
  ContactPoint out[kMaxPointsPerPair];
  // Full ring and the lower half: the deepest point, feature 0.
  for (const Shape& s : {ring(r), ring(r, kPi, kPi)}) {
    ASSERT_EQ(run(s, pa, plane(), Pose{}, 1.0, out), 1);
    EXPECT_EQ(out[0].feature, 0);
    EXPECT_NEAR(out[0].gap, h - r, kTol);
    expectVecNear(out[0].point_a, Vec3(1e-3, 2e-3, h - r), kTol);
  }
  // Upper half: the deepest point is outside, both ends (features 1, 2) at height h.
  ASSERT_EQ(run(ring(r, 0, kPi), pa, plane(), Pose{}, 1.0, out), 2);
  EXPECT_EQ(out[0].feature, 1);
  EXPECT_EQ(out[1].feature, 2);
  expectVecNear(out[0].point_a, Vec3(1e-3 + r, 2e-3, h), kTol);
  expectVecNear(out[1].point_a, Vec3(1e-3 - r, 2e-3, h), kTol);
  EXPECT_NEAR(out[0].gap, h, kTol);
  EXPECT_NEAR(out[1].gap, h, kTol);
  // An arc starting 0.1 rad past the deepest point: its start is its lowest point.
  ASSERT_EQ(run(ring(r, -kPi / 2 + 0.1, 1.0), pa, plane(), Pose{}, 1.0, out), 2);
  EXPECT_NEAR(byFeature(out, 2, 1)->gap, h - r * std::cos(0.1), kTol);
  EXPECT_NEAR(byFeature(out, 2, 2)->gap, h - r * std::cos(1.1), kTol);
  // The margin drops the higher end.
  ASSERT_EQ(run(ring(r, -kPi / 2 + 0.1, 1.0), pa, plane(), Pose{}, h - 0.5 * r, out), 1);
  EXPECT_EQ(out[0].feature, 1);
  // An arc ending exactly at the deepest point (start + span written in two
  // roundings): still the deepest point, as feature 0 or as the arc's end.
  ASSERT_GE(run(ring(r, -kPi / 2 - 1.0, 1.0), pa, plane(), Pose{}, 1.0, out), 1);
  EXPECT_NEAR(minGap(out, 2), h - r, kTol);
  // Parallel to the plane (frame z = world z): three points, all at height h.
  const Pose flat = at(Vec3(0, 0, h));
  ASSERT_EQ(run(ring(r), flat, plane(), Pose{}, 1.0, out), 3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(out[i].feature, 3 + i);
    EXPECT_NEAR(out[i].gap, h, kTol);
  }
  ASSERT_EQ(run(ring(r, 0.3, 1.0), flat, plane(), Pose{}, 1.0, out), 3);
  expectVecNear(byFeature(out, 3, 1)->point_a, Vec3(r * std::cos(0.3), r * std::sin(0.3), h), kTol);
  expectVecNear(byFeature(out, 3, 2)->point_a, Vec3(r * std::cos(1.3), r * std::sin(1.3), h), kTol);
  expectVecNear(byFeature(out, 3, 3)->point_a, Vec3(r * std::cos(0.8), r * std::sin(0.8), h), kTol);
}

// Ring against a face at random poses: where the brute-force deepest point of
// the arc has its foot inside the rectangle by more than 1 um, the routine gives
// that gap (same tolerance as ring-plane) and a point within r dt of it; where
// the foot is outside by more than 1 um, no point near it. Every emitted foot
// lies in the closed rectangle.
TEST(ContactGeometry, RingFaceAgainstBruteForce) {
  std::mt19937_64 rng(102);
  ContactPoint out[kMaxPointsPerPair];
  int inside = 0, outside = 0, behind_count = 0;
  for (int it = 0; it < 1200; ++it) {
    const double r = uni(rng, 0.3e-3, 3e-3);
    const Shape s = randomRing(rng, r);
    const double sx = uni(rng, 0.5e-3, 6e-3), sy = uni(rng, 0.5e-3, 6e-3);
    const Pose pb = at(Vec3(uni(rng, -0.02, 0.02), uni(rng, -0.02, 0.02), uni(rng, -0.02, 0.02)), randQuat(rng));
    const Vec3 m = pb.rotate(Vec3::UnitZ());
    const Vec3 off = pb.rotate(Vec3(uni(rng, -0.5 * sx - r, 0.5 * sx + r), uni(rng, -0.5 * sy - r, 0.5 * sy + r), 0));
    const Pose pa = at(pb.p + off + uni(rng, -r, r) * m, randQuat(rng));
    const RingFrame f(pa);
    double t0 = 0;
    const double brute = bruteMin(s, [&](double t) { return m.dot(f.at(r, t) - pb.p); }, &t0);
    const Vec3 deepest = f.at(r, t0);
    const Vec3 foot = pb.q.conjugate() * (deepest - pb.p);
    const double out_by = std::max(std::abs(foot.x()) - 0.5 * sx, std::abs(foot.y()) - 0.5 * sy);
    const int n = run(s, pa, face(sx, sy), pb, 1.0, out);
    for (int i = 0; i < n; ++i) {
      expectOnArc(out[i].point_a, s, f, 1e-15);
      const Vec3 l = pb.q.conjugate() * (out[i].point_b - pb.p);
      EXPECT_NEAR(l.z(), 0.0, 1e-15);
      EXPECT_LE(std::abs(l.x()), 0.5 * sx);
      EXPECT_LE(std::abs(l.y()), 0.5 * sy);
      expectVecNear(out[i].normal, m, 1e-15);
      EXPECT_GE(out[i].gap, brute - 1e-10);
    }
    const double dt = s.span / (kSamples - 1);
    const ContactPoint* near = nullptr;
    for (int i = 0; i < n; ++i)
      if ((out[i].point_a - deepest).norm() <= r * dt + 1e-12) near = &out[i];
    // Below the face by more than its nearest edge is far (-out_by): behind it.
    const bool behind = -brute > -out_by + 1e-6;
    if (out_by < -1e-6 && -brute < -out_by - 1e-6) {
      ++inside;
      ASSERT_TRUE(near) << "it " << it;
      EXPECT_NEAR(near->gap, brute, r * dt * dt / 8 + 1e-15);
    } else if (out_by > 1e-6 || behind) {
      ++outside;
      behind_count += behind && out_by < 0;
      EXPECT_FALSE(near) << "it " << it;
    }
  }
  EXPECT_GT(behind_count, 100);
  EXPECT_GT(inside, 100);
  EXPECT_GT(outside, 150);
}

// The edge rule: the foot of the deepest point exactly on an edge or corner
// counts as on the face (closed rectangle); 1e-12 m beyond, no point.
// The nearest-feature rule of bounded patches: a point deeper below a face, or
// inside a cylinder patch, than the patch's nearest side is far came in from
// the side (behind the patch) and gives no point; shallower, it does.
TEST(ContactGeometry, PatchesDropPointsFromBehind) {
  ContactPoint out[kMaxPointsPerPair];
  const Quat vertical = rotAbout(Vec3::UnitX(), kPi / 2);  // deepest point straight below the centre
  const double r = 0.5;
  // Face 2 x 4: the ring's lowest point 0.3 below it, 0.2 / 0.4 from the x edge.
  EXPECT_EQ(run(ring(r), at(Vec3(0.8, 0, r - 0.3), vertical), face(2, 4), Pose{}, 1.0, out), 0);
  ASSERT_EQ(run(ring(r), at(Vec3(0.6, 0, r - 0.3), vertical), face(2, 4), Pose{}, 1.0, out), 1);
  EXPECT_NEAR(out[0].gap, -0.3, kTol);
  // Deep by exactly the distance to the edge: kept (the rule is strict).
  EXPECT_EQ(run(ring(r), at(Vec3(0.75, 0, r - 0.25), vertical), face(2, 4), Pose{}, 1.0, out), 1);
  // Cylinder R 2 along z; the ring (in xy, r 0.5) centred at x = 2.2: its
  // nearest point (1.7, 0, 0) is 0.3 inside, 1.7 from the axis.
  const Shape rg = ring(r);
  const Pose c(at(Vec3(2.2, 0, 0)));
  EXPECT_EQ(run(rg, c, cylinderArc(2, 1, -0.1, 0.2), Pose{}, 1.0, out), 0);  // 1.7 sin 0.1 = 0.17 from its side
  ASSERT_EQ(run(rg, c, cylinderArc(2, 1, -0.3, 0.6), Pose{}, 1.0, out), 1);  // 1.7 sin 0.3 = 0.50
  EXPECT_NEAR(out[0].gap, -0.3, kTol);
  EXPECT_EQ(run(rg, c, cylinder(2, 0.5), Pose{}, 1.0, out), 0);  // 0.25 from a flat end
  EXPECT_EQ(run(rg, c, cylinder(2, 0.7), Pose{}, 1.0, out), 1);
  // Hollow R 2: the ring centred at x = 1.8 reaches 2.3 (0.3 into the wall).
  const Pose h(at(Vec3(1.8, 0, 0)));
  EXPECT_EQ(run(rg, h, hollowArc(2, 1, -0.1, 0.2), Pose{}, 1.0, out), 0);   // 2.3 sin 0.1 = 0.23
  ASSERT_EQ(run(rg, h, hollowArc(2, 1, -0.2, 0.4), Pose{}, 1.0, out), 1);   // 2.3 sin 0.2 = 0.46
  EXPECT_NEAR(out[0].gap, -0.3, kTol);
  EXPECT_EQ(run(rg, h, hollowArc(2, 0.5), Pose{}, 1.0, out), 0);
}

TEST(ContactGeometry, RingFaceEdgeRule) {
  const double r = 0.5e-3, g = 0.01e-3;
  const Quat vertical = rotAbout(Vec3::UnitX(), kPi / 2);  // deepest point straight below the centre
  const Pose pb = at(Vec3(0, 0, 0));
  ContactPoint out[kMaxPointsPerPair];
  auto count = [&](double x, double y) {
    return run(ring(r), at(Vec3(x, y, r + g), vertical), face(2e-3, 4e-3), pb, 1.0, out);
  };
  EXPECT_EQ(count(0, 0), 1);
  EXPECT_NEAR(out[0].gap, g, kTol);
  EXPECT_EQ(count(1e-3, 0), 1);      // on the x edge
  EXPECT_EQ(count(-1e-3, 2e-3), 1);  // on a corner
  EXPECT_EQ(count(1e-3 + 1e-12, 0), 0);
  EXPECT_EQ(count(0, -2e-3 - 1e-12), 0);
  // Beyond the edge the ring hangs over the face with its side, still no point.
  EXPECT_EQ(count(1e-3 + 0.4e-3, 0), 0);
  // Same on a turned, shifted face.
  const Pose turned = at(Vec3(0.1, 0.2, 0.3), rotAbout(Vec3(0.3, -0.2, 1), 0.8));
  const Vec3 m = turned.rotate(Vec3::UnitZ());
  const Quat q = Quat::FromTwoVectors(Vec3::UnitZ(), m) * vertical;  // frame y = m: ring plane contains m
  ASSERT_LT(std::abs(q.toRotationMatrix().col(2).dot(m)), 1e-12);
  auto count2 = [&](double x) {
    return run(ring(r), at(turned.apply(Vec3(x, 0, 0)) + (r + g) * m, q), face(2e-3, 4e-3), turned, 1.0, out);
  };
  EXPECT_EQ(count2(0.999e-3), 1);
  EXPECT_NEAR(out[0].gap, g, 1e-15);
  expectVecNear(out[0].point_b, turned.apply(Vec3(0.999e-3, 0, 0)), 1e-15);
  EXPECT_EQ(count2(1.001e-3), 0);
}

// Ring against a long full cylinder at random poses (parallel, perpendicular and
// oblique axes): the lowest emitted gap equals the brute-force minimum over the
// arc of the gap g(t) (w: the ring point across the axis); each point lies on
// the arc and on the lateral surface, its normal B's outward one.
// - Solid: g = |w| - R, the ring centre R + r/2 .. R + 3r/2 from the axis, r <= R:
//   |w| >= R/2, so |g''| <= r + r^2 / (R/2) = G; normal away from the axis.
// - Hollow (material outside, the ring kept inside): g = R - |w|, r <= 0.4 R, the
//   centre 0.5 R .. R - r/2 from the axis: |w| >= 0.1 R, G = r + r^2 / (0.1 R);
//   normal towards the axis.
// The sampling error is below G dt^2 / 8.
static void ringCylinderAgainstBruteForce(bool hollow, unsigned seed) {
  std::mt19937_64 rng(seed);
  ContactPoint out[kMaxPointsPerPair];
  int kinds[3] = {};
  const double sign = hollow ? -1.0 : 1.0;
  for (int it = 0; it < 600; ++it) {
    const double R = uni(rng, 1e-3, 6e-3);
    const double r = (hollow ? uni(rng, 0.05, 0.4) : uni(rng, 0.2, 1.0)) * R;
    const Shape s = randomRing(rng, r);
    const Pose pb = at(Vec3(uni(rng, -0.02, 0.02), uni(rng, -0.02, 0.02), uni(rng, -0.02, 0.02)), randQuat(rng));
    const Vec3 u = pb.rotate(Vec3::UnitZ());
    const Vec3 dir = rotAbout(u, uni(rng, -kPi, kPi)) * anyOrthogonal(u);
    const double from_axis = hollow ? uni(rng, 0.5 * R, R - 0.5 * r) : uni(rng, R + 0.5 * r, R + 1.5 * r);
    const Vec3 c = pb.p + from_axis * dir + uni(rng, -0.01, 0.01) * u;
    const int kind = it % 3;
    Quat q;
    if (kind == 0) q = pb.q * rotAbout(Vec3::UnitZ(), uni(rng, -kPi, kPi));  // parallel axes
    else if (kind == 1) q = Quat::FromTwoVectors(Vec3::UnitZ(), rotAbout(u, uni(rng, -kPi, kPi)) * anyOrthogonal(u)) *
                            rotAbout(Vec3::UnitZ(), uni(rng, -kPi, kPi));  // perpendicular
    else q = randQuat(rng);
    const Pose pa = at(c, q);
    const RingFrame f(pa);
    auto gapAt = [&](double t) {
      const Vec3 w = f.at(r, t) - pb.p;
      return sign * ((w - u.dot(w) * u).norm() - R);
    };
    const double brute = bruteMin(s, gapAt);
    const int n = run(s, pa, hollow ? hollowArc(R, 1.0) : cylinder(R, 1.0), pb, 1.0, out);
    ASSERT_GE(n, 1) << "it " << it;
    const double dt = s.span / (kSamples - 1);
    const double G = r + r * r / ((hollow ? 0.1 : 0.5) * R);
    EXPECT_NEAR(minGap(out, n), brute, G * dt * dt / 8 + 1e-15) << "it " << it << " kind " << kind;
    EXPECT_LE(minGap(out, n), brute + 1e-15);
    for (int i = 0; i < n; ++i) {
      expectOnArc(out[i].point_a, s, f, 1e-15);
      const Vec3 wb = out[i].point_b - pb.p;
      EXPECT_NEAR((wb - u.dot(wb) * u).norm(), R, 1e-15);  // on the lateral surface
      // Round-off of the normal's axial part: the point's axial offset (up to 1 cm)
      // over its distance from the axis (down to 0.1 R), times the epsilon.
      EXPECT_NEAR(out[i].normal.dot(u), 0.0, 1e-13);
      const Vec3 wa = out[i].point_a - pb.p;
      expectVecNear(out[i].normal, sign * (wa - u.dot(wa) * u).normalized(), 1e-12);
      EXPECT_NEAR(out[i].gap, (out[i].point_a - out[i].point_b).dot(out[i].normal), 1e-15);
    }
    ++kinds[kind];
  }
  for (int k : kinds) EXPECT_EQ(k, 200);
}

// The margin is a filter (what the narrowphase cache relies on): the points of a
// ring-cylinder pair at margin m are those at a wide margin with gap < m, for rings
// near their cylinder (coaxial to oblique, centred to eccentric, inside the patch
// to beyond its ends), at margins around each pair's lowest gap, so that the
// early-outs (the bound before the sampling, the one after it) are taken and
// missed. Fails if a bound is not one (it would drop points).
static void ringCylinderMarginIsAFilter(bool hollow, unsigned seed) {
  std::mt19937_64 rng(seed);
  ContactPoint wide[kMaxPointsPerPair], out[kMaxPointsPerPair];
  int none = 0, some = 0;
  for (int it = 0; it < 3000; ++it) {
    const double R = uni(rng, 1e-3, 6e-3), L = uni(rng, 1e-3, 1e-2);
    // Kinds: 0 around the axis (coaxial to eccentric; solid: the ring encircles
    // the cylinder), 1 beside it (solid) or far off-centre (hollow), 2 at an end
    // of the patch, tilted.
    const int kind = it % 3;
    const double r = kind == 1 ? uni(rng, 0.2, hollow ? 0.5 : 1.0) * R
                               : (hollow ? uni(rng, 0.5, 0.99) : uni(rng, 1.01, 1.5)) * R;
    const Shape s = randomRing(rng, r);
    const Pose pb = at(Vec3(uni(rng, -0.02, 0.02), uni(rng, -0.02, 0.02), uni(rng, -0.02, 0.02)), randQuat(rng));
    const Vec3 u = pb.rotate(Vec3::UnitZ());
    const double tilt = kind == 2 ? uni(rng, 0, 1) : std::pow(10.0, uni(rng, -6, -0.5)) * (it % 7 == 0 ? 0 : 1);
    const Quat q = pb.q * rotAbout(anyOrthogonal(Vec3::UnitZ()), tilt) * rotAbout(Vec3::UnitZ(), uni(rng, -kPi, kPi));
    const Vec3 off = rotAbout(u, uni(rng, -kPi, kPi)) * anyOrthogonal(u);
    double from_axis = uni(rng, 0, 0.5) * std::abs(R - r), along = uni(rng, -0.7, 0.7) * L;
    if (kind == 1) from_axis = hollow ? R - r * uni(rng, 0.9, 1.3) : R + r * uni(rng, 0.9, 1.3);
    if (kind == 2) along = (it % 2 ? 1 : -1) * (0.5 * L + uni(rng, -1, 1) * r * std::sin(tilt));
    const Vec3 c = pb.p + from_axis * off + along * u;
    const Shape b = hollow ? hollowArc(R, L) : cylinder(R, L);
    const int nw = run(s, at(c, q), b, pb, 1.0, wide);
    double lowest = 0.1 * R;
    for (int i = 0; i < nw; ++i) lowest = std::min(lowest, wide[i].gap);
    for (double d : {-3e-2, -1e-7, 1e-7, 3e-3, 3e-2}) {
      const double m = std::max(1e-12, lowest + d * R);
      const int n = run(s, at(c, q), b, pb, m, out);
      int k = 0;
      for (int i = 0; i < nw; ++i) {
        if (!(wide[i].gap < m)) continue;
        ASSERT_LT(k, n) << "it " << it << " margin " << m << ": a point was dropped";
        EXPECT_EQ(out[k].feature, wide[i].feature);
        EXPECT_EQ(out[k].gap, wide[i].gap);
        ++k;
      }
      EXPECT_EQ(n, k) << "it " << it << " margin " << m;
      (n == 0 ? none : some) += 1;
    }
  }
  EXPECT_GT(none, 1000);  // both outcomes are exercised
  EXPECT_GT(some, 1000);
}

// A ring around a cylinder, tilted by 0.1 rad, its centre past the cylinder's end
// by half its axial extent r sin(tilt): the ring comes nearest the axis (r cos tilt
// from it) at its two points furthest along the axis, and the inner one lies on the
// patch. It is the pair's one point, wherever the ring's own angle starts. (Fails
// if the axial early-out counts the ring's extent short.)
TEST(ContactGeometry, RingAroundCylinderEndKeepsItsInnerPoint) {
  const double R = 2e-3, r = 2.1e-3, L = 4e-3, tilt = 0.1;
  ContactPoint out[kMaxPointsPerPair];
  for (double spin : {0.0, 1.0, 2.5}) {
    const Quat q = rotAbout(Vec3::UnitX(), tilt) * rotAbout(Vec3::UnitZ(), spin);
    const Vec3 c(0, 0, 0.5 * L + 0.5 * r * std::sin(tilt));
    ASSERT_EQ(run(ring(r), at(c, q), cylinder(R, L), Pose{}, 1e-4, out), 1) << "spin " << spin;
    EXPECT_NEAR(out[0].gap, r * std::cos(tilt) - R, 1e-12);
    EXPECT_NEAR(out[0].point_a.z(), 0.5 * L - 0.5 * r * std::sin(tilt), 1e-12);
  }
}

TEST(ContactGeometry, RingCylinderMarginIsAFilter) { ringCylinderMarginIsAFilter(false, 107); }
TEST(ContactGeometry, RingInHollowCylinderMarginIsAFilter) { ringCylinderMarginIsAFilter(true, 109); }

TEST(ContactGeometry, RingCylinderAgainstBruteForce) { ringCylinderAgainstBruteForce(false, 103); }
TEST(ContactGeometry, RingInHollowCylinderAgainstBruteForce) { ringCylinderAgainstBruteForce(true, 105); }

// A hollow cylinder's patch: the ring (r 0.5) centred at x = 1 inside R 2 along
// z: nearest point (1.5, 0, 0) on the wall (2, 0, 0), gap 0.5, normal -x; the
// span limits the wall by the direction from the axis, the length as for a solid.
TEST(ContactGeometry, RingInHollowCylinderPatchLimits) {
  ContactPoint out[kMaxPointsPerPair];
  const Shape rg = ring(0.5);
  ASSERT_EQ(run(rg, at(Vec3(1, 0, 0)), hollowArc(2, 1), Pose{}, 1.0, out), 1);
  EXPECT_EQ(out[0].feature, 0);
  EXPECT_NEAR(out[0].gap, 0.5, kTol);
  expectVecNear(out[0].normal, -Vec3::UnitX(), kTol);
  expectVecNear(out[0].point_a, Vec3(1.5, 0, 0), kTol);
  expectVecNear(out[0].point_b, Vec3(2, 0, 0), kTol);
  // Pressed 0.1 into the wall: gap -0.1, the same normal.
  ASSERT_EQ(run(rg, at(Vec3(1.6, 0, 0)), hollowArc(2, 1), Pose{}, 1.0, out), 1);
  EXPECT_NEAR(out[0].gap, -0.1, kTol);
  EXPECT_EQ(run(rg, at(Vec3(1, 0, 0.5)), hollowArc(2, 1), Pose{}, 1.0, out), 1);  // at the end: kept
  EXPECT_EQ(run(rg, at(Vec3(1, 0, 0.5 + 1e-12)), hollowArc(2, 1), Pose{}, 1.0, out), 0);
  EXPECT_EQ(run(rg, at(Vec3(1, 0, 0)), hollowArc(2, 1, -0.1, 0.2), Pose{}, 1.0, out), 1);
  EXPECT_EQ(run(rg, at(Vec3(1, 0, 0)), hollowArc(2, 1, 0.1, 0.2), Pose{}, 1.0, out), 0);
  // The same ring solid-cylinder style would be 1.5 deep: the hollow one is
  // not the solid one with the sign of the gap flipped.
  ASSERT_EQ(run(rg, at(Vec3(1, 0, 0)), cylinder(2, 4), Pose{}, 1.0, out), 1);
  EXPECT_NEAR(out[0].gap, -1.5, kTol);
  // A guide arc like the C-60's bar wedge (R 5.9, 29 deg about 180 deg) and a
  // tip passing 0.49 inside it, just before its span: no point; within it, +0.49.
  const Shape guide = hollowArc(5.9, 3, 165.3 * kPi / 180, 29.4 * kPi / 180);
  const Vec3 d165(std::cos(165 * kPi / 180), std::sin(165 * kPi / 180), 0);
  const Vec3 d170(std::cos(170 * kPi / 180), std::sin(170 * kPi / 180), 0);
  EXPECT_EQ(run(rg, at(4.91 * d165), guide, Pose{}, 1.0, out), 0);
  ASSERT_EQ(run(rg, at(4.91 * d170), guide, Pose{}, 1.0, out), 1);
  EXPECT_NEAR(out[0].gap, 0.49, 1e-12);
  expectVecNear(out[0].normal, -d170, kTol);
}

// The cylinder's patch: length (closed) and angular span; two minima when a
// perpendicular ring hoops around the axis.
TEST(ContactGeometry, RingCylinderPatchLimits) {
  ContactPoint out[kMaxPointsPerPair];
  // Parallel axes: the ring (r 0.5) centred at x = 3 beside the cylinder R 2
  // along z: nearest point (2.5, 0, z), gap 0.5, normal +x.
  const Shape rg = ring(0.5);
  ASSERT_EQ(run(rg, at(Vec3(3, 0, 0)), cylinder(2, 1), Pose{}, 1.0, out), 1);
  EXPECT_EQ(out[0].feature, 0);
  EXPECT_NEAR(out[0].gap, 0.5, kTol);
  expectVecNear(out[0].normal, Vec3::UnitX(), kTol);
  expectVecNear(out[0].point_a, Vec3(2.5, 0, 0), kTol);
  expectVecNear(out[0].point_b, Vec3(2, 0, 0), kTol);
  EXPECT_EQ(run(rg, at(Vec3(3, 0, 0.5)), cylinder(2, 1), Pose{}, 1.0, out), 1);  // at the end: kept
  EXPECT_EQ(run(rg, at(Vec3(3, 0, 0.5 + 1e-12)), cylinder(2, 1), Pose{}, 1.0, out), 0);
  EXPECT_EQ(run(rg, at(Vec3(3, 0, 0)), cylinderArc(2, 1, -0.1, 0.2), Pose{}, 1.0, out), 1);
  EXPECT_EQ(run(rg, at(Vec3(3, 0, 0)), cylinderArc(2, 1, 0.1, 0.2), Pose{}, 1.0, out), 0);
  EXPECT_EQ(run(rg, at(Vec3(3, 0, 0)), cylinderArc(2, 1, 0.1, 2 * kPi - 0.2), Pose{}, 1.0, out), 0);
  EXPECT_EQ(run(rg, at(Vec3(3, 0, 0)), cylinderArc(2, 1, -kPi / 2, kPi / 2), Pose{}, 1.0, out), 1);  // end of the span
  // The hook-arc case: the same at 100 deg round the axis, span 60 deg about it.
  const Vec3 d100(std::cos(100 * kPi / 180), std::sin(100 * kPi / 180), 0);
  ASSERT_EQ(run(rg, at(3 * d100), cylinderArc(2, 1, 70 * kPi / 180, 60 * kPi / 180), Pose{}, 1.0, out), 1);
  expectVecNear(out[0].normal, d100, kTol);
  // An arc of the ring facing away: its ends are its nearest points (1 and 2).
  ASSERT_EQ(run(ring(0.5, -kPi / 2, kPi), at(Vec3(3, 0, 0)), cylinder(2, 1), Pose{}, 10.0, out), 2);
  EXPECT_NEAR(byFeature(out, 2, 1)->gap, std::sqrt(9 + 0.25) - 2, kTol);
  EXPECT_NEAR(byFeature(out, 2, 2)->gap, std::sqrt(9 + 0.25) - 2, kTol);
  // Perpendicular: a ring of r 2 in the plane y = 1.5 (axis y) around the
  // cylinder R 1 along z: |w| = sqrt(4 cos^2 t + 2.25), lowest at t = +-pi/2,
  // the points (0, 1.5, +-2), gap 0.5, both with normal +y.
  const Quat ringInXZ = rotAbout(Vec3::UnitX(), kPi / 2);  // frame y -> world z
  ASSERT_EQ(run(ring(2), at(Vec3(0, 1.5, 0), ringInXZ), cylinder(1, 5), Pose{}, 1.0, out), 2);
  const ContactPoint* f0 = byFeature(out, 2, 0);
  const ContactPoint* f3 = byFeature(out, 2, 3);
  ASSERT_TRUE(f0 && f3);
  EXPECT_NEAR(f0->gap, 0.5, kTol);
  EXPECT_NEAR(f3->gap, 0.5, kTol);
  expectVecNear(f0->normal, Vec3::UnitY(), kTol);
  expectVecNear(f0->point_a, Vec3(0, 1.5, 2), 1e-9);
  expectVecNear(f3->point_a, Vec3(0, 1.5, -2), 1e-9);
  // Cylinder only 3 long: both minima beyond its ends, no point; shifted up by
  // 1, only the lower one (now at z = -1) is on it.
  EXPECT_EQ(run(ring(2), at(Vec3(0, 1.5, 0), ringInXZ), cylinder(1, 3), Pose{}, 1.0, out), 0);
  ASSERT_EQ(run(ring(2), at(Vec3(0, 1.5, 1), ringInXZ), cylinder(1, 3), Pose{}, 1.0, out), 1);
  expectVecNear(out[0].point_a, Vec3(0, 1.5, -1), 1e-9);
  EXPECT_NEAR(out[0].gap, 0.5, kTol);
}

// Swapped argument order for every ring pair, including arcs, faces off-centre
// and limited cylinders: same points with A and B exchanged, normal flipped.
TEST(ContactGeometry, RingPairsSwapped) {
  std::mt19937_64 rng(104);
  ContactPoint ab[kMaxPointsPerPair], ba[kMaxPointsPerPair];
  int compared = 0;
  for (int it = 0; it < 300; ++it) {
    const Shape s = randomRing(rng, 1e-3);
    const Pose pb = at(Vec3::Zero(), randQuat(rng));
    const Pose pa = at(Vec3(uni(rng, -3e-3, 3e-3), uni(rng, -3e-3, 3e-3), uni(rng, -3e-3, 3e-3)), randQuat(rng));
    const Shape others[4] = {plane(), face(3e-3, 2e-3), cylinderArc(1e-3, 4e-3, uni(rng, -kPi, kPi), uni(rng, 0.5, 2 * kPi)),
                             hollowArc(4e-3, 4e-3, uni(rng, -kPi, kPi), uni(rng, 0.5, 2 * kPi))};
    for (const Shape& b : others) {
      const int n = run(s, pa, b, pb, 1.0, ab);
      const int m = run(b, pb, s, pa, 1.0, ba);
      ASSERT_EQ(n, m);
      for (int i = 0; i < n; ++i) {
        EXPECT_EQ(ba[i].feature, ab[i].feature);
        EXPECT_EQ(ba[i].gap, ab[i].gap);
        EXPECT_EQ(ba[i].normal, Vec3(-ab[i].normal));
        EXPECT_EQ(ba[i].point_a, ab[i].point_b);
        EXPECT_EQ(ba[i].point_b, ab[i].point_a);
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 300);
}

// A cylinder limited to an arc against a plane: its two end rims as arcs.
TEST(ContactGeometry, CylinderArcPlane) {
  ContactPoint out[kMaxPointsPerPair];
  // Axis along x, 0.4 above the plane, radius 0.3, length 1. Frame: z -> x.
  const Quat alongX = rotAbout(Vec3::UnitY(), kPi / 2);  // frame x -> -z, frame y -> y
  const Pose pa = at(Vec3(0, 0, 0.4), alongX);
  // Full: the existing line contact (two rim points, gap 0.1).
  ASSERT_EQ(run(cylinder(0.3, 1), pa, plane(), Pose{}, 1.0, out), 2);
  EXPECT_NEAR(minGap(out, 2), 0.1, kTol);
  // Arc containing the bottom (frame +x = world -z): same two points, features 0 and 4.
  ASSERT_EQ(run(cylinderArc(0.3, 1, -0.5, 1.0), pa, plane(), Pose{}, 1.0, out), 2);
  EXPECT_NEAR(byFeature(out, 2, 0)->gap, 0.1, kTol);
  EXPECT_NEAR(byFeature(out, 2, 4)->gap, 0.1, kTol);
  // Arc on the top, start pi/2 + 0.2, span pi - 0.4 (height 0.4 - 0.3 cos t):
  // the deepest point is outside, the four arc ends at 0.4 + 0.3 sin 0.2.
  const double s0 = kPi / 2 + 0.2, sp = kPi - 0.4;
  ASSERT_EQ(run(cylinderArc(0.3, 1, s0, sp), pa, plane(), Pose{}, 1.0, out), 4);
  for (int f : {1, 2, 5, 6}) {
    const ContactPoint* p = byFeature(out, 4, f);
    ASSERT_TRUE(p) << f;
    EXPECT_NEAR(p->gap, 0.4 + 0.3 * std::sin(0.2), kTol) << f;
  }
}

// Three C-60 contacts at the ON state, from the CAD tables
// (/work/shared/c60/cad/contacts_cad.json; world frame, mm, inputs rounded to
// 1e-4 mm): the pairs reproduce the CAD distance (gap before the authors'
// offset) within 3e-4 mm and its points within 3e-3 mm.
namespace {
// The frame at o whose z is `z` and x is `x` (made orthogonal to z).
Pose frameAt(const Vec3& o, const Vec3& z, const Vec3& x) {
  const Vec3 zn = z.normalized();
  const Vec3 xn = (x - x.dot(zn) * zn).normalized();
  Mat3 r;
  r.col(0) = xn;
  r.col(1) = zn.cross(xn);
  r.col(2) = zn;
  return Pose{o, Quat(r)};
}
double deg(double d) { return d * kPi / 180; }
}  // namespace

TEST(ContactGeometry, C60CadContactsAtOn) {
  ContactPoint out[kMaxPointsPerPair];
  // C4_1: the hook's vertical half-ring r 0.5 (its middle towards the seat)
  // on the bar's seat F4, a 0.59013 x 3 face whose outward normal is
  // (-0.5878, 0.809, 0). CAD distance 0.009111.
  {
    const Vec3 c(2.4093, 5.6963, 7.1), mid = (Vec3(2.7122, 5.2984, 7.1) - c).normalized();
    const Pose ringPose = frameAt(c, Vec3(-0.7957, -0.6056, 0), mid);
    const Vec3 n(-0.5878, 0.809, 0);
    const Pose seat = frameAt(Vec3(2.7602, 5.3221, 8.1), n, Vec3(0, 0, 1).cross(n));
    ASSERT_EQ(run(ring(0.5, -kPi / 2, kPi), ringPose, face(0.59013, 3.0), seat, 1.0, out), 1);
    std::printf("[ figures  ] C4_1 at ON: distance %.6f mm (CAD 0.009111)\n", out[0].gap);
    EXPECT_NEAR(out[0].gap, 0.009111, 3e-4);
    expectVecNear(out[0].point_a, Vec3(2.7122, 5.2984, 7.1), 3e-3);
    expectVecNear(out[0].point_b, Vec3(2.7175, 5.2911, 7.1), 3e-3);
  }
  // C5_1: the bar's half-ring r 0.48, 130.75 deg about its middle, outside the
  // hook's arc r 5.63 about J3, 3 long, at world angles 156.07..204.97 deg.
  // CAD distance 0.029465.
  {
    const Vec3 c(2.1612, 5.1341, 7.4), mid = Vec3(2.5495, 5.4162, 7.4) - c;
    const double a = std::atan2(mid.y(), mid.x()), sp = deg(130.75);
    const Pose hook = at(Vec3(7.767, 7.6377, 8.1));
    ASSERT_EQ(run(ring(0.48, a - sp / 2, sp), at(c), cylinderArc(5.63, 3.0, deg(156.07), deg(48.9)), hook, 1.0, out), 1);
    std::printf("[ figures  ] C5_1 at ON: distance %.6f mm (CAD 0.029465)\n", out[0].gap);
    EXPECT_NEAR(out[0].gap, 0.029465, 3e-4);
    expectVecNear(out[0].point_a, Vec3(2.5995, 5.3298, 7.4), 3e-3);
    expectVecNear(out[0].point_b, Vec3(2.6264, 5.3418, 7.4), 3e-3);
    // The contact lies at 204.07 deg about J3, 0.9 deg inside the arc's end: an
    // arc ending at 203 deg gives no point.
    EXPECT_EQ(run(ring(0.48, a - sp / 2, sp), at(c), cylinderArc(5.63, 3.0, deg(154.1), deg(48.9)), hook, 1.0, out), 0);
  }
  // TRIP_2: the bar's arc r 6.0 (53.18 deg about 179.47 deg) against the
  // probe's flat end, the face x = -5.0 of 6.17522 x 6.20044 facing +x.
  // CAD distance 0.389133.
  {
    const double sp = deg(53.18), a = std::atan2(-9.0045 + 9.0596, -4.6106 - 1.3891);
    const Pose probe = frameAt(Vec3(-5.0, -8.9, 4.65), Vec3(1, 0, 0), Vec3(0, 1, 0));
    ASSERT_EQ(run(ring(6.0, a - sp / 2, sp), at(Vec3(1.3891, -9.0596, 5.9)), face(6.17522, 6.20044), probe, 1.0, out), 1);
    std::printf("[ figures  ] TRIP_2 at ON: distance %.6f mm (CAD 0.389133)\n", out[0].gap);
    EXPECT_NEAR(out[0].gap, 0.389133, 3e-4);
    expectVecNear(out[0].point_a, Vec3(-4.6109, -9.0596, 5.9), 3e-3);
    expectVecNear(out[0].normal, Vec3(1, 0, 0), 1e-12);
  }
}
