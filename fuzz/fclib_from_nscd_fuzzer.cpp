// Fuzz target: the input of nscd_fclib --from-nscd, a problem file condensed into
// a local FCLib problem (tools/fclib/condense_problem.cpp; the HDF5 writing that
// follows needs FCLib, docs/fuzzing.md). A file read is condensed without a crash
// into a square problem of 3 rows per contact, one mu each, or refused with a reason
// (no contact; a block whose size is not its kind's).
#include <cstdint>
#include <string>

#include "condense_problem.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nscd::ProblemFile p;
  if (!nscd_fuzz::readProblemInput(data, size, p)) return 0;
  nscd_fclib::CondensedProblem c;
  std::string why;
  if (!nscd_fclib::condenseProblem(p, c, why)) {
    if (why.empty() || why.find('\n') != std::string::npos) nscd_fuzz::fail("a refusal without a one-line reason");
    return 0;
  }
  const Eigen::Index n = c.q.size();
  if (c.W.rows() != n || c.W.cols() != n || n != 3 * static_cast<Eigen::Index>(c.mu.size()))
    nscd_fuzz::fail("a condensed problem of inconsistent sizes");
  return 0;
}
