// A dense matrix stored as an FCLib matrix in compressed columns (nz = -1) or rows
// (nz = -2), its non-zero entries only: what nscd_fclib writes, and what the
// reader's test and the fuzz seeds write. Owns the arrays `matrix` points into.
#pragma once

extern "C" {
#include <fclib.h>
}

#include <vector>

#include <Eigen/Core>

namespace nscd_fclib {

struct CompressedMatrix {
  std::vector<int> pointers, indices;
  std::vector<double> values;
  fclib_matrix matrix{};

  CompressedMatrix(const Eigen::MatrixXd& D, int nz = -1) {
    const bool columns = nz == -1;
    const Eigen::Index outer = columns ? D.cols() : D.rows(), inner = columns ? D.rows() : D.cols();
    pointers.push_back(0);
    for (Eigen::Index o = 0; o < outer; ++o) {
      for (Eigen::Index k = 0; k < inner; ++k) {
        const double v = columns ? D(k, o) : D(o, k);
        if (v == 0) continue;
        indices.push_back(static_cast<int>(k));
        values.push_back(v);
      }
      pointers.push_back(static_cast<int>(values.size()));
    }
    matrix.nzmax = static_cast<int>(values.size());
    matrix.m = static_cast<int>(D.rows());
    matrix.n = static_cast<int>(D.cols());
    matrix.p = pointers.data();
    matrix.i = indices.data();
    matrix.x = values.data();
    matrix.nz = nz;
  }
  CompressedMatrix(const CompressedMatrix&) = delete;  // `matrix` points into this one's arrays
  CompressedMatrix& operator=(const CompressedMatrix&) = delete;
};

}  // namespace nscd_fclib
