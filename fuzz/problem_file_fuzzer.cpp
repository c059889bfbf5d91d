// Fuzz target: a friction-contact problem file (nscd::readProblemFile, what
// nscd_solve_problems and the solver tests read), then solved as
// nscd_solve_problems solves it, from the file's warm start and from zero, with a
// budget of 30 iterations. A bad file is refused with one line naming it; a file
// read is consistent (fuzz_support's readProblemInput).
#include <cstdint>

#include "fuzz_support.hpp"
#include "nscd_sim/friction_contact_solver.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nscd::ProblemFile p;
  if (!nscd_fuzz::readProblemInput(data, size, p)) return 0;
  static nscd::FrictionContactSolver solver;  // kept warm across inputs, as the tools keep it
  nscd::SolverOptions options;
  options.max_iterations = 30;
  const Eigen::Index m = p.b.size();
  for (const bool cold : {false, true}) {
    Eigen::VectorXd P = cold ? Eigen::VectorXd::Zero(m) : p.P_start;
    const nscd::SolverReport rep = solver.solve(p.W, p.b, p.blocks, options, P);
    if (rep.converged && !P.allFinite()) nscd_fuzz::fail("a converged answer that is not finite");
  }
  return 0;
}
