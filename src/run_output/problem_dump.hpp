// Which friction-contact solves of a run are written as problem files
// (nscd_run --dump-problems/--dump-when, nscd_stress likewise) and their names:
// docs/interfaces.md, "Problem files".
#pragma once

#include <cstdint>
#include <string>

#include "nscd_sim/simulator.hpp"

namespace nscd {

class ProblemDump {
 public:
  // when: "unconverged", "all", a step count N (every Nth step), or
  // "stage=NAME[,NAME...]" (the solves those stages finished, SolverReport::stage:
  // solverStageName). prefix: put before each file name. Throws
  // std::invalid_argument saying what is wrong with `when`.
  ProblemDump(std::string dir, const std::string& when, std::string prefix = "");
  // Writes the problem of a solve of step `step` (1-based) if it is chosen:
  // DIR/PREFIXstepNNNNNNNN_rR.txt, a substep's ..._hH_sS_rR.txt, a rescue's with
  // _KIND before .txt. Throws std::runtime_error if the file cannot be written.
  void write(const ProblemView& v, long step);
  int written() const { return written_; }

 private:
  std::string dir_, prefix_;
  long every_ = 0;            // 0: by convergence or stage
  std::uint32_t stages_ = 0;  // bit s: SolverStage s chosen (0: unconverged solves)
  int written_ = 0;
};

}  // namespace nscd
