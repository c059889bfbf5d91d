// A parameter sweep: the Cartesian product of value lists, numbered run by run,
// cut into shards (run k belongs to shard k mod n), and its CSV merge.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace nscd::sweep {

struct SweepAxis {
  std::string key;
  std::vector<std::string> values;  // as written, so the CSV shows what was asked
};

// Parses "key=v1,v2,..." or "key=log:lo:hi:n" (n log-spaced values) or
// "key=lin:lo:hi:n". Throws std::invalid_argument.
SweepAxis parseAxis(const std::string& text);

// Number of runs of the grid (product of the axis sizes; 1 for no axis).
long gridSize(const std::vector<SweepAxis>& axes);
// The value index along each axis of run k (the last axis varies fastest).
std::vector<int> gridPoint(const std::vector<SweepAxis>& axes, long k);

// Parses "i/n" with 0 <= i < n. Throws std::invalid_argument.
void parseShard(const std::string& text, int& index, int& count);

// Reads CSV files written by nscd_sweep (same header; first column "run"),
// writes the header once and every row sorted by run. Returns the number of
// rows; reports duplicates and (with the "runs" column) missing runs on `log`.
// Throws std::runtime_error on unreadable files or mismatched headers.
long mergeCsv(const std::vector<std::string>& files, std::ostream& out, std::ostream& log);

}  // namespace nscd::sweep
