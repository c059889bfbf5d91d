// Fuzz target: the input of nscd_fclib --from-nscd, a problem file condensed into
// a local FCLib problem (tools/fclib/condense_problem.cpp; the HDF5 writing that
// follows needs FCLib, docs/fuzzing.md). A file read is condensed without a crash
// into a square problem of 3 rows per contact, one mu each.
#include <cstdint>

#include "condense_problem.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nscd::ProblemFile p;
  if (!nscd_fuzz::readProblemInput(data, size, p)) return 0;
  nscd_fclib::CondensedProblem c;
  if (!nscd_fclib::condenseProblem(p, c)) return 0;  // bilateral rows only: refused
  const Eigen::Index n = c.q.size();
  if (c.W.rows() != n || c.W.cols() != n || n != 3 * static_cast<Eigen::Index>(c.mu.size()))
    nscd_fuzz::fail("a condensed problem of inconsistent sizes");
  return 0;
}
