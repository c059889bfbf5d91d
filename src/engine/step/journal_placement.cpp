// Journal placement: a clearance joint's journal can start anywhere inside its
// bearing (<clearance initial_offset>), the polarisation before any load. The
// tree placement puts every journal on its bore's axis; this moves the bodies by
// the smallest displacement (mass metric) that puts each such journal's centre at
// its offset with the journal axis parallel to the bore. Closed loops make the
// offsets interact (a loop's offsets must add up), so the bodies also turn a
// little: Gauss-Newton on the offsets' residual, minimum-norm steps. The assembly
// projection runs afterwards and removes any penetration this creates.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "step_stages.hpp"

namespace nscd {
namespace {

constexpr int kPlacementIterations = 30;
constexpr double kPlacementTolerance = 1e-13;  // m (and rad for the axes)
constexpr double kStepTolerance = 1e-12;        // m and rad: the soft rows' fit is done
// Singular values below this fraction of the largest are zero: redundant rows (a
// loop's closure, the third component of a x n), not directions to move along.
constexpr double kRankThreshold = 1e-7;
constexpr double kProbe = 1e-6;                // finite-difference step, m and rad

// Residual of clearance joint c, 6 rows from `row` of r: journal centre - bore
// centre - target, and (journal axis x bore axis) times the bearing length (a tilt
// as a displacement at the rings; rank 2). Planar mode: the in-plane part of the
// first only (2 rows).
void jointResidual(const Model& m, const State& s, int c, const Vec3& target, bool planar, int row,
                   Eigen::VectorXd& r) {
  const ClearanceJoint& cj = m.clearance_joints[c];
  const Vec3 d = bodyPointWorld(s, cj.journal_body, cj.journal_center) -
                 bodyPointWorld(s, cj.bearing_body, cj.bearing_center) - target;
  if (planar) {
    r.segment<2>(row) = d.head<2>();
    return;
  }
  const Vec3 n = cj.bearing_body == kGround ? cj.bearing_axis : Vec3(s.bodies[cj.bearing_body].q * cj.bearing_axis);
  const Vec3 a = cj.journal_body == kGround ? cj.journal_axis : Vec3(s.bodies[cj.journal_body].q * cj.journal_axis);
  r.segment<3>(row) = d;
  r.segment<3>(row + 3) = cj.length * a.cross(n);
}

// The residuals of the placed joints (hard: their offsets) and of the others (soft:
// where the tree placement put them), stacked in that order.
struct PlacementRows {
  std::vector<int> joints;   // clearance joints, placed ones first
  std::vector<Vec3> target;  // their targets
  int hard = 0;              // rows of the placed joints
  int per = 6;               // rows per joint
  // Soft rows are divided by the joint's radial clearance (a fraction of it): a
  // stand-in joint with a huge clearance (the C-60's P3_axis) barely counts.
  void residual(const Model& m, const State& s, bool planar, Eigen::VectorXd& r) const {
    r.resize(per * static_cast<int>(joints.size()));
    for (size_t k = 0; k < joints.size(); ++k) {
      const int row = per * static_cast<int>(k);
      jointResidual(m, s, joints[k], target[k], planar, row, r);
      if (row >= hard) r.segment(row, per) /= m.clearance_joints[joints[k]].radial;
    }
  }
};

// Body `body` displaced along dof (0-2: translation, 3-5: rotation, world) by `step`.
void displace(State& s, int body, int dof, double step) {
  BodyState& b = s.bodies[body];
  if (dof < 3) {
    b.x[dof] += step;
  } else {
    Vec3 phi = Vec3::Zero();
    phi[dof - 3] = step;
    b.q = (expMap(phi) * b.q).normalized();
  }
}

Vec3 currentOffset(const Model& m, const State& s, int c) {
  const ClearanceJoint& cj = m.clearance_joints[c];
  return bodyPointWorld(s, cj.journal_body, cj.journal_center) - bodyPointWorld(s, cj.bearing_body, cj.bearing_center);
}

// The placed joints first, aimed at their offsets; then the others, aimed at where
// the tree placement put them.
PlacementRows placementRows(const Model& m, const State& s, bool planar) {
  PlacementRows rows;
  rows.per = planar ? 2 : 6;
  for (int pass = 0; pass < 2; ++pass)
    for (size_t c = 0; c < m.clearance_joints.size(); ++c)
      if (m.clearance_joints[c].has_initial_offset == (pass == 0)) {
        rows.joints.push_back(static_cast<int>(c));
        rows.target.push_back(pass == 0 ? m.clearance_joints[c].initial_offset : currentOffset(m, s, static_cast<int>(c)));
      }
  const int placed = static_cast<int>(std::count_if(m.clearance_joints.begin(), m.clearance_joints.end(),
                                                    [](const ClearanceJoint& cj) { return cj.has_initial_offset; }));
  rows.hard = rows.per * placed;
  return rows;
}

// dq = S y with S = M^-1/2: the minimum-norm y is the smallest displacement in the
// mass metric (a heavy body moves less). One entry per body and moved DOF.
Eigen::VectorXd massMetricScale(const Model& m, const State& s, const std::vector<int>& dofs) {
  const int nb = static_cast<int>(s.bodies.size());
  const int nd = static_cast<int>(dofs.size());
  Eigen::VectorXd scale(nb * nd);
  for (int b = 0; b < nb; ++b) {
    const Mat3 R = s.bodies[b].q.toRotationMatrix();
    const Mat3 Iw = R * m.bodies[b].inertia * R.transpose();
    for (int k = 0; k < nd; ++k)
      scale[b * nd + k] = std::sqrt(dofs[k] < 3 ? 1.0 / m.bodies[b].mass : 1.0 / Iw(dofs[k] - 3, dofs[k] - 3));
  }
  return scale;
}

// J = d(residual)/dy, by central differences: the rank decisions need clean columns.
void placementJacobian(const Model& m, const State& s, const PlacementRows& rows, bool planar,
                       const std::vector<int>& dofs, const Eigen::VectorXd& scale, int residual_rows,
                       Eigen::MatrixXd& J) {
  const int nb = static_cast<int>(s.bodies.size());
  const int nd = static_cast<int>(dofs.size());
  Eigen::VectorXd rp, rm;
  J.resize(residual_rows, nb * nd);
  for (int b = 0; b < nb; ++b)
    for (int k = 0; k < nd; ++k) {
      State sp = s, sm = s;
      displace(sp, b, dofs[k], kProbe);
      displace(sm, b, dofs[k], -kProbe);
      rows.residual(m, sp, planar, rp);
      rows.residual(m, sm, planar, rm);
      J.col(b * nd + k) = (rp - rm) / (2 * kProbe) * scale[b * nd + k];
    }
}

// One Gauss-Newton step y: the minimum-norm solution of the hard rows, corrected
// within their null space towards the soft rows' least squares.
Eigen::VectorXd placementStep(const Eigen::MatrixXd& J, const Eigen::VectorXd& r, int hard) {
  const int n = static_cast<int>(J.cols());
  const int soft = static_cast<int>(r.size()) - hard;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(J.topRows(hard), Eigen::ComputeFullV | Eigen::ComputeThinU);
  svd.setThreshold(kRankThreshold);
  Eigen::VectorXd y = -svd.solve(r.head(hard));
  const int rank = static_cast<int>(svd.rank());
  if (soft > 0 && rank < n) {
    const Eigen::MatrixXd N = svd.matrixV().rightCols(n - rank);
    const Eigen::MatrixXd C = J.bottomRows(soft) * N;
    const Eigen::VectorXd rs = r.tail(soft) + J.bottomRows(soft) * y;
    // Minimum-norm least squares: directions the soft rows do not see (a link
    // turning about its only joint) stay put. The cut is absolute (against the hard
    // rows' scale): a soft row that barely sees a direction must not drive it.
    Eigen::JacobiSVD<Eigen::MatrixXd> soft_svd(C, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const double cut = kRankThreshold * svd.singularValues()(0);
    if (soft_svd.singularValues().size() > 0 && soft_svd.singularValues()(0) > cut) {
      soft_svd.setThreshold(cut / soft_svd.singularValues()(0));
      y -= N * soft_svd.solve(rs);
    }
  }
  return y;
}

}  // namespace

// Each Gauss-Newton step is the smallest displacement (metric M) that meets the
// placed joints' rows exactly, and among those the one that best keeps the other
// joints' journals where they were (least squares in the null space of the hard
// rows): a link that no offset concerns follows the links it is jointed to.
void placeJournals(const Model& m, State& s) {
  const bool planar = m.settings.planar == PlanarMode::XY;
  const PlacementRows rows = placementRows(m, s, planar);
  if (rows.hard == 0) return;  // no joint has an initial offset
  const std::vector<int> dofs = planar ? std::vector<int>{0, 1, 5} : std::vector<int>{0, 1, 2, 3, 4, 5};
  const int nb = static_cast<int>(s.bodies.size());
  const int nd = static_cast<int>(dofs.size());
  const Eigen::VectorXd scale = massMetricScale(m, s, dofs);
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  double err = 0;
  for (int it = 0; it < kPlacementIterations; ++it) {
    rows.residual(m, s, planar, r);
    err = r.head(rows.hard).lpNorm<Eigen::Infinity>();
    placementJacobian(m, s, rows, planar, dofs, scale, static_cast<int>(r.size()), J);
    const Eigen::VectorXd dq = scale.cwiseProduct(placementStep(J, r, rows.hard));
    if (err < kPlacementTolerance && dq.lpNorm<Eigen::Infinity>() < kStepTolerance) return;
    for (int b = 0; b < nb; ++b)
      for (int k = 0; k < nd; ++k) displace(s, b, dofs[k], dq[b * nd + k]);
  }
  rows.residual(m, s, planar, r);
  err = r.head(rows.hard).lpNorm<Eigen::Infinity>();
  if (err < 1e-10) return;  // as close as round-off allows on this geometry
  throw std::runtime_error(m.source_file + ": assembly failed: the journals cannot be placed at " +
                           "their initial_offset (residual " + std::to_string(err) + " m after " +
                           std::to_string(kPlacementIterations) + " Gauss-Newton steps; axial offsets " +
                           "around a closed loop must add up to zero)");
}

}  // namespace nscd
