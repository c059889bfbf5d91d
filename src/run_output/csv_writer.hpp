// The CSV columns of nscd_run --csv (docs/interfaces.md): one row per recorded step.
// Shared by nscd_run and nscd_sweep --series (library nscd_run_output).
#pragma once

#include <cstdio>
#include <string>

#include "nscd_sim/simulator.hpp"

namespace nscd {

class CsvWriter {
 public:
  // Opens the file and writes the header. Throws std::runtime_error if it cannot.
  CsvWriter(const std::string& path, const Simulator& sim);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  void writeRow(const Simulator& sim);

 private:
  std::FILE* f_ = nullptr;
  bool adaptive_ = false;  // adaptive step control: the step columns h, error, rejected, extrapolated
};

}  // namespace nscd
