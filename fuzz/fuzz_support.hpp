// What the fuzz targets share: the repository's files, a scratch file for the
// readers that take a path, and the oracles (a bad input gets one line, a step
// never hands out a non-finite figure). A failed oracle aborts: libFuzzer keeps
// the input as a crash.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "nscd_sim/model.hpp"
#include "nscd_sim/problem_file.hpp"
#include "nscd_sim/simulator.hpp"

namespace nscd_fuzz {

// A file of the repository (NSCD_SOURCE_DIR); aborts if it cannot be read.
std::string repoFile(const std::string& relative_path);

// Writes the bytes to this process's scratch file (its name ends in `suffix`)
// and returns its path: the same path on every call with the same suffix.
std::string scratchFile(const uint8_t* data, size_t size, const std::string& suffix);

// Aborts with "nscd fuzz oracle: WHAT".
[[noreturn]] void fail(const std::string& what);

// A refusal's message: not empty, one line, starting with `prefix`.
void expectOneLine(const std::string& message, const std::string& prefix);

// The input as a problem file (what problem_file and fclib_from_nscd read): false
// when readProblemFile refuses it (with one line naming the file, else aborts);
// a problem read must be consistent (W square, b, P_start and P of its rows,
// every block inside the rows), else aborts.
bool readProblemInput(const uint8_t* data, size_t size, nscd::ProblemFile& problem);

// The input's lines (without their '\n').
std::vector<std::string> lines(const uint8_t* data, size_t size);

// Whether the settings' budgets keep a step short enough to fuzz (max_iterations
// and projection_max_iterations <= 1000, max_step_halvings <= 4): a user may set
// 10^7 iterations and wait, a fuzz target may not.
bool boundedBudget(const nscd::Settings& settings);
// Lowers the budgets to those bounds (for a target that fuzzes something else, the
// scene loader, and steps what it loads only to check it).
void boundBudget(nscd::Settings& settings);

// Steps a loaded model: builds the Simulator (an assembly failure is a refusal
// with one line), then up to `steps` steps; after every step that is not reported
// NonFinite, the state, energies, contact reports and every key figure must be
// finite (but a named contact's gap, +inf when its shapes have no point to measure).
// `on_step(k, sim)` runs before step k (commands); may be empty.
// After step k of `sim` (not reported NonFinite): the state, energies, contact
// reports and every key figure are finite (a named contact's gap may be +inf),
// else aborts. `figures` is scratch space kept across calls.
void checkStepOutputs(const nscd::Simulator& sim, int k, std::vector<double>& figures);

struct SteppingCommand {
  int step = 0;  // before this step
  int actuator = 0;
  double value = 0;
};
// stop_when_unsolved: no step after one left unsolved (its checks done), whose
// next steps would only repeat its work.
void stepAndCheck(nscd::Model model, int steps, const std::vector<SteppingCommand>& commands = {},
                  const std::vector<std::string>& schedules = {}, const std::vector<int>& resets = {},
                  bool stop_when_unsolved = false);

}  // namespace nscd_fuzz
