// A primal-dual interior-point method for the convex cone quadratic program
//   minimise 1/2 y^T Q y + q^T y   over y in K,
// Q symmetric positive semidefinite (singular allowed), K a product of blocks:
// 3-dimensional second-order cones {y0 >= |(y1, y2)|}, half-lines {y >= 0} and
// free rows. Nesterov-Todd scaling, Mehrotra's predictor-corrector, dense
// (LU of the n x n scaled system per iteration). Used by the cone fixed point
// (cone_fixed_point.cpp) on the problems the Newton stages leave unsolved: an
// interior-point method does not care that Q is singular or that its nonzero
// eigenvalues spread over ten decades. Internal to the engine.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace nscd {

struct ConeBlock {
  enum Kind { SecondOrder, HalfLine, Free } kind = SecondOrder;
  int row = 0;   // first row
  int size = 3;  // 3 for SecondOrder, 1 for HalfLine, any for Free
};

// Buffers, grown to the largest problem seen, never shrunk.
struct ConeQpBuffers {
  int maxRows = 0;
  Eigen::MatrixXd Qs, K;  // the scaled Q; the Newton system, LU in place
  Eigen::VectorXd qs, y, z, rd, lam, dvec, rhs, dy, dz, dya, dza, rc, ylast, zlast;
  std::vector<int> piv;
  std::vector<Eigen::Matrix3d> W, Winv;  // Nesterov-Todd scaling, per cone block
};

struct ConeQpReport {
  int iterations = 0;
  bool converged = false;  // residual and gap within the tolerances below
};

// Solves the problem of the top-left n x n of Q and the head of q, with Q's
// diagonal raised by 1e-8 of its largest entry (a Tikhonov term: the answer is
// unique and bounded even where the optimal set is not; see the .cpp); y: out (n).
// Tolerances are relative to the problem scaled to a unit largest diagonal of Q
// and a unit largest |q_i|: dual residual 1e-11 (1 + |q|), gap 1e-13 (1 + |q^T y|).
// A non-finite iterate or a failed factorisation ends it at the last good iterate.
ConeQpReport solveConeQp(const Eigen::Ref<const Eigen::MatrixXd>& Q,
                         const Eigen::Ref<const Eigen::VectorXd>& q,
                         const std::vector<ConeBlock>& blocks, int n, ConeQpBuffers& qp,
                         Eigen::Ref<Eigen::VectorXd> y);

}  // namespace nscd
