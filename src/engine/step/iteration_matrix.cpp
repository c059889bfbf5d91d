// Stage 1b: the Moreau-Jean iteration matrix. Springs and PD actuators are
// implicit: A = M - h theta C - h^2 theta^2 K (C = dF/dv, K = dF/dq, symmetric
// parts), rhs = h F + h^2 theta (K v_k + K_skew_v) (the skew part of K, of body-fixed
// loads, explicit), and Ŵ = A^-1 maps impulses to velocity changes. Without such
// elements A = M and Ŵ = M^-1, computed once at set-up.
#include <cmath>

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

namespace {

// The inverse of a small SPD matrix (its leading n x n block) from its Cholesky
// factor, A = L Lᵀ, A⁻¹ = L⁻ᵀ L⁻¹: plain loops, where Eigen's dynamic-size LLT and
// triangular solves spent most of their time setting up on 6 x 6 and 12 x 12
// blocks. A gets L (lower triangle), then A⁻¹; Li gets L⁻¹. False (A not positive
// definite, as Eigen's LLT would say) leaves A partly factored.
bool spdInverse(Eigen::MatrixXd& A, Eigen::MatrixXd& Li, int n) {
  for (int j = 0; j < n; ++j) {
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= A(j, k) * A(j, k);
    if (!(d > 0)) return false;
    const double ljj = std::sqrt(d);
    A(j, j) = ljj;
    for (int i = j + 1; i < n; ++i) {
      double sum = A(i, j);
      for (int k = 0; k < j; ++k) sum -= A(i, k) * A(j, k);
      A(i, j) = sum / ljj;
    }
  }
  for (int c = 0; c < n; ++c) {
    Li(c, c) = 1.0 / A(c, c);
    for (int i = c + 1; i < n; ++i) {
      double sum = 0;
      for (int k = c; k < i; ++k) sum += A(i, k) * Li(k, c);
      Li(i, c) = -sum / A(i, i);
    }
  }
  for (int j = 0; j < n; ++j)
    for (int i = j; i < n; ++i) {
      double sum = 0;
      for (int k = i; k < n; ++k) sum += Li(k, i) * Li(k, j);
      A(i, j) = sum;
      A(j, i) = sum;
    }
  return true;
}

// inv = A⁻¹ for a stiff group's block A (overwritten). A DOF whose row and column
// of A are zero off the diagonal (a body's translation, which a torsion spring or a
// PD actuator on a revolute joint leaves to M) is its own 1 x 1 block; spdInverse
// runs on the others only, gathered in order into A's leading block. The answer
// is the full factorisation's: the terms the gathering drops are exact zeros
// (x - 0 * y = x), and the lone DOF's entry is the same (1 / sqrt(a))^2.
// dofs: scratch of A's size.
bool groupInverse(Eigen::MatrixXd& A, Eigen::MatrixXd& Li, std::vector<int>& dofs,
                  Eigen::MatrixXd& inv) {
  const int n = static_cast<int>(A.rows());
  inv.setZero();
  int nc = 0;
  for (int i = 0; i < n; ++i) {
    bool coupled = false;
    for (int j = 0; j < n && !coupled; ++j) coupled = j != i && (A(i, j) != 0 || A(j, i) != 0);
    if (coupled) {
      dofs[nc++] = i;
      continue;
    }
    if (!(A(i, i) > 0)) return false;
    const double li = 1.0 / std::sqrt(A(i, i));
    inv(i, i) = li * li;
  }
  // In place: entry (a, b) comes from (dofs[a], dofs[b]), never before it in
  // column-major order, and no later source is written first (dofs ascends).
  for (int b = 0; b < nc; ++b)
    for (int a = 0; a < nc; ++a) A(a, b) = A(dofs[a], dofs[b]);
  if (!spdInverse(A, Li, nc)) return false;
  for (int b = 0; b < nc; ++b)
    for (int a = 0; a < nc; ++a) inv(dofs[a], dofs[b]) = A(a, b);
  return true;
}

// rhs += h^2 theta (K v_k + K_skew_v). K is nonzero only within the stiff groups
// (forces.cpp). Its skew part (springs with body-fixed loads) enters the rhs only,
// explicitly: A must stay SPD.
void addStiffnessImpulse(double h, double theta, StepWorkspace& ws) {
  for (const std::vector<int>& g : ws.facts.stiff_groups)
    for (int br : g) {
      for (int bc : g)
        ws.rhs.segment<6>(6 * br).noalias() +=
            (h * h * theta) * (ws.K.block<6, 6>(6 * br, 6 * bc) * ws.vk.segment<6>(6 * bc));
      ws.rhs.segment<6>(6 * br) += (h * h * theta) * ws.K_skew_v.segment<6>(6 * br);
    }
}

// Ag = M - h theta C - h^2 theta^2 K over the bodies of one stiff group, in the
// group's own numbering (6 rows and columns per body, in the order of `bodies`).
void fillGroupIterationMatrix(const Model& m, double h, double theta, const std::vector<int>& bodies,
                              const StepWorkspace& ws, Eigen::MatrixXd& Ag) {
  const int k = static_cast<int>(bodies.size());
  for (int bc = 0; bc < k; ++bc)
    for (int br = 0; br < k; ++br) {
      const int r0 = 6 * bodies[br], c0 = 6 * bodies[bc];
      for (int c = 0; c < 6; ++c)
        for (int r = 0; r < 6; ++r) {
          double base = 0;
          if (br == bc) {
            const Body& body = m.bodies[bodies[br]];
            if (r < 3 && c < 3) base = r == c ? body.mass : 0.0;
            else if (r >= 3 && c >= 3) base = body.inertia(r - 3, c - 3);
          }
          Ag(6 * br + r, 6 * bc + c) = base - h * theta * ws.C(r0 + r, c0 + c) -
                                       h * h * theta * theta * ws.K(r0 + r, c0 + c);
        }
    }
}

// Without the planar projection: C and K couple only the bodies of a stiff group,
// so A is block-diagonal over the groups, and every other body's block is M's: Ŵ
// is M^-1 there (set up once, never written) and each group's block of A is
// inverted on its own. False when a group's block is not positive definite.
bool invertStiffGroups(const Model& m, double h, double theta, StepWorkspace& ws) {
  const std::vector<std::vector<int>>& groups = ws.facts.stiff_groups;
  for (size_t g = 0; g < groups.size(); ++g) {
    const std::vector<int>& bodies = groups[g];
    Eigen::MatrixXd& Ag = ws.group_A[g];
    fillGroupIterationMatrix(m, h, theta, bodies, ws, Ag);
    Eigen::MatrixXd& inv = ws.group_inverse[g];
    if (!groupInverse(Ag, ws.group_factor_inverse[g], ws.group_dofs, inv)) return false;
    const int k = static_cast<int>(bodies.size());
    for (int bc = 0; bc < k; ++bc)
      for (int br = 0; br < k; ++br)
        ws.iteration_inverse.block<6, 6>(6 * bodies[br], 6 * bodies[bc]) =
            inv.block<6, 6>(6 * br, 6 * bc);
  }
  return true;
}

// With the planar projection the whole of A is built and inverted on the basis
// of the in-plane motions. False when it is not positive definite.
bool invertPlanarIterationMatrix(const Model& m, double h, double theta, StepWorkspace& ws) {
  const int n = ws.n;
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
  return reducedInverse(ws.A, ws, ws.iteration_inverse);
}

}  // namespace

void buildIterationMatrix(const Model& m, double h, StepWorkspace& ws, StepStats& st) {
  const double theta = m.settings.theta;
  ws.rhs.noalias() = h * ws.F;
  if (!ws.facts.stiff) return;
  addStiffnessImpulse(h, theta, ws);
  const bool inverted = ws.facts.planar ? invertPlanarIterationMatrix(m, h, theta, ws)
                                        : invertStiffGroups(m, h, theta, ws);
  if (!inverted) {
    // Not positive definite (a spring stiffer than the step can carry implicitly):
    // the step treats the elements explicitly.
    ws.iteration_inverse = ws.mass_inverse;
    st.iteration_matrix_fallback = true;
  }
}

void addIterationInverseTimes(const StepWorkspace& ws, const Eigen::VectorXd& x,
                              Eigen::VectorXd& y) {
  // Ŵ couples a body only with those of its stiff group: its 6 x 6 blocks there.
  for (int b = 0; b < ws.nbodies; ++b)
    for (int c : ws.facts.coupled[b])
      y.segment<6>(6 * c).noalias() += ws.iteration_inverse.block<6, 6>(6 * c, 6 * b) * x.segment<6>(6 * b);
}

}  // namespace nscd
