// Least-distance and non-negative least-squares problems (small, dense), for the
// projection's fallback (projection.cpp).
#pragma once

#include <Eigen/Dense>

namespace nscd {

// min |E x - f| over x >= 0 (Lawson-Hanson). False if it did not terminate.
bool nonNegativeLeastSquares(const Eigen::MatrixXd& E, const Eigen::VectorXd& f, Eigen::VectorXd& x);

// min |y| over A y >= c. False if infeasible (or not solved); y = 0 then.
bool leastDistance(const Eigen::MatrixXd& A, const Eigen::VectorXd& c, Eigen::VectorXd& y);

}  // namespace nscd
