// Friction-contact problems as text files: what `nscd_run --dump-problems` writes
// and the solver studies read (format in docs/interfaces.md, "Problem files").
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "nscd_sim/friction_contact_solver.hpp"
#include "nscd_sim/simulator.hpp"

namespace nscd {

// One problem read back: U = W P + b over blocks, with the run's warm start,
// its answer and how the run's solve ended.
struct ProblemFile {
  double t = 0;
  int round = 0;
  Eigen::MatrixXd W;
  Eigen::VectorXd b;
  std::vector<ProblemBlock> blocks;
  Eigen::VectorXd P_start;
  Eigen::VectorXd P;
  double residual = 0;
  bool converged = false;
  int iterations = 0;
};

// Writes the problem a ProblemObserver was shown; throws std::runtime_error if
// the file cannot be written.
void writeProblemFile(const std::string& path, const ProblemView& view);
// Reads one back; throws std::runtime_error with the file and what is wrong.
ProblemFile readProblemFile(const std::string& path);

}  // namespace nscd
