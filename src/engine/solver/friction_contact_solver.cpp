// The friction-contact solver's front: checks the problem, answers a single
// contact by the local solver alone, sets up the buffers and the problem
// (problem_setup.cpp; a problem of bilateral rows only as the linear system it
// is), runs the schedule of stages (solver_schedule.cpp) and reports; and the
// Siconos-style error.
#include "nscd_sim/friction_contact_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "solve_run.hpp"
#include "solver_schedule.hpp"

namespace nscd {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

constexpr int kMaxBilateral = 6;
using BVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxBilateral, 1>;

constexpr double kRelZeroDiag = 1e-13;  // as problem_setup.cpp: a zero row

// Summed in 64 bits: a caller's block with a row near INT_MAX overflowed an int
// (undefined; it wrapped to a negative m, and the solve answered NoRows, converged).
// Such a block is refused by validBlocks; m is capped so that it is one.
int problemRows(const std::vector<ProblemBlock>& blocks) {
  Eigen::Index m = 0;
  for (const ProblemBlock& bl : blocks) m = std::max(m, Eigen::Index(bl.row) + bl.size);
  return int(std::min<Eigen::Index>(m, std::numeric_limits<int>::max()));
}

// A pull (P_N < 0) is no answer of the contact law, however small it is
// against |b|: the block's error is at least the pull itself, unnormalised
// (scale = max(1, |b|), the error's normalisation), so an accepted answer has
// P_N >= -tolerance on every contact. (The block's own error is >= |P_N| already;
// divided by a |b| of sliding velocities, 7-11 m/s on the slider-crank, a pull of
// 1.1e-7 N s passed a tolerance of 1e-8. An answer without pulls is unchanged.)
double withPullFloor(double e, double pn, double scale) { return pn < 0 ? std::max(e, -pn * scale) : e; }

// Squared error of one block given its U (see solverError); scale: max(1, |b|).
double blockError2(const ProblemBlock& bl, const double* P, const double* U, double scale) {
  switch (bl.kind) {
    case BlockKind::Frictional: {
      const Vector3d p(P[0], P[1], P[2]);
      const Vector3d u(U[0], U[1], U[2]);
      const double e = withPullFloor(localCoulombError(p, u, bl.mu), P[0], scale);
      return e * e;
    }
    case BlockKind::Frictionless: {
      const double e = withPullFloor(P[0] - std::max(0.0, P[0] - U[0]), P[0], scale);
      return e * e;
    }
    case BlockKind::Bilateral: {
      double s = 0;
      for (int i = 0; i < bl.size; ++i) s += U[i] * U[i];
      return s;
    }
  }
  return 0;
}

bool allBilateral(const std::vector<ProblemBlock>& blocks) {
  for (const ProblemBlock& bl : blocks)
    if (bl.kind != BlockKind::Bilateral) return false;
  return true;
}

bool validBlocks(const std::vector<ProblemBlock>& blocks, Eigen::Index rows) {
  for (const ProblemBlock& bl : blocks) {
    const int want = rowsOfKind(bl.kind);
    if (bl.row < 0 || bl.size < 1 || Eigen::Index(bl.row) + bl.size > rows) return false;
    if (want > 0 ? bl.size != want : bl.size > kMaxBilateral) return false;
  }
  return true;
}

// Every row 0..m-1 in exactly one block, as the engine builds its problems (each
// block where the one before ends: checked without the marks). The Newton's
// Jacobian and right-hand side, its row scaling and the interior point's
// directions are written block by block: a row in no block or in two kept what
// an earlier solve (or the allocator) had left there, and the answer depended
// on the solver's history. covered: m entries of scratch.
bool blocksTileRows(const std::vector<ProblemBlock>& blocks, int m, std::vector<char>& covered) {
  int next = 0;
  bool consecutive = true;
  for (const ProblemBlock& bl : blocks) {
    consecutive = consecutive && bl.row == next;
    next += bl.size;  // each at most m (validBlocks): no overflow before the test below
    if (next > m) return false;
  }
  if (next != m) return false;
  if (consecutive) return true;
  std::fill_n(covered.begin(), m, char(0));
  for (const ProblemBlock& bl : blocks)
    for (int i = bl.row; i < bl.row + bl.size; ++i) {
      if (covered[i]) return false;
      covered[i] = 1;
    }
  return true;  // m rows covered by m block rows, none twice: each once
}

// One frictional contact (a pin in its hole, a body on a plane): the local
// solver's answer is the problem's. Checked on the problem's own error; the
// general path takes over (from this answer) if it falls short. True if solved.
bool solveSingleContact(const Eigen::Ref<const Eigen::MatrixXd>& W,
                        const Eigen::Ref<const Eigen::VectorXd>& b,
                        const std::vector<ProblemBlock>& blocks, const SolverOptions& options,
                        Eigen::Ref<Eigen::VectorXd>& P, SolverReport& rep) {
  if (!(blocks.size() == 1 && blocks[0].kind == BlockKind::Frictional && blocks[0].row == 0 &&
        W.topLeftCorner<3, 3>().allFinite() && b.head<3>().allFinite()))
    return false;
  const Matrix3d Wl = W.topLeftCorner<3, 3>();
  const Vector3d bl = b.head<3>();
  if (!(Wl.diagonal().minCoeff() > kRelZeroDiag * Wl.diagonal().maxCoeff())) return false;
  Vector3d Pl = P.head<3>().allFinite() ? Vector3d(P.head<3>()) : Vector3d::Zero();
  solveLocalFrictional(Wl, bl, blocks[0].mu, std::max(1e-14, 1e-2 * options.tolerance), Pl);
  const Vector3d Ul = Wl * Pl + bl;
  const double err = errorFromU(blocks, Pl.data(), Ul.data(), bl.norm());
  if (err > options.tolerance) return false;
  P.head<3>() = Pl;
  rep.residual = err;
  rep.converged = true;
  rep.sweeps = 1;
  rep.iteration_sum = 1;
  rep.stage = SolverStage::LocalSolver;
  return true;
}

// Non-finite input is reported, never looped on. maxDiag: the largest W(i, i).
bool finiteProblem(const Eigen::Ref<const Eigen::MatrixXd>& W,
                   const Eigen::Ref<const Eigen::VectorXd>& b, int m, double& maxDiag) {
  maxDiag = 0;
  for (int i = 0; i < m; ++i) {
    if (!std::isfinite(W(i, i)) || !std::isfinite(b(i))) return false;
    maxDiag = std::max(maxDiag, W(i, i));
  }
  // W.allFinite() in one vectorised pass instead of an entry-by-entry test: x * 0 is
  // +-0 for a finite x and NaN otherwise, and a sum of +-0 is +-0 (== 0) while a NaN
  // stays NaN, in any order: the same answer for every W.
  return (W.topLeftCorner(m, m).array() * 0.0).sum() == 0;
}

// The buffers grow to the largest problem seen, never shrink.
void growBuffers(FrictionContactSolver::Buffers& buf, int m, bool newtonAllowed) {
  if (m > buf.maxRows) {
    buf.maxRows = m;
    buf.U.resize(m);
    buf.Pbest.resize(m);
    buf.Pstart.resize(m);
    buf.Pinitial.resize(m);
    buf.phi.resize(m);
    buf.d.resize(m);
    buf.Wd.resize(m);
    buf.Pt.resize(m);
    buf.Ut.resize(m);
    buf.phiT.resize(m);
    buf.rho.resize(m);
    buf.piv.resize(m);
    buf.zeroRow.resize(m);
    buf.localFactor.resize(m);
    buf.eqRows.reserve(m);
  }
  if (newtonAllowed && buf.J.rows() < m) {  // not for NSGS only; capped at the Newton size
    const int cap = std::min(buf.maxRows, kNewtonMaxRows);
    buf.J.resize(cap, cap);
    buf.Wprox.resize(cap, cap);
    buf.bprox.resize(cap);
    buf.Pcentre.resize(cap);
    buf.Ptrial.resize(cap);
    buf.proxBest.resize(cap);
  }
}

// The report; if not converged, the best iterate and its error on the exact U.
void finishRun(SolveRun& run, bool ok) {
  SolverReport& rep = run.rep;
  rep.iteration_sum = rep.sweeps + rep.newton_iterations + rep.interior_point_iterations;
  if (!ok) {
    rep.residual = INFINITY;
    rep.stage = SolverStage::Failed;
    return;
  }
  if (!rep.converged) {
    if (run.best.err < run.it.err) run.it.P.head(run.problem.m) = run.best.P;
    refreshIterate(run.problem, run.it);
  }
  rep.residual = run.it.err;
}

// Bilateral rows only: the equality schedule, its factor the solve (no warm start needed).
SolverReport solveEqualityOnly(const Eigen::Ref<const Eigen::MatrixXd>& W, const Eigen::Ref<const Eigen::VectorXd>& b,
                               const std::vector<ProblemBlock>& blocks, const SolverOptions& options,
                               Eigen::Ref<Eigen::VectorXd> P, double maxDiag, SolverBuffers& buf) {
  const int m = problemRows(blocks);
  growBuffers(buf, m, false);
  SolveRun run(W, b, blocks, options, P, buf, m);
  run.problem.equalityOnly = true;
  prepareEqualityProblem(run.problem, maxDiag);
  buf.equalityFactorRows = m;
  finishRun(run, solveBySchedule(run));
  return run.rep;
}

// Any problem: set up, the warm start checked, the schedule of its method run.
SolverReport solveGeneralProblem(const Eigen::Ref<const Eigen::MatrixXd>& W, const Eigen::Ref<const Eigen::VectorXd>& b,
                                 const std::vector<ProblemBlock>& blocks, const SolverOptions& options,
                                 Eigen::Ref<Eigen::VectorXd> P, double maxDiag, SolverBuffers& buf) {
  const int m = problemRows(blocks);
  if (!P.head(m).allFinite()) P.head(m).setZero();  // a poisoned warm start is dropped
  growBuffers(buf, m, scheduleUsesNewton(options.method, m));
  SolveRun run(W, b, blocks, options, P, buf, m);
  prepareProblem(run.problem, maxDiag);
  restartIterate(run.problem, run.it);
  run.best.adopt(run.it);
  run.nsgs = NsgsState::fresh(run.it.err);
  buf.Pinitial.head(m) = P.head(m);
  if (run.it.err <= options.tolerance) {
    run.rep.residual = run.it.err;
    run.rep.converged = true;
    run.rep.stage = SolverStage::WarmStart;
    return run.rep;
  }
  finishRun(run, solveBySchedule(run));
  return run.rep;
}

constexpr const char* kStageNames[kSolverStageCount] = {
    "no_rows",        "local_solver",    "equalities",      "warm_start",      "sweeps",          "newton",
    "newton_from_zero", "newton_from_warm", "newton_retry",  "proximal_trial",  "sweeps_to_budget",
    "proximal_newton", "long_newton",    "cone_fixed_point", "unsolved",       "failed"};

}  // namespace

const char* solverStageName(SolverStage stage) {
  const int i = static_cast<int>(stage);
  return i >= 0 && i < kSolverStageCount ? kStageNames[i] : "?";
}

double errorFromU(const std::vector<ProblemBlock>& blocks, const double* P, const double* U,
                  double bnorm) {
  const double scale = std::max(1.0, bnorm);
  double s = 0;
  for (const ProblemBlock& bl : blocks) s += blockError2(bl, P + bl.row, U + bl.row, scale);
  return std::sqrt(s) / scale;
}

double solverError(const Eigen::Ref<const Eigen::MatrixXd>& W,
                   const Eigen::Ref<const Eigen::VectorXd>& b,
                   const Eigen::Ref<const Eigen::VectorXd>& P,
                   const std::vector<ProblemBlock>& blocks) {
  const int m = problemRows(blocks);
  if (m == 0) return 0;
  if (!validBlocks(blocks, std::min({W.rows(), W.cols(), b.size(), P.size()}))) return INFINITY;
  const double bnorm = b.head(m).norm();
  if (!std::isfinite(bnorm)) return INFINITY;
  const double scale = std::max(1.0, bnorm);
  double s = 0;
  for (const ProblemBlock& bl : blocks) {
    // Row block of U = W P + b, fixed-capacity result: no allocation.
    BVec u = b.segment(bl.row, bl.size);
    u.noalias() += W.block(bl.row, 0, bl.size, m) * P.head(m);
    s += blockError2(bl, P.data() + bl.row, u.data(), scale);
  }
  const double e = std::sqrt(s) / scale;
  return std::isfinite(e) ? e : INFINITY;
}

SolverReport FrictionContactSolver::solve(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                          const Eigen::Ref<const Eigen::VectorXd>& b,
                                          const std::vector<ProblemBlock>& blocks,
                                          const SolverOptions& options,
                                          Eigen::Ref<Eigen::VectorXd> P) {
  SolverReport rep;
  rep.residual = INFINITY;
  buffers_.equalityFactorRows = 0;  // whatever this solve does, the last factor goes
  const int m = problemRows(blocks);
  if (m == 0) {
    rep.residual = 0;
    rep.converged = true;
    rep.stage = SolverStage::NoRows;
    return rep;
  }
  if (!validBlocks(blocks, std::min({W.rows(), W.cols(), b.size(), P.size()}))) return rep;
  if (solveSingleContact(W, b, blocks, options, P, rep)) return rep;
  double maxDiag = 0;
  if (!finiteProblem(W, b, m, maxDiag)) return rep;
  growBuffers(buffers_, m, false);  // the schedules grow the Newton's buffers as they need them
  if (!blocksTileRows(blocks, m, buffers_.zeroRow)) return rep;
  const bool equalityOnly =
      allBilateral(blocks) && !(options.skip_stages >> static_cast<int>(SolverStage::Equalities) & 1);
  if (!equalityOnly) return solveGeneralProblem(W, b, blocks, options, P, maxDiag, buffers_);
  const SolverReport direct = solveEqualityOnly(W, b, blocks, options, P, maxDiag, buffers_);
  if (direct.converged || direct.stage == SolverStage::Failed) return direct;
  // Rows so nearly dependent that leaving them out leaves a residual above the
  // tolerance (a mechanism at a singular configuration), or an inconsistent
  // system: the general schedule from the direct answer (its regularised Newton).
  buffers_.equalityFactorRows = 0;  // the general set-up factors other things into eqL
  rep = solveGeneralProblem(W, b, blocks, options, P, maxDiag, buffers_);
  rep.sweeps += direct.sweeps;
  rep.iteration_sum += direct.sweeps;
  return rep;
}

bool FrictionContactSolver::solveEqualitiesAgain(const Eigen::Ref<const Eigen::VectorXd>& b,
                                                 Eigen::Ref<Eigen::VectorXd> P) {
  const int m = int(P.size());
  if (m == 0 || m != buffers_.equalityFactorRows || b.size() < m) return false;
  solveByEqualityFactor(buffers_, m, b.data(), P.data());
  return true;
}

}  // namespace nscd
