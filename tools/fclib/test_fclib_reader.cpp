// nscd_fclib's reader of FCLib files (read_fclib_problem.hpp, fclib_file_check.hpp):
// the repository's problems read; a global problem condensed to W = H^T M^-1 H,
// q = H^T M^-1 f + w; compressed rows and triplets read as the dense matrix they
// store; every bad file (the fuzz target's findings in fuzz/regressions/fclib_reader,
// indices outside the matrix, a negative mu, files that are no FCLib problem)
// refused with one line, never an exit or an out-of-bounds read.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "compressed_matrix.hpp"
#include "read_fclib_problem.hpp"

namespace {

namespace fs = std::filesystem;
using nscd_fclib::CompressedMatrix;
using nscd_fclib::LocalProblem;

std::string scratch(const std::string& name) {
  return fs::temp_directory_path().string() + "/nscd_test_fclib_" + std::to_string(getpid()) + "_" + name;
}

bool writeLocal(const std::string& path, fclib_matrix* W, std::vector<double> q, std::vector<double> mu, int dim) {
  std::remove(path.c_str());  // FCLib adds to an existing file
  fclib_local l{};
  l.W = W;
  l.q = q.data();
  l.mu = mu.data();
  l.spacedim = dim;
  return fclib_write_local(&l, path.c_str()) == 1;
}

::testing::AssertionResult refusedWithOneLine(const std::string& path) {
  LocalProblem p;
  std::string error;
  if (nscd_fclib::readFclibProblem(path.c_str(), p, error))
    return ::testing::AssertionFailure() << path << " was read";
  if (error.empty() || error.find('\n') != std::string::npos)
    return ::testing::AssertionFailure() << path << ": message [" << error << "]";
  return ::testing::AssertionSuccess() << error;
}

}  // namespace

TEST(FclibReader, RepositoryProblemsRead) {
  int files = 0;
  for (const char* dir : {"tools/fclib/problems", "tools/fclib/c60_hard"}) {
    for (const fs::directory_entry& e : fs::directory_iterator(std::string(NSCD_SOURCE_DIR) + "/" + dir)) {
      if (e.path().extension() != ".hdf5") continue;
      SCOPED_TRACE(e.path().string());
      LocalProblem p;
      std::string error;
      ASSERT_TRUE(nscd_fclib::readFclibProblem(e.path().c_str(), p, error)) << error;
      EXPECT_EQ(p.dim, 3);
      EXPECT_GT(p.contacts, 0);
      EXPECT_EQ(p.W.rows(), 3 * p.contacts);
      EXPECT_EQ(p.W.cols(), p.W.rows());
      EXPECT_EQ(p.q.size(), p.W.rows());
      EXPECT_EQ(static_cast<int>(p.mu.size()), p.contacts);
      EXPECT_TRUE(p.W.allFinite() && p.q.allFinite());
      EXPECT_GT(p.W.diagonal().minCoeff(), 0.0) << "a Delassus matrix has a positive diagonal";
      ++files;
    }
  }
  EXPECT_GE(files, 13);
}

// M v = H r + f, U = H^T v + w on 2 contacts (6 velocities): W and q as the
// condensation's closed form, to rounding.
TEST(FclibReader, GlobalProblemIsCondensed) {
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(6, 6), H = Eigen::MatrixXd::Zero(6, 6);
  for (int k = 0; k < 6; ++k) M(k, k) = 2.0 + k % 3;
  M(0, 1) = M(1, 0) = 0.5;
  for (int k = 0; k < 6; ++k) H(k, 5 - k) = 1.0;
  H(0, 0) = 0.25;
  CompressedMatrix Ms(M, -1), Hs(H, -2);
  std::vector<double> f = {0, 0, -9.81, 0, 0, -9.81}, w = {0.01, 0, 0, 0.02, 0, 0}, mu = {0.3, 0.5};
  fclib_global g{};
  g.M = &Ms.matrix;
  g.H = &Hs.matrix;
  g.f = f.data();
  g.w = w.data();
  g.mu = mu.data();
  g.spacedim = 3;
  const std::string path = scratch("global.hdf5");
  std::remove(path.c_str());
  ASSERT_EQ(fclib_write_global(&g, path.c_str()), 1);
  LocalProblem p;
  std::string error;
  ASSERT_TRUE(nscd_fclib::readFclibProblem(path.c_str(), p, error)) << error;
  std::remove(path.c_str());
  const Eigen::MatrixXd W = H.transpose() * M.inverse() * H;
  const Eigen::VectorXd q = H.transpose() * M.inverse() * Eigen::Map<Eigen::VectorXd>(f.data(), 6) +
                            Eigen::Map<Eigen::VectorXd>(w.data(), 6);
  EXPECT_EQ(p.contacts, 2);
  EXPECT_LT((p.W - W).norm(), 1e-14 * W.norm());
  EXPECT_LT((p.q - q).norm(), 1e-14 * q.norm());
  EXPECT_EQ(p.mu, mu);
}

// Compressed rows (nz = -2) and triplets (nz >= 0, 2D): the matrix stored, entry for
// entry (compressed rows once read as a zero matrix).
TEST(FclibReader, CompressedRowsAndTripletsRead) {
  Eigen::MatrixXd W(3, 3);
  W << 2, 0.1, 0, 0.1, 1, -0.3, 0, 0.2, 1;  // not symmetric: rows and columns told apart
  CompressedMatrix rows(W, -2);
  const std::string path = scratch("csr.hdf5");
  ASSERT_TRUE(writeLocal(path, &rows.matrix, {-0.1, 0.05, 0}, {0.4}, 3));
  LocalProblem p;
  std::string error;
  ASSERT_TRUE(nscd_fclib::readFclibProblem(path.c_str(), p, error)) << error;
  EXPECT_EQ(p.W, W);

  std::vector<int> r = {0, 1, 2, 3, 0, 0}, c = {0, 1, 2, 3, 2, 2};  // a repeated entry adds up
  std::vector<double> x = {1, 1, 1, 1, 0.2, 0.05};
  fclib_matrix T{};
  T.nzmax = T.nz = 6;
  T.m = T.n = 4;
  T.i = r.data();
  T.p = c.data();
  T.x = x.data();
  ASSERT_TRUE(writeLocal(path, &T, {-1, 0, 0.5, 0}, {0.2, 0.6}, 2));
  ASSERT_TRUE(nscd_fclib::readFclibProblem(path.c_str(), p, error)) << error;
  std::remove(path.c_str());
  Eigen::MatrixXd expected = Eigen::MatrixXd::Identity(4, 4);
  expected(0, 2) = 0.25;
  EXPECT_EQ(p.dim, 2);
  EXPECT_EQ(p.contacts, 2);
  EXPECT_EQ(p.W, expected);
}

// Files FCLib reads but whose content cannot be used: each refused with one line.
TEST(FclibReader, BadContentRefused) {
  const std::string path = scratch("bad.hdf5");
  Eigen::MatrixXd W = Eigen::MatrixXd::Identity(3, 3);
  {
    CompressedMatrix c(W, -1);
    c.indices[1] = 7;  // a row index outside the 3 rows
    ASSERT_TRUE(writeLocal(path, &c.matrix, {0, 0, 0}, {0.5}, 3));
    EXPECT_TRUE(refusedWithOneLine(path));
  }
  {
    CompressedMatrix c(W, -1);
    c.pointers[2] = 9;  // a column pointer above nzmax
    ASSERT_TRUE(writeLocal(path, &c.matrix, {0, 0, 0}, {0.5}, 3));
    EXPECT_TRUE(refusedWithOneLine(path));
  }
  {
    CompressedMatrix c(W, -1);
    ASSERT_TRUE(writeLocal(path, &c.matrix, {0, 0, 0}, {-0.5}, 3));  // mu < 0
    EXPECT_TRUE(refusedWithOneLine(path));
    ASSERT_TRUE(writeLocal(path, &c.matrix, {0, NAN, 0}, {0.5}, 3));
    EXPECT_TRUE(refusedWithOneLine(path));
  }
  {
    CompressedMatrix c(Eigen::MatrixXd::Identity(3, 6), -1);  // W not square
    ASSERT_TRUE(writeLocal(path, &c.matrix, {0, 0, 0}, {0.5}, 3));
    EXPECT_TRUE(refusedWithOneLine(path));
  }
  std::remove(path.c_str());
}

// Files that are no FCLib problem, and damaged ones (tools/fclib/bad_files: a
// mutated box_stack2_mu1_step300.hdf5 whose symbol-table node made FCLib exit, one
// whose metadata length makes HDF5 ask for 380 GB): refused with one line, the
// process alive.
TEST(FclibReader, BadFilesRefused) {
  const std::string junk = scratch("junk.hdf5");
  std::ofstream(junk) << "not an HDF5 file\n";
  EXPECT_TRUE(refusedWithOneLine(junk));
  std::remove(junk.c_str());
  EXPECT_TRUE(refusedWithOneLine(scratch("missing.hdf5")));
  int files = 0;
  for (const fs::directory_entry& e :
       fs::directory_iterator(std::string(NSCD_SOURCE_DIR) + "/tools/fclib/bad_files")) {
    EXPECT_TRUE(refusedWithOneLine(e.path().string()));
    ++files;
  }
  EXPECT_GE(files, 2);
}
