// Reads friction-contact problems in the FCLib HDF5 format (local: U = W r + q;
// global problems are condensed to local ones) and solves them with
// nscd::FrictionContactSolver, cold-started, at each requested tolerance,
// printing iterations, error and time. Built with Siconos numerics
// (NSCD_WITH_SICONOS), it also runs Siconos's fc3d solvers on the same problem
// and reports both error measures for every solution, and can convert a
// Siconos .dat problem (frictionContact_printInFilename) to FCLib.
//
// usage: nscd_fclib [--tol 1e-4,1e-8,1e-10] [--max-iter N] [--siconos nsgs,nsn_ac,...|none]
//                   [--csv FILE] [--min-ms T] [--measure siconos|nscd]
//                   [--siconos-storage best|sparse|dense] PROBLEM.hdf5...
// Tolerances are on the chosen error measure: Siconos's (natural-map residual /
// |q|, the default) or nscd's (/ max(1, |q|)); our solver is given the tolerance
// that makes its own stopping test equivalent. Every answer, ours and Siconos's,
// is measured here on an untouched copy of the problem; a Siconos solver counts
// as converged if it says so and the measured error is within the tolerance.
//        nscd_fclib --convert IN.dat OUT.hdf5 [--title TEXT] [--description TEXT]
//        nscd_fclib --from-nscd IN.txt OUT.hdf5 [--title TEXT] [--description TEXT]
//        nscd_fclib --to-nscd IN.hdf5 OUT.txt
// --to-nscd writes an FCLib problem as an nscd problem file (P_start = P = 0),
// for nscd_solve_problems and the tests.
// --from-nscd takes a problem file of `nscd_run --dump-problems`: its bilateral
// rows are condensed out (Schur complement; a singular equality block by its
// pseudo-inverse), a frictionless contact becomes a 3-row contact with mu = 0
// and inert tangents, and the result is written as a local FCLib problem.
// fclib.h has no C++ guard.
extern "C" {
#include <fclib.h>
}

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "../command_line.hpp"
#include "compressed_matrix.hpp"
#include "condense_problem.hpp"
#include "read_fclib_problem.hpp"
#include "nscd_sim/friction_contact_solver.hpp"
#include "nscd_sim/problem_file.hpp"

#ifdef NSCD_WITH_SICONOS
#include <FrictionContactProblem.h>
#include <Friction_cst.h>
#include <NonSmoothDrivers.h>
#include <NumericsMatrix.h>
#include <SolverOptions.h>
#endif

namespace {

using Clock = std::chrono::steady_clock;

using nscd_fclib::LocalProblem;

// Reads `path` (read_fclib_problem.hpp); false after one line naming it and what is wrong.
bool readProblem(const char* path, LocalProblem& out) {
  std::string error;
  if (!nscd_fclib::readFclibProblem(path, out, error)) {
    std::fprintf(stderr, "%s: not a usable FCLib problem: %s\n", path, error.c_str());
    return false;
  }
  if (out.bilateral_ignored) std::fprintf(stderr, "%s: V/R (bilateral part) ignored\n", path);
  return true;
}

// Our block layout; a 2D problem becomes 3D with a decoupled, inert second tangent.
void toOurs(const LocalProblem& p, Eigen::MatrixXd& W, Eigen::VectorXd& b,
            std::vector<nscd::ProblemBlock>& blocks) {
  const int n = 3 * p.contacts;
  W = Eigen::MatrixXd::Zero(n, n);
  b = Eigen::VectorXd::Zero(n);
  blocks.clear();
  for (int a = 0; a < p.contacts; ++a) {
    nscd::ProblemBlock bl;
    bl.kind = nscd::BlockKind::Frictional;
    bl.row = 3 * a;
    bl.size = 3;
    bl.mu = p.mu[a];
    blocks.push_back(bl);
  }
  if (p.dim == 3) {
    W = p.W;
    b = p.q;
    return;
  }
  for (int a = 0; a < p.contacts; ++a) {
    for (int c = 0; c < p.contacts; ++c)
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) W(3 * a + i, 3 * c + j) = p.W(2 * a + i, 2 * c + j);
    W(3 * a + 2, 3 * a + 2) = std::max(p.W(2 * a + 1, 2 * a + 1), 1.0);
    b(3 * a) = p.q(2 * a);
    b(3 * a + 1) = p.q(2 * a + 1);
  }
}

struct Row {
  std::string problem, solver;
  int contacts = 0;
  double tol = 0;
  long iterations = 0;
  double err_ours = 0;     // nscd::solverError: / max(1, |q|)
  double err_siconos = -1; // the natural-map residual / |q| (siconosMeasure)
  double ms = 0;
  bool converged = false;
};

#ifdef NSCD_WITH_SICONOS
struct SiconosSolver {
  const char* name;
  int id;
};
const SiconosSolver kSiconosSolvers[] = {
    {"nsgs", SICONOS_FRICTION_3D_NSGS},     {"nsn_ac", SICONOS_FRICTION_3D_NSN_AC},
    {"nsn_fb", SICONOS_FRICTION_3D_NSN_FB}, {"nsn_nm", SICONOS_FRICTION_3D_NSN_NM},
    {"prox", SICONOS_FRICTION_3D_PROX},     {"admm", SICONOS_FRICTION_3D_ADMM},
    {"vi_eg", SICONOS_FRICTION_3D_VI_EG},   {"vi_fpp", SICONOS_FRICTION_3D_VI_FPP},
};

// A numerics problem owning copies of W, q and mu. W is stored sparse (its
// Newton solvers factorise sparse matrices; dense storage makes them much
// slower) or dense.
FrictionContactProblem* makeSiconosProblem(const LocalProblem& p, bool sparse) {
  const int n = static_cast<int>(p.W.rows());
  NumericsMatrix* M = nullptr;
  if (sparse) {
    M = NM_create(NM_SPARSE, n, n);
    NM_triplet_alloc(M, static_cast<CS_INT>((p.W.array() != 0).count()));
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        if (p.W(i, j) != 0) NM_entry(M, i, j, p.W(i, j));
  } else {
    M = NM_create(NM_DENSE, n, n);
    Eigen::Map<Eigen::MatrixXd>(M->matrix0, n, n) = p.W;
  }
  double* q = static_cast<double*>(std::malloc(sizeof(double) * n));
  double* mu = static_cast<double*>(std::malloc(sizeof(double) * p.contacts));
  std::copy(p.q.data(), p.q.data() + n, q);
  std::copy(p.mu.begin(), p.mu.end(), mu);
  return frictionContactProblem_new_with_data(p.dim, p.contacts, M, q, mu);
}

#endif

// A row's answer within the tolerance on the chosen measure (a hair of slack for
// the two evaluations' round-off).
bool withinTolerance(const Row& r, const std::string& measure, double tol) {
  const double e = measure == "siconos" ? r.err_siconos : r.err_ours;
  return std::isfinite(e) && e <= tol * (1 + 1e-6);
}

// Siconos's measure from ours: the same natural-map residual, divided by |q|
// instead of max(1, |q|). (fc3d_compute_error of Siconos 4.4 divides by |q|;
// that of 4.5 by a norm that also takes in the reaction's, so an answer with
// huge impulses, on a problem with none that fits, passes its own test: PROX's
// answer to a stress-suite problem, |r| = 4e3, 3.8e-5 from it in the residual,
// scores 9.5e-9 there. All answers are measured here, by the one formula.)
double siconosMeasure(double err_ours, double qnorm) {
  return qnorm > 0 ? err_ours * std::max(1.0, qnorm) / qnorm : err_ours;
}

[[maybe_unused]] double ourError(const LocalProblem& p, const Eigen::VectorXd& r) {  // Siconos builds only
  Eigen::MatrixXd W;
  Eigen::VectorXd b;
  std::vector<nscd::ProblemBlock> blocks;
  toOurs(p, W, b, blocks);
  Eigen::VectorXd P = Eigen::VectorXd::Zero(W.rows());
  for (int a = 0; a < p.contacts; ++a)
    for (int i = 0; i < p.dim; ++i) P(3 * a + i) = r(p.dim * a + i);
  return nscd::solverError(W, b, P, blocks);
}

// Runs `solve` (cold start each time; it returns the milliseconds of its timed
// part) until min_ms is measured; the fastest run.
template <class Solve>
double timeIt(Solve solve, double min_ms) {
  double best = 1e300, total = 0;
  for (int rep = 0; rep < 1000 && (rep == 0 || total < min_ms); ++rep) {
    const double ms = solve();
    best = std::min(best, ms);
    total += ms;
  }
  return best;
}

void printRow(FILE* f, const Row& r, bool csv) {
  if (csv) {
    std::fprintf(f, "%s,%d,%s,%.0e,%ld,%.3e,%.3e,%.4g,%d\n", r.problem.c_str(), r.contacts,
                 r.solver.c_str(), r.tol, r.iterations, r.err_ours, r.err_siconos, r.ms,
                 r.converged ? 1 : 0);
  } else {
    std::fprintf(f, "%-32s %4d %-10s %7.0e %7ld %10.3e %10.3e %10.4g %s\n", r.problem.c_str(),
                 r.contacts, r.solver.c_str(), r.tol, r.iterations, r.err_ours, r.err_siconos, r.ms,
                 r.converged ? "yes" : "NO");
  }
}

// Writes a local problem U = W r + q (3 rows per contact) as FCLib HDF5.
int writeLocal(const Eigen::MatrixXd& Wd, const Eigen::VectorXd& q, std::vector<double> mu,
               const char* out, const std::string& title, const std::string& descr,
               const std::string& math) {
  const int n = static_cast<int>(q.size());
  nscd_fclib::CompressedMatrix W(Wd);
  fclib_info info{};
  std::string t = title, d = descr, m = math;
  info.title = &t[0];
  info.description = &d[0];
  info.math_info = &m[0];
  std::vector<double> qv(q.data(), q.data() + n);
  fclib_local lp{};
  lp.W = &W.matrix;
  lp.mu = mu.data();
  lp.q = qv.data();
  lp.spacedim = 3;
  lp.info = &info;
  std::remove(out);  // fclib appends to an existing file
  if (!fclib_write_local(&lp, out)) {
    std::fprintf(stderr, "%s: fclib_write_local failed\n", out);
    return 1;
  }
  std::printf("-> %s (%d contacts, %d non-zeros)\n", out, n / 3, W.matrix.nzmax);
  return 0;
}

int fromNscd(const char* in, const char* out, const std::string& title, const std::string& descr) {
  nscd::ProblemFile p;
  try {
    p = nscd::readProblemFile(in);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  nscd_fclib::CondensedProblem c;
  std::string why;
  if (!nscd_fclib::condenseProblem(p, c, why)) {
    std::fprintf(stderr, "%s: %s\n", in, why.c_str());
    return 1;
  }
  std::printf("%s: %d contacts, %d bilateral rows condensed\n", in, static_cast<int>(c.mu.size()),
              c.bilateral_rows);
  return writeLocal(c.W, c.q, c.mu, out, title, descr,
                    "U = W r + q, Coulomb friction; nscd_run --dump-problems, bilateral rows condensed");
}

#ifdef NSCD_WITH_SICONOS
int convert(const char* in, const char* out, const std::string& title, const std::string& descr) {
  FrictionContactProblem* fp = frictionContact_new_from_filename(in);
  if (!fp) {
    std::fprintf(stderr, "%s: cannot read a Siconos friction-contact problem\n", in);
    return 1;
  }
  const int n = fp->dimension * fp->numberOfContacts;
  Eigen::MatrixXd W(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) W(i, j) = NM_get_value(fp->M, i, j);
  const Eigen::VectorXd q = Eigen::Map<Eigen::VectorXd>(fp->q, n);
  const std::vector<double> mu(fp->mu, fp->mu + fp->numberOfContacts);
  const int dim = fp->dimension;
  frictionContactProblem_free(fp);
  if (dim != 3) {
    std::fprintf(stderr, "%s: a %dD problem: only 3D ones are converted\n", in, dim);
    return 1;
  }
  std::printf("%s: ", in);
  return writeLocal(W, q, mu, out, title, descr, "U = W r + q, Coulomb friction, Siconos numerics .dat source");
}
#endif

int toNscd(const char* in, const char* out) {
  LocalProblem p;
  if (!readProblem(in, p)) return 1;
  Eigen::MatrixXd W;
  Eigen::VectorXd b;
  std::vector<nscd::ProblemBlock> blocks;
  toOurs(p, W, b, blocks);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(b.size());
  nscd::SolverReport none;
  try {
    nscd::writeProblemFile(out, nscd::ProblemView{0, 0, W, b, blocks, zero, zero, none});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  std::printf("-> %s (%d contacts)\n", out, p.contacts);
  return 0;
}

// The command line (usage in the file's head).
struct Options {
  std::vector<double> tols{1e-4, 1e-8, 1e-10};
  long max_iter = 10000;
  double min_ms = 20;
  std::string csv_path, title, descr, convert_in, convert_out, measure = "siconos";
  std::string from_in, from_out, to_in, to_out;
  std::string storage = "best";  // of W for the Siconos solvers: sparse, dense or the faster
  std::vector<std::string> siconos_names{"nsgs", "nsn_ac", "nsn_fb", "prox"};
  std::vector<const char*> files;
};

// False after the usage line (an unknown option).
bool parseOptions(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] { return nscd_cli::optionValue(a, argc, argv, i); };
    if (a == "--tol") {
      o.tols.clear();
      for (const std::string& s : nscd_cli::splitCommas(next())) o.tols.push_back(std::atof(s.c_str()));
    } else if (a == "--max-iter") o.max_iter = std::atol(next().c_str());
    else if (a == "--min-ms") o.min_ms = std::atof(next().c_str());
    else if (a == "--csv") o.csv_path = next();
    else if (a == "--measure") o.measure = next();
    else if (a == "--siconos-storage") o.storage = next();
    else if (a == "--siconos") {
      const std::string s = next();
      o.siconos_names = s == "none" ? std::vector<std::string>{} : nscd_cli::splitCommas(s);
    } else if (a == "--convert") {
      o.convert_in = next();
      o.convert_out = next();
    } else if (a == "--from-nscd") {
      o.from_in = next();
      o.from_out = next();
    } else if (a == "--to-nscd") {
      o.to_in = next();
      o.to_out = next();
    } else if (a == "--title") o.title = next();
    else if (a == "--description") o.descr = next();
    else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr,
                   "usage: %s [--tol 1e-4,1e-8,1e-10] [--max-iter N] [--siconos nsgs,nsn_ac,...|none] "
                   "[--csv FILE] [--min-ms T] [--measure siconos|nscd] [--siconos-storage best|sparse|dense] "
                   "PROBLEM.hdf5...\n"
                   "       %s --convert IN.dat OUT.hdf5 [--title T] [--description D]\n"
                   "       %s --from-nscd IN.txt OUT.hdf5 [--title T] [--description D]\n"
                   "       %s --to-nscd IN.hdf5 OUT.txt\n",
                   argv[0], argv[0], argv[0], argv[0]);
      return false;
    } else o.files.push_back(argv[i]);
  }
  return true;
}

// Prints a row on standard output and, when there is one, in the CSV.
void report(const Row& r, FILE* csv) {
  printRow(stdout, r, false);
  if (csv) printRow(csv, r, true);
}

// Our solver on the problem (W, b, blocks) at tolerance tol, cold-started, timed.
// qn: |q|, for Siconos's measure.
Row solveOurs(const LocalProblem& p, const Eigen::MatrixXd& W, const Eigen::VectorXd& b,
              const std::vector<nscd::ProblemBlock>& blocks, double tol, double qn, const Options& o) {
  nscd::FrictionContactSolver solver;
  nscd::SolverOptions opt;
  // Same absolute residual as Siconos's relative one: scale by |q| / max(1, |q|).
  opt.tolerance = o.measure == "siconos" && qn > 0 ? tol * qn / std::max(1.0, qn) : tol;
  opt.max_iterations = static_cast<int>(std::min<long>(o.max_iter, 1 << 30));
  Eigen::VectorXd P(W.rows());
  nscd::SolverReport rep;
  Row r;
  r.problem = p.name;
  r.contacts = p.contacts;
  r.solver = "nscd";
  r.tol = tol;
  r.ms = timeIt([&] {
    P.setZero();
    const auto t0 = Clock::now();
    rep = solver.solve(W, b, blocks, opt, P);
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  }, o.min_ms);
  r.iterations = rep.iteration_sum;
  r.err_ours = nscd::solverError(W, b, P, blocks);
  r.converged = rep.converged;
  r.err_siconos = siconosMeasure(r.err_ours, qn);
  r.converged = rep.converged && withinTolerance(r, o.measure, tol);
  return r;
}

#ifdef NSCD_WITH_SICONOS
// Siconos's solver `sname` (id) on the problem at tolerance tol, with W stored sparse
// or dense, cold-started, timed; its answer measured here.
Row solveSiconos(const LocalProblem& p, const std::string& sname, int id, bool sparse, double tol, double qn,
                 const Options& o) {
  const int n = static_cast<int>(p.W.rows());
  Eigen::VectorXd reac(n), velo(n);
  int info = -1;
  long iters = 0;
  Row s;
  s.problem = p.name;
  s.contacts = p.contacts;
  s.solver = sname + (sparse ? "/sp" : "/de");
  s.tol = tol;
  s.ms = timeIt([&] {
    SolverOptions* so = solver_options_create(id);
    so->dparam[SICONOS_DPARAM_TOL] = tol;
    so->iparam[SICONOS_IPARAM_MAX_ITER] = static_cast<int>(o.max_iter);
    reac.setZero();
    velo.setZero();
    FrictionContactProblem* fs = makeSiconosProblem(p, sparse);
    const auto t0 = Clock::now();
    info = fc3d_driver(fs, reac.data(), velo.data(), so);
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    iters = so->iparam[SICONOS_IPARAM_ITER_DONE];
    solver_options_delete(so);
    frictionContactProblem_free(fs);
    return ms;
  }, o.min_ms);
  s.iterations = iters;
  s.err_ours = ourError(p, reac);
  s.err_siconos = siconosMeasure(s.err_ours, qn);
  // Converged: Siconos says so (info 0) and the answer's error, measured on
  // the untouched problem, is within the tolerance. PROX can report info 0
  // on an answer far from it (3.9e-4 against 1e-8 on a stress problem).
  s.converged = info == 0 && withinTolerance(s, o.measure, tol);
  if (info == 0 && !s.converged)
    std::fprintf(stderr, "%s %s: Siconos reports converged at %g; measured error %.3e (%s)\n",
                 p.name.c_str(), s.solver.c_str(), tol,
                 o.measure == "siconos" ? s.err_siconos : s.err_ours, o.measure.c_str());
  return s;
}

// Each chosen Siconos solver at tolerance tol, one row each: of the storages of W
// tried ("best": both), the converged, then faster, run.
void runSiconosSolvers(const LocalProblem& p, double tol, double qn, const Options& o, FILE* csv) {
  // Siconos's solvers get a fresh copy of the problem per call: PROX shifts its
  // diagonal and q in place and takes the shift off afterwards.
  std::vector<bool> storages;  // sparse?
  if (o.storage != "dense") storages.push_back(true);
  if (o.storage != "sparse") storages.push_back(false);
  for (const std::string& sname : o.siconos_names) {
    int id = -1;
    for (const SiconosSolver& s : kSiconosSolvers)
      if (sname == s.name) id = s.id;
    if (id < 0) {
      std::fprintf(stderr, "unknown Siconos solver %s\n", sname.c_str());
      continue;
    }
    Row best;
    bool have = false;
    for (const bool sparse : storages) {
      const Row s = solveSiconos(p, sname, id, sparse, tol, qn, o);
      if (!have || (s.converged && !best.converged) ||
          (s.converged == best.converged && s.ms < best.ms)) {
        best = s;
        have = true;
      }
    }
    report(best, csv);
  }
}
#endif

// Every problem file at every tolerance: ours, then Siconos's solvers (3D problems).
// The count of problems unread or unsolved by ours.
int solveFiles(const Options& o, FILE* csv) {
  int failures = 0;
  for (const char* path : o.files) {
    LocalProblem p;
    if (!readProblem(path, p)) {
      ++failures;
      continue;
    }
    Eigen::MatrixXd W;
    Eigen::VectorXd b;
    std::vector<nscd::ProblemBlock> blocks;
    toOurs(p, W, b, blocks);
    const double qn = b.norm();
    for (double tol : o.tols) {
      const Row r = solveOurs(p, W, b, blocks, tol, qn, o);
      report(r, csv);
      if (!r.converged) ++failures;
#ifdef NSCD_WITH_SICONOS
      if (p.dim == 3) runSiconosSolvers(p, tol, qn, o, csv);
#endif
    }
  }
  return failures;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parseOptions(argc, argv, o)) return 2;
  if (!o.from_in.empty()) return fromNscd(o.from_in.c_str(), o.from_out.c_str(), o.title, o.descr);
  if (!o.to_in.empty()) return toNscd(o.to_in.c_str(), o.to_out.c_str());
  if (!o.convert_in.empty()) {
#ifdef NSCD_WITH_SICONOS
    return convert(o.convert_in.c_str(), o.convert_out.c_str(), o.title, o.descr);
#else
    std::fprintf(stderr, "--convert needs a build with Siconos numerics\n");
    return 2;
#endif
  }
#ifndef NSCD_WITH_SICONOS
  o.siconos_names.clear();
#endif
  FILE* csv = nullptr;
  if (!o.csv_path.empty()) {
    csv = std::fopen(o.csv_path.c_str(), "w");
    if (!csv) {
      std::fprintf(stderr, "cannot write %s\n", o.csv_path.c_str());
      return 1;
    }
    std::fprintf(csv, "problem,contacts,solver,tol,iterations,error_nscd,error_siconos,time_ms,converged\n");
  }
  std::printf("%-32s %4s %-10s %7s %7s %10s %10s %10s %s\n", "problem", "nc", "solver", "tol", "iter",
              "err(nscd)", "err(sicon)", "time ms", "conv");
  const int failures = solveFiles(o, csv);
  if (csv) std::fclose(csv);
  return failures == 0 ? 0 : 3;
}
