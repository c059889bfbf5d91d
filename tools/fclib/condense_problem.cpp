// nscd problem -> local FCLib problem (condense_problem.hpp).
#include "condense_problem.hpp"

#include <string>

#include <Eigen/Dense>

namespace nscd_fclib {

bool condenseProblem(const nscd::ProblemFile& p, CondensedProblem& out, std::string& why) {
  for (const nscd::ProblemBlock& bl : p.blocks) {
    const int want = nscd::rowsOfKind(bl.kind);
    if (want > 0 && bl.size != want) {
      why = "a " + std::string(want == 3 ? "frictional" : "frictionless") + " block of " + std::to_string(bl.size) +
            " rows at row " + std::to_string(bl.row) + " (" + std::to_string(want) + " expected)";
      return false;
    }
  }
  std::vector<int> eq;  // bilateral rows
  for (const nscd::ProblemBlock& bl : p.blocks) {
    if (bl.kind == nscd::BlockKind::Bilateral)
      for (int i = bl.row; i < bl.row + bl.size; ++i) eq.push_back(i);
  }
  out.mu.clear();
  std::vector<int> rows;  // the local rows: 3 per contact (a frictionless one: its normal + 2 inert)
  for (const nscd::ProblemBlock& bl : p.blocks) {
    if (bl.kind == nscd::BlockKind::Bilateral) continue;
    out.mu.push_back(bl.kind == nscd::BlockKind::Frictional ? bl.mu : 0.0);
    rows.push_back(bl.row);
    rows.push_back(bl.kind == nscd::BlockKind::Frictional ? bl.row + 1 : -1);
    rows.push_back(bl.kind == nscd::BlockKind::Frictional ? bl.row + 2 : -1);
  }
  const int n = static_cast<int>(rows.size()), ne = static_cast<int>(eq.size());
  out.bilateral_rows = ne;
  if (n == 0) {
    why = "no contact (bilateral rows only): not an FCLib problem";
    return false;
  }
  Eigen::MatrixXd Wcc = Eigen::MatrixXd::Zero(n, n), Wce = Eigen::MatrixXd::Zero(n, ne),
                  Wee(ne, ne);
  Eigen::VectorXd qc = Eigen::VectorXd::Zero(n), qe(ne);
  for (int a = 0; a < n; ++a) {
    if (rows[a] < 0) {
      Wcc(a, a) = 1;  // an inert tangent: U_T = P_T, and mu = 0 keeps P_T = 0
      continue;
    }
    qc(a) = p.b(rows[a]);
    for (int c = 0; c < n; ++c)
      if (rows[c] >= 0) Wcc(a, c) = p.W(rows[a], rows[c]);
    for (int e = 0; e < ne; ++e) Wce(a, e) = p.W(rows[a], eq[e]);
  }
  for (int e = 0; e < ne; ++e) {
    qe(e) = p.b(eq[e]);
    for (int f = 0; f < ne; ++f) Wee(e, f) = p.W(eq[e], eq[f]);
  }
  out.W = Wcc;
  out.q = qc;
  if (ne > 0) {  // U_e = 0 eliminates P_e: P_e = -Wee^+ (Wec P_c + q_e)
    const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(Wee);
    out.W -= Wce * cod.solve(Wce.transpose());
    out.q -= Wce * cod.solve(qe);
    out.W = 0.5 * (out.W + out.W.transpose());
  }
  return true;
}

}  // namespace nscd_fclib
