// The least-distance problem min |y| s.t. A y >= c, by Lawson and Hanson's
// reduction to non-negative least squares (Solving Least Squares Problems, 1974,
// ch. 23): with E = [A^T; c^T] and f = e_(n+1), the NNLS solution u of
// min |E u - f|, u >= 0, gives the residual r = E u - f and y = -r_(1..n) / r_(n+1);
// r = 0 means the constraints are infeasible. NNLS is their finite active-set
// method. The projection uses it where its complementarity problem (the dual
// of this one) is too ill-conditioned for Gauss-Seidel: many rows on few
// degrees of freedom with masses 1e3 apart.
#include "least_distance.hpp"

#include <Eigen/QR>
#include <cmath>
#include <limits>
#include <vector>

namespace nscd {
namespace {

// Least squares on the columns `set` of E: z(set) = argmin |E_set z - f|.
void solveOnSet(const Eigen::MatrixXd& E, const Eigen::VectorXd& f, const std::vector<int>& set,
                Eigen::MatrixXd& Es, Eigen::VectorXd& z) {
  Es.resize(E.rows(), static_cast<Eigen::Index>(set.size()));
  for (size_t k = 0; k < set.size(); ++k) Es.col(static_cast<Eigen::Index>(k)) = E.col(set[k]);
  const Eigen::VectorXd zs = Es.completeOrthogonalDecomposition().solve(f);
  z.setZero();
  for (size_t k = 0; k < set.size(); ++k) z(set[k]) = zs(static_cast<Eigen::Index>(k));
}

}  // namespace

bool nonNegativeLeastSquares(const Eigen::MatrixXd& E, const Eigen::VectorXd& f, Eigen::VectorXd& x) {
  const int m = static_cast<int>(E.cols());
  x = Eigen::VectorXd::Zero(m);
  if (m == 0 || E.rows() == 0) return true;
  std::vector<char> in_set(m, 0);
  std::vector<int> set;
  Eigen::MatrixXd Es;
  Eigen::VectorXd z(m), w(m);
  const double tol = 10 * std::numeric_limits<double>::epsilon() * E.cwiseAbs().maxCoeff() * (m + 1);
  for (int outer = 0; outer < 3 * m + 10; ++outer) {
    w.noalias() = E.transpose() * (f - E * x);
    int t = -1;
    double best = tol;
    for (int j = 0; j < m; ++j)
      if (!in_set[j] && w(j) > best) {
        best = w(j);
        t = j;
      }
    if (t < 0) return true;  // Kuhn-Tucker conditions hold
    in_set[t] = 1;
    set.push_back(t);
    for (int inner = 0; inner < 3 * m + 10; ++inner) {
      solveOnSet(E, f, set, Es, z);
      bool positive = true;
      for (int j : set) positive = positive && z(j) > 0;
      if (positive) {
        x = z;
        break;
      }
      // Step from x towards z until a variable of the set reaches zero.
      double alpha = 1;
      for (int j : set)
        if (z(j) <= 0) alpha = std::min(alpha, x(j) / (x(j) - z(j)));
      x += alpha * (z - x);
      std::vector<int> keep;
      for (int j : set) {
        if (x(j) <= tol) {
          x(j) = 0;
          in_set[j] = 0;
        } else {
          keep.push_back(j);
        }
      }
      set.swap(keep);
      if (set.empty()) break;
    }
    if (!x.allFinite()) return false;
  }
  return false;  // iteration limit (not reached in exact arithmetic)
}

bool leastDistance(const Eigen::MatrixXd& A, const Eigen::VectorXd& c, Eigen::VectorXd& y) {
  const Eigen::Index r = A.rows(), n = A.cols();
  y = Eigen::VectorXd::Zero(n);
  if (r == 0 || c.maxCoeff() <= 0) return true;  // y = 0 is feasible
  Eigen::MatrixXd E(n + 1, r);
  E.topRows(n) = A.transpose();
  E.row(n) = c.transpose();
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n + 1);
  f(n) = 1;
  Eigen::VectorXd u;
  if (!nonNegativeLeastSquares(E, f, u)) return false;
  const Eigen::VectorXd res = E * u - f;
  if (!(std::abs(res(n)) > 1e-12)) return false;  // infeasible
  y = -res.head(n) / res(n);
  return y.allFinite();
}

}  // namespace nscd
