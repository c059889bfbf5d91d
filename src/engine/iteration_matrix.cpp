// Stage 1b: the Moreau-Jean iteration matrix. Springs and PD actuators are
// implicit: A = M - h theta C - h^2 theta^2 K (C = dF/dv, K = dF/dq, symmetric
// parts), rhs = h F + h^2 theta K v_k, and Ŵ = A^-1 maps impulses to velocity
// changes. Without such elements A = M and Ŵ = M^-1, computed once at set-up.
#include "step_stages.hpp"

namespace nscd {

bool reducedInverse(const Eigen::MatrixXd& A, StepWorkspace& ws, Eigen::MatrixXd& out) {
  if (!ws.facts.planar) {
    ws.llt.compute(A);
    if (ws.llt.info() != Eigen::Success) return false;
    out.setIdentity();
    ws.llt.solveInPlace(out);
    return true;
  }
  ws.AB.noalias() = A * ws.basis;
  ws.red.noalias() = ws.basis.transpose() * ws.AB;
  ws.llt.compute(ws.red);
  if (ws.llt.info() != Eigen::Success) return false;
  ws.BT = ws.basis.transpose();
  ws.llt.solveInPlace(ws.BT);
  out.noalias() = ws.basis * ws.BT;
  return true;
}

void buildIterationMatrix(const Model& m, double h, StepWorkspace& ws, StepStats& st) {
  const double theta = m.settings.theta;
  const int n = ws.n;
  ws.rhs.noalias() = h * ws.F;
  if (!ws.facts.stiff) return;
  for (int i = 0; i < ws.nbodies; ++i) {
    ws.A.block<6, 6>(6 * i, 6 * i).setZero();
    ws.A.block<3, 3>(6 * i, 6 * i) = m.bodies[i].mass * Mat3::Identity();
    ws.A.block<3, 3>(6 * i + 3, 6 * i + 3) = m.bodies[i].inertia;
  }
  // A = M - h theta C - h^2 theta^2 K   (off-diagonal blocks come from C, K only)
  for (int c = 0; c < n; ++c)
    for (int r = 0; r < n; ++r) {
      const bool diag_block = (r / 6) == (c / 6);
      const double base = diag_block ? ws.A(r, c) : 0.0;
      ws.A(r, c) = base - h * theta * ws.C(r, c) - h * h * theta * theta * ws.K(r, c);
    }
  ws.rhs.noalias() += (h * h * theta) * ws.K * ws.vk;
  if (!reducedInverse(ws.A, ws, ws.iteration_inverse)) {
    // Not positive definite (a spring stiffer than the step can carry implicitly):
    // the step treats the elements explicitly.
    ws.iteration_inverse = ws.mass_inverse;
    st.iteration_matrix_fallback = true;
  }
}

}  // namespace nscd
