// An nscd problem file's problem as a local FCLib one (nscd_fclib --from-nscd):
// U = W r + q with 3 rows per contact. Its bilateral rows are condensed out (Schur
// complement; a singular equality block by its pseudo-inverse) and a frictionless
// contact becomes a 3-row contact with mu = 0 and inert tangents. No FCLib here,
// so the fuzz targets reach it without HDF5.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "nscd_sim/problem_file.hpp"

namespace nscd_fclib {

struct CondensedProblem {
  Eigen::MatrixXd W;
  Eigen::VectorXd q;
  std::vector<double> mu;  // per contact
  int bilateral_rows = 0;  // condensed out
};

// False if the problem has no contact (bilateral rows only): not an FCLib problem.
bool condenseProblem(const nscd::ProblemFile& p, CondensedProblem& out);

}  // namespace nscd_fclib
