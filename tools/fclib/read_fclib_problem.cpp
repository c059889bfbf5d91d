// Reading FCLib problems (read_fclib_problem.hpp).
#include "read_fclib_problem.hpp"

// fclib.h has no C++ guard.
extern "C" {
#include <fclib.h>
}

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "fclib_file_check.hpp"

namespace nscd_fclib {
namespace {

struct LocalDeleter {
  void operator()(fclib_local* p) const {
    fclib_delete_local(p);
    std::free(p);
  }
};
struct GlobalDeleter {
  void operator()(fclib_global* p) const {
    fclib_delete_global(p);
    std::free(p);
  }
};

bool finite(const double* x, long n) {
  for (long k = 0; k < n; ++k)
    if (!std::isfinite(x[k])) return false;
  return true;
}

// `A` as a dense matrix, or false with `error`: FCLib stores compressed columns
// (nz = -1), compressed rows (nz = -2) or triplets (nz >= 0 entries; p holds the
// column indices), and checks none of the indices.
bool toDense(const fclib_matrix* A, const char* name, double max_entries, Eigen::MatrixXd& D, std::string& error) {
  const auto fail = [&](const std::string& what) {
    error = std::string("matrix ") + name + ": " + what;
    return false;
  };
  if (!A) return fail("missing");
  if (A->m < 0 || A->n < 0 || A->nzmax < 0) return fail("negative size");
  if (static_cast<double>(A->m) * A->n > max_entries)
    return fail(std::to_string(A->m) + " x " + std::to_string(A->n) + " is too large to hold densely");
  if (A->nz < -2) return fail("unknown storage nz = " + std::to_string(A->nz));
  const long entries = A->nz >= 0 ? A->nz : A->nzmax;
  if (A->nz > A->nzmax) return fail("nz = " + std::to_string(A->nz) + " above nzmax");
  if (entries > 0 && (!A->p || !A->i || !A->x)) return fail("arrays missing");
  if (!finite(A->x, entries)) return fail("a value that is not finite");
  D = Eigen::MatrixXd::Zero(A->m, A->n);
  if (A->nz >= 0) {
    for (long k = 0; k < A->nz; ++k) {
      if (A->i[k] < 0 || A->i[k] >= A->m || A->p[k] < 0 || A->p[k] >= A->n)
        return fail("entry " + std::to_string(k) + " outside the matrix");
      D(A->i[k], A->p[k]) += A->x[k];
    }
    return true;
  }
  // Compressed: `outer` pointers (outer + 1 of them) into indices below `inner`.
  const bool columns = A->nz == -1;
  const int outer = columns ? A->n : A->m, inner = columns ? A->m : A->n;
  if (!A->p) return fail("arrays missing");
  if (A->p[0] != 0) return fail("pointers do not start at 0");
  for (int j = 0; j < outer; ++j) {
    if (A->p[j + 1] < A->p[j] || A->p[j + 1] > A->nzmax) return fail("pointers out of order or above nzmax");
    for (int k = A->p[j]; k < A->p[j + 1]; ++k) {
      if (A->i[k] < 0 || A->i[k] >= inner) return fail("index " + std::to_string(k) + " outside the matrix");
      (columns ? D(A->i[k], j) : D(j, A->i[k])) += A->x[k];
    }
  }
  return true;
}

bool checkMu(const double* mu, int contacts, std::string& error) {
  for (int a = 0; a < contacts; ++a) {
    if (!(std::isfinite(mu[a]) && mu[a] >= 0)) {
      error = "contact " + std::to_string(a) + ": mu " + std::to_string(mu[a]) + " (must be finite and >= 0)";
      return false;
    }
  }
  return true;
}

bool readLocal(fclib_local* lp, LocalProblem& out, std::string& error, double max_entries) {
  if (lp->spacedim != 2 && lp->spacedim != 3) {
    error = "space dimension " + std::to_string(lp->spacedim) + " (must be 2 or 3)";
    return false;
  }
  out.dim = lp->spacedim;
  if (!toDense(lp->W, "W", max_entries, out.W, error)) return false;
  if (out.W.rows() != out.W.cols() || out.W.rows() % out.dim != 0) {
    error = "W is " + std::to_string(out.W.rows()) + " x " + std::to_string(out.W.cols()) +
            ": must be square, " + std::to_string(out.dim) + " rows per contact";
    return false;
  }
  out.contacts = static_cast<int>(out.W.rows()) / out.dim;
  if (!lp->q || !lp->mu || !finite(lp->q, out.W.rows())) {
    error = "q missing or not finite";
    return false;
  }
  if (!checkMu(lp->mu, out.contacts, error)) return false;
  out.q = Eigen::Map<const Eigen::VectorXd>(lp->q, out.W.rows());
  out.mu.assign(lp->mu, lp->mu + out.contacts);
  out.bilateral_ignored = lp->V || lp->R;
  return true;
}

// M v = H r + f, U = H^T v + w  ->  W = H^T M^-1 H, q = H^T M^-1 f + w.
bool readGlobal(fclib_global* gp, LocalProblem& out, std::string& error, double max_entries) {
  if (gp->G) {
    error = "a global problem with equality constraints (G): not supported";
    return false;
  }
  if (gp->spacedim != 2 && gp->spacedim != 3) {
    error = "space dimension " + std::to_string(gp->spacedim) + " (must be 2 or 3)";
    return false;
  }
  out.dim = gp->spacedim;
  Eigen::MatrixXd M, H;
  if (!toDense(gp->M, "M", max_entries, M, error) || !toDense(gp->H, "H", max_entries, H, error)) return false;
  if (M.rows() != M.cols() || H.rows() != M.rows() || H.cols() % out.dim != 0) {
    error = "M is " + std::to_string(M.rows()) + " x " + std::to_string(M.cols()) + ", H " +
            std::to_string(H.rows()) + " x " + std::to_string(H.cols()) +
            ": M must be square, H of M's rows and " + std::to_string(out.dim) + " columns per contact";
    return false;
  }
  if (static_cast<double>(H.cols()) * H.cols() > max_entries) {
    error = "W would be " + std::to_string(H.cols()) + " x " + std::to_string(H.cols()) + ": too large";
    return false;
  }
  out.contacts = static_cast<int>(H.cols()) / out.dim;
  if (!gp->f || !gp->w || !gp->mu || !finite(gp->f, M.rows()) || !finite(gp->w, H.cols())) {
    error = "f or w missing or not finite";
    return false;
  }
  if (!checkMu(gp->mu, out.contacts, error)) return false;
  const Eigen::LLT<Eigen::MatrixXd> llt(M);
  if (llt.info() != Eigen::Success) {
    error = "M is not positive definite";
    return false;
  }
  const Eigen::VectorXd f = Eigen::Map<const Eigen::VectorXd>(gp->f, M.rows());
  const Eigen::VectorXd w = Eigen::Map<const Eigen::VectorXd>(gp->w, H.cols());
  out.W = H.transpose() * llt.solve(H);
  out.q = H.transpose() * llt.solve(f) + w;
  if (!out.W.allFinite() || !out.q.allFinite()) {
    error = "H^T M^-1 H or its q overflow";
    return false;
  }
  out.mu.assign(gp->mu, gp->mu + out.contacts);
  return true;
}

}  // namespace

bool readFclibProblem(const char* path, LocalProblem& out, std::string& error, double max_dense_entries) {
  out = LocalProblem{};
  out.name = path;
  if (const char* slash = std::strrchr(path, '/')) out.name = slash + 1;
  // FCLib exits on a file it cannot read and trusts the file's sizes: checked first.
  FclibKind kind{};
  if (!checkFclibFile(path, kind, error, static_cast<long>(std::min(max_dense_entries, 2e9)))) return false;
  error = "FCLib read no problem";
  if (kind == FclibKind::Local) {
    const std::unique_ptr<fclib_local, LocalDeleter> lp{fclib_read_local(path)};
    return lp && readLocal(lp.get(), out, error, max_dense_entries);
  }
  const std::unique_ptr<fclib_global, GlobalDeleter> gp{fclib_read_global(path)};
  return gp && readGlobal(gp.get(), out, error, max_dense_entries);
}

}  // namespace nscd_fclib
