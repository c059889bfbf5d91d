// An FCLib HDF5 problem read into dense matrices (nscd_fclib's input; the fuzz
// target fclib_reader reads through it too). Local problems (U = W r + q) as they
// are; global ones (M v = H r + f, U = H^T v + w) condensed to local ones. What
// FCLib hands back is checked before it is used: sizes that agree, indices inside
// the matrix, finite numbers, mu >= 0, M positive definite. Before FCLib opens
// the file, fclib_file_check.hpp checks it holds what FCLib will read (FCLib exits
// the process when an HDF5 call fails and trusts the file's size fields).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace nscd_fclib {

// A local problem: U = W r + q, contacts of `dim` rows (normal first).
struct LocalProblem {
  std::string name;
  int dim = 3;
  int contacts = 0;
  Eigen::MatrixXd W;
  Eigen::VectorXd q;
  std::vector<double> mu;
  bool bilateral_ignored = false;  // a local problem's V/R part, left out
};

// Dense matrices of more entries than this are refused (the tool works densely).
constexpr double kMaxDenseEntries = 1e8;

// Reads `path`; false with `error` ("what is wrong", without the path) if it holds
// no FCLib problem or one that cannot be used. `max_dense_entries` bounds every
// dense matrix made (rows x columns).
bool readFclibProblem(const char* path, LocalProblem& out, std::string& error,
                      double max_dense_entries = kMaxDenseEntries);

}  // namespace nscd_fclib
