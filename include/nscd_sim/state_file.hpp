// A Simulator's State as a text file: what `nscd_run --initial-state/--save-state`
// and the Python module's Simulator.save_state()/load_state() read and write
// (format in docs/interfaces.md, "State files"). Every number is a hex float, so
// a state reads back bit for bit and a run continued from it is the run that
// wrote it. The file names the model it belongs to (the counts and a hash of the
// names of its bodies, joints, clearance joints, contacts and actuators): a state
// of another scene is refused, a damaged or truncated file too.
#pragma once

#include <stdexcept>
#include <string>

#include "nscd_sim/simulator.hpp"

namespace nscd {

// A state file that cannot be read or does not fit the scene: "FILE:LINE: what"
// (or "FILE: what" when no line is to blame).
class StateFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The model's identity as far as a State is concerned: 16 hex digits of a 64-bit
// FNV-1a hash of the names of its bodies, joints, clearance joints, contacts and
// actuators, in order. Settings, masses and geometry are not in it: a state may be
// continued with another dt, friction or step control on purpose.
std::string stateFingerprint(const Model& model);

// The line a state file ends with, for the text above it: "checksum " and 16 hex
// digits of a 64-bit FNV-1a hash of the text, and a newline (tools that edit a state
// file on purpose, tests, the fuzz target, write it again with this).
std::string stateChecksumLine(const std::string& text);

// Writes sim.state() to `path` (`note`: a comment line, e.g. the command that made
// it). Throws StateFileError if the file cannot be written.
void writeStateFile(const std::string& path, const Simulator& sim, const std::string& note = "");

// Reads a state file written for sim's model; checks its format, checksum, model,
// sizes and values (finite, unit quaternions, step_next/step_error >= 0, ring
// hints finite or NaN). Throws StateFileError. Does not change sim.
State readStateFile(const std::string& path, const Simulator& sim);

// readStateFile, then sim.setState: the run continues from the file's state.
void loadStateFile(const std::string& path, Simulator& sim);

}  // namespace nscd
