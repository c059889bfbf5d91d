// Fuzz target: a friction-contact problem file (nscd::readProblemFile, what
// nscd_solve_problems and the solver tests read), then solved as
// nscd_solve_problems solves it, from the file's warm start and from zero, with a
// budget of 30 iterations. A bad file is refused with one line naming it; a file
// read is consistent (sizes, blocks inside the rows).
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_support.hpp"
#include "nscd_sim/friction_contact_solver.hpp"
#include "nscd_sim/problem_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = nscd_fuzz::scratchFile(data, size, ".txt");
  nscd::ProblemFile p;
  try {
    p = nscd::readProblemFile(path);
  } catch (const std::runtime_error& e) {
    nscd_fuzz::expectOneLine(e.what(), path);
    return 0;
  }
  const Eigen::Index m = p.b.size();
  if (p.W.rows() != m || p.W.cols() != m || p.P_start.size() != m || p.P.size() != m)
    nscd_fuzz::fail("a problem read with inconsistent sizes");
  for (const nscd::ProblemBlock& bl : p.blocks)
    if (bl.row < 0 || bl.size < 1 || bl.row + bl.size > m) nscd_fuzz::fail("a block outside the rows was read");
  static nscd::FrictionContactSolver solver;  // kept warm across inputs, as the tools keep it
  nscd::SolverOptions options;
  options.max_iterations = 30;
  for (const bool cold : {false, true}) {
    Eigen::VectorXd P = cold ? Eigen::VectorXd::Zero(m) : p.P_start;
    const nscd::SolverReport rep = solver.solve(p.W, p.b, p.blocks, options, P);
    if (rep.converged && !P.allFinite()) nscd_fuzz::fail("a converged answer that is not finite");
  }
  return 0;
}
