// An nscd problem file's problem as a local FCLib one (nscd_fclib --from-nscd):
// U = W r + q with 3 rows per contact. Its bilateral rows are condensed out (Schur
// complement; a singular equality block by its pseudo-inverse) and a frictionless
// contact becomes a 3-row contact with mu = 0 and inert tangents. No FCLib here,
// so the fuzz targets reach it without HDF5.
#pragma once

#include <string>
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

// False, with the reason in `why`, if the problem has no contact (bilateral rows
// only: not an FCLib problem) or a block whose size is not its kind's (a frictional
// contact 3 rows, a frictionless one 1: what the solver takes; readProblemFile
// reads any size within the rows).
bool condenseProblem(const nscd::ProblemFile& p, CondensedProblem& out, std::string& why);

}  // namespace nscd_fclib
