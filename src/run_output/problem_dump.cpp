#include "problem_dump.hpp"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "nscd_sim/problem_file.hpp"

namespace nscd {
namespace {

// The bits of the stages named in "a,b,c".
std::uint32_t stageBits(const std::string& names) {
  std::uint32_t bits = 0;
  size_t from = 0;
  while (from <= names.size()) {
    const size_t comma = std::min(names.find(',', from), names.size());
    const std::string name = names.substr(from, comma - from);
    int s = 0;
    while (s < kSolverStageCount && name != solverStageName(static_cast<SolverStage>(s))) ++s;
    if (s == kSolverStageCount) throw std::invalid_argument("no solver stage '" + name + "' (docs/solver.md)");
    bits |= 1u << s;
    from = comma + 1;
  }
  return bits;
}

}  // namespace

ProblemDump::ProblemDump(std::string dir, const std::string& when, std::string prefix)
    : dir_(std::move(dir)), prefix_(std::move(prefix)) {
  if (when == "unconverged") return;
  if (when == "all") {
    every_ = 1;
  } else if (when.rfind("stage=", 0) == 0) {
    stages_ = stageBits(when.substr(6));
  } else {
    char* end = nullptr;
    every_ = std::strtol(when.c_str(), &end, 10);
    if (end == when.c_str() || *end != 0 || every_ < 1)
      throw std::invalid_argument(when + ": expected unconverged, all, a step count N >= 1 or stage=NAME,...");
  }
}

void ProblemDump::write(const ProblemView& v, long step) {
  const bool chosen = every_ > 0 ? (step - 1) % every_ == 0
                      : stages_ ? (stages_ >> static_cast<int>(v.report.stage) & 1) != 0
                                : !v.report.converged;
  if (!chosen) return;
  char name[96];
  // A rescue's re-solve is named after it: stepN_rR_plastic.txt.
  const char* sep = v.resolve ? "_" : "";
  const char* kind = v.resolve ? v.resolve : "";
  if (v.halvings == 0)
    std::snprintf(name, sizeof name, "/step%08ld_r%d%s%s.txt", step, v.round, sep, kind);
  else  // a substep of the step taken in halves (Settings::max_step_halvings)
    std::snprintf(name, sizeof name, "/step%08ld_h%d_s%d_r%d%s%s.txt", step, v.halvings, v.substep, v.round, sep,
                  kind);
  writeProblemFile(dir_ + "/" + prefix_ + (name + 1), v);
  ++written_;
}

}  // namespace nscd
