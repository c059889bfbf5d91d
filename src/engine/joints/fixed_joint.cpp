// The fixed joint: relative orientation locked (3 rows), anchors coincide (3 rows).
#include "joint_rows.hpp"

namespace nscd {

void appendFixedRows(const Joint& j, const State& s, const JointPlacement& p,
                     ConstraintBlock& blk, int& r, Eigen::MatrixXd& G) {
  appendOrientationLockRows(j, s, p, blk, r, G);
  appendPointRows(j, s, p, blk, r, G);
}

}  // namespace nscd
