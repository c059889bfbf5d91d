// The Alart-Curnier function of the friction-contact problem, written once for
// the local 3x3 solver (local_contact_solver.cpp) and the global Newton
// (global_newton.cpp). For one frictional contact, with the normal row first:
//   phi_N = P_N - max(0, P_N - rhoN U_N)
//   phi_T = P_T - proj_{disc of radius mu max(0, P_N - rhoN U_N)}(P_T - rhoT U_T)
// zero exactly where (U, P) obey Coulomb's law.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "nscd_sim/friction_contact_solver.hpp"

namespace nscd {

// phi at (P, U); with A and B, one element of the generalised Jacobian:
// A = dphi/dP, B = dphi/dU.
void alartCurnierContact(const Eigen::Vector3d& P, const Eigen::Vector3d& U, double mu,
                         double rhoN, double rhoT, Eigen::Vector3d& phi, Eigen::Matrix3d* A,
                         Eigen::Matrix3d* B);

// The function of the whole problem, phi(P) with U = W P + b given; returns
// 0.5 |phi|^2. rho: per-row scaling 1/W(i, i) (frictional tangents: 1/mean of
// the two). zeroRow: P_i = 0 (its row of phi is P_i).
double acResidual(const std::vector<ProblemBlock>& blocks, const double* P, const double* U,
                  const double* rho, const char* zeroRow, double* phi);

// J = A + B (W + delta diag(W)) at the current P, U: one element of the
// generalised Jacobian of the problem with W regularised (nonsingular on
// hyperstatic sets, and the same roots). J: the top-left m x m of the storage.
void acJacobian(const Eigen::Ref<const Eigen::MatrixXd>& W, const std::vector<ProblemBlock>& blocks,
                const double* P, const double* U, const double* rho, const char* zeroRow,
                double delta, Eigen::Ref<Eigen::MatrixXd> J);

}  // namespace nscd
