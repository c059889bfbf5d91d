// The ideal revolute joint: the anchors coincide (3 rows) and the child's axis
// stays on the parent's (2 rows); its angle and rate about the axis.
#include <cmath>

#include "joint_rows.hpp"

namespace nscd {

namespace {

// One row's 6-column piece on a body written into G (column-major, leading
// dimension ld), as putRow writes it: body B's piece set to [lin, R_b^T ang], body
// A's added to the cleared row, hence +0.0 (+0 + x is x, but -0 comes out +0, as
// putRow's += makes it). A ground side has no piece, so its values are not formed.
inline void writePieceB(double* gb, Eigen::Index ld, const Vec3& lin, const Vec3& ang) {
  for (int k = 0; k < 3; ++k) {
    gb[k * ld] = lin[k];
    gb[(k + 3) * ld] = ang[k];
  }
}
inline void writePieceA(double* ga, Eigen::Index ld, const Vec3& lin, const Vec3& ang) {
  for (int k = 0; k < 3; ++k) {
    ga[k * ld] = 0.0 + lin[k];
    ga[(k + 3) * ld] = 0.0 + ang[k];
  }
}

// The five rows' pieces (ga, gb: G at the first row on bodies A and B), on the
// bodies present (kA, kB; a ground side has no piece, so its values are not formed).
template <bool kA, bool kB>
void writeRevolutePieces(const Quat& qa_t, const Quat& qb_t, const Vec3& ra, const Vec3& rb, const Vec3& axis_b,
                         const Frame3& fa, double* ga, double* gb, Eigen::Index ld) {
  for (int i = 0; i < 3; ++i) {  // the anchors coincide
    const Vec3 d = Vec3::Unit(i);
    if (kB) writePieceB(gb + i, ld, d, qb_t * rb.cross(d));
    if (kA) writePieceA(ga + i, ld, -d, qa_t * (-(ra.cross(d))));
  }
  for (int i = 1; i < 3; ++i) {  // the child's axis on the parent's
    const Vec3 c = axis_b.cross(fa.e[i]);
    if (kB) writePieceB(gb + 2 + i, ld, Vec3::Zero(), qb_t * c);
    if (kA) writePieceA(ga + 2 + i, ld, Vec3::Zero(), qa_t * (-c));
  }
}

}  // namespace

void appendRevoluteRows(const Joint& j, const State& s, const JointPlacement& p,
                        ConstraintBlock& blk, int& r, Eigen::MatrixXd& G) {
  const Vec3 axis_b = p.b.q * j.axis_b;
  if (j.body_a == j.body_b) {  // both pieces on one body: putRow adds them up
    appendPointRows(j, s, p, blk, r, G);
    for (int i = 1; i < 3; ++i) {
      const Vec3 c = axis_b.cross(p.fa.e[i]);
      putRow(G, r, s, j.body_a, j.body_b, Vec3::Zero(), c, Vec3::Zero(), -c);
      blk.error[r - blk.row] = axis_b.dot(p.fa.e[i]);
      ++r;
    }
    return;
  }
  // The same rows as appendPointRows and putRow write, the same arithmetic
  // (bit for bit), with the bodies' conjugate rotations and lever arms formed
  // once and the row written in place.
  const Eigen::Index ld = G.outerStride();
  const Quat qa_t = p.a.q.conjugate(), qb_t = p.b.q.conjugate();
  const Vec3 rb = p.pb - p.b.x, ra = p.pa - p.a.x;
  double* gb = j.body_b != kGround ? &G(r, 6 * j.body_b) : nullptr;
  double* ga = j.body_a != kGround ? &G(r, 6 * j.body_a) : nullptr;
  if (ga && gb)
    writeRevolutePieces<true, true>(qa_t, qb_t, ra, rb, axis_b, p.fa, ga, gb, ld);
  else if (gb)
    writeRevolutePieces<false, true>(qa_t, qb_t, ra, rb, axis_b, p.fa, ga, gb, ld);
  else if (ga)
    writeRevolutePieces<true, false>(qa_t, qb_t, ra, rb, axis_b, p.fa, ga, gb, ld);
  // The linear parts: +-1 at the axis of a point row, 0 elsewhere (linear_axis).
  blk.linear_known = true;
  for (int i = 0; i < 3; ++i) {  // the anchors coincide
    blk.linear_axis[r - blk.row] = static_cast<signed char>(i);
    blk.error[r - blk.row] = p.dp.dot(Vec3::Unit(i));
    ++r;
  }
  for (int i = 1; i < 3; ++i) {  // the child's axis on the parent's
    blk.linear_axis[r - blk.row] = kLinearZero;
    blk.error[r - blk.row] = axis_b.dot(p.fa.e[i]);
    ++r;
  }
}

void appendRevoluteErrors(const Joint& j, const JointPlacement& p, ConstraintBlock& blk, int& r) {
  const Vec3 axis_b = p.b.q * j.axis_b;
  for (int i = 0; i < 3; ++i) blk.error[r++ - blk.row] = p.dp.dot(Vec3::Unit(i));
  for (int i = 1; i < 3; ++i) blk.error[r++ - blk.row] = axis_b.dot(p.fa.e[i]);
}

// Twist angle of the child about the joint axis, from the URDF zero, in (-pi, pi].
double revoluteAngle(const Joint& j, const BodyState& a, const BodyState& b) {
  Quat dev = (a.q.conjugate() * b.q) * j.rel_rot_zero.conjugate();
  if (dev.w() < 0) dev.coeffs() = -dev.coeffs();
  return 2.0 * std::atan2(dev.vec().dot(j.axis_a), dev.w());
}

double revoluteRate(const Joint& j, const BodyState& a, const BodyState& b) {
  return (b.q * b.w - a.q * a.w).dot(a.q * j.axis_a);
}

}  // namespace nscd
