// The friction-contact solver's driver: checks the problem, sets up its
// buffers (scaling, zero rows, the factored equality block), then runs NSGS
// sweeps (nsgs.cpp) and, when they converge slowly, the global Newton
// (global_newton.cpp), and for what they leave unsolved the proximal Newton
// (proximal_newton.cpp) and the cone fixed point (cone_fixed_point.cpp); and the
// Siconos-style error. A problem of one frictional contact goes to the local
// solver alone.
#include "nscd_sim/friction_contact_solver.hpp"

#include <algorithm>
#include <cmath>

#include "dense_kernels.hpp"
#include "solve_run.hpp"

namespace nscd {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

constexpr int kMaxBilateral = 6;
using BVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxBilateral, 1>;

constexpr double kRelZeroDiag = 1e-13;  // a W diagonal below this * max diagonal is a zero row
constexpr double kEqDrop = 1e-11;       // equality pivots below this * max diagonal: dependent rows

// Global Newton (see solve()).
constexpr int kNewtonMaxRows = 400;      // dense m x m LU beyond this costs more than sweeps
constexpr int kNewtonSmallRows = 24;     // Auto: Newton after one sweep up to this size
constexpr int kSwitchSweeps = 1;         // Auto: looks at the NSGS rate after 1, 2, 4, 8, ... sweeps
constexpr double kNewtonCostIterations = 6;  // Auto: expected Newton iterations...
constexpr double kLuRowsPerSweep = 20;   // ...each costing (1 + m / this) sweeps
constexpr int kNewtonAttempts = 4;       // Newton runs per solve, NSGS sweeps in between
// The long Newton after everything else. Its Jacobian regularisation floor is
// 100x the short attempts' (1e-8 of diag(W)): over hundreds of steps on a
// hyperstatic set, the bare Newton step's components along W's near-null
// directions (impulse moved between redundant contacts) throw the iterate
// across kinks and it cycles (C-60 handle step 638 of docs/fclib.md, cold: 1e-7
// after 500 steps; with the floor 6.8e-9).
constexpr NewtonBudget kNewtonLastResort{500, 150, 1e-8};

int problemRows(const std::vector<ProblemBlock>& blocks) {
  int m = 0;
  for (const ProblemBlock& bl : blocks) m = std::max(m, bl.row + bl.size);
  return m;
}

// Squared error of one block given its U (see solverError).
double blockError2(const ProblemBlock& bl, const double* P, const double* U) {
  switch (bl.kind) {
    case BlockKind::Frictional: {
      const Vector3d p(P[0], P[1], P[2]);
      const Vector3d u(U[0], U[1], U[2]);
      const double e = localCoulombError(p, u, bl.mu);
      return e * e;
    }
    case BlockKind::Frictionless: {
      const double e = P[0] - std::max(0.0, P[0] - U[0]);
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

bool validBlocks(const std::vector<ProblemBlock>& blocks, Eigen::Index rows) {
  for (const ProblemBlock& bl : blocks) {
    const int want = bl.kind == BlockKind::Frictional ? 3 : bl.kind == BlockKind::Frictionless ? 1 : -1;
    if (bl.row < 0 || bl.size < 1 || bl.row + bl.size > rows) return false;
    if (want > 0 ? bl.size != want : bl.size > kMaxBilateral) return false;
  }
  return true;
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
  rep.iterations = 1;
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
void growWorkspace(FrictionContactSolver::Workspace& ws, int m, bool newtonAllowed) {
  if (m > ws.maxRows) {
    ws.maxRows = m;
    ws.U.resize(m);
    ws.Pbest.resize(m);
    ws.Pstart.resize(m);
    ws.Pinitial.resize(m);
    ws.phi.resize(m);
    ws.d.resize(m);
    ws.Wd.resize(m);
    ws.Pt.resize(m);
    ws.Ut.resize(m);
    ws.phiT.resize(m);
    ws.rho.resize(m);
    ws.piv.resize(m);
    ws.zeroRow.resize(m);
    ws.localFactor.resize(m);
    ws.eqRows.reserve(m);
  }
  if (newtonAllowed && ws.J.rows() < m) {  // not for NSGS only; capped at the Newton size
    const int cap = std::min(ws.maxRows, kNewtonMaxRows);
    ws.J.resize(cap, cap);
    ws.Wprox.resize(cap, cap);
    ws.bprox.resize(cap);
    ws.Pcentre.resize(cap);
    ws.Pouter.resize(3 * cap);
  }
}

}  // namespace

// Zero rows (planar scenes) keep P = 0; the per-row scaling of the Newton
// function; the equality rows assembled into one block, factored once; U, the
// error and the NSGS bookkeeping of the starting point.
void setUpRun(SolveRun& run, double maxDiag) {
  const auto& W = run.W;
  const int m = run.m;
  SolveRun::Workspace& ws = run.ws;
  run.maxDiag = maxDiag;
  run.zeroDiag = kRelZeroDiag * maxDiag;
  char* zeroRow = ws.zeroRow.data();
  double* rho = ws.rho.data();
  for (int i = 0; i < m; ++i) zeroRow[i] = !(W(i, i) > run.zeroDiag);
  for (const ProblemBlock& bl : run.blocks) {
    const int r = bl.row;
    // A bilateral row's Newton function is its velocity U itself (rho 1), the
    // quantity the error measures: the direction does not depend on a row's
    // scale, but the line search's merit 0.5 |phi|^2 does, and 1 / W_ii (up to
    // 4e9 on the rotation rows of the ideal C-60's light links) let it trade the
    // joints' error for the contacts'. Newton iterations on the ideal C-60 at rest
    // 28 -> 10 a step (bench 10.8 -> 4.9); the paper model's bench 5.5 -> 6.0.
    for (int i = r; i < r + bl.size; ++i) {
      rho[i] = zeroRow[i] || bl.kind == BlockKind::Bilateral ? 1.0 : 1.0 / W(i, i);
      if (zeroRow[i] && bl.kind != BlockKind::Frictionless && (bl.kind == BlockKind::Bilateral || i > r))
        run.P(i) = 0;
    }
    // One scale for the normal and the tangents of a contact (1 / its normal
    // diagonal): the Alart-Curnier disc P_T - rho U_T then lives in the same
    // metric as P_N - rho U_N; separate tangent scales made the Newton stall on
    // the C-60's hyperstatic sets.
    if (bl.kind == BlockKind::Frictional) rho[r + 1] = rho[r + 2] = rho[r];
  }

  ws.eqRows.clear();
  double maxEqDiag = 0;
  for (const ProblemBlock& bl : run.blocks) {
    if (bl.kind != BlockKind::Bilateral) continue;
    for (int i = bl.row; i < bl.row + bl.size; ++i) {
      if (zeroRow[i]) continue;
      ws.eqRows.push_back(i);
      maxEqDiag = std::max(maxEqDiag, W(i, i));
    }
  }
  const int ne = int(ws.eqRows.size());
  run.ne = ne;
  if (ne > ws.maxEq) {
    ws.maxEq = ne;
    ws.eqL.resize(ne, ne);
    ws.eqRhs.resize(2 * ne);
    ws.eqPerm.resize(ne);
  }
  if (ne > 0) {
    for (int c = 0; c < ne; ++c)
      for (int r = 0; r < ne; ++r) ws.eqL(r, c) = W(ws.eqRows[r], ws.eqRows[c]);
    ws.eqRank = pivotedCholesky(ws.eqL.data(), int(ws.eqL.rows()), ne, kEqDrop * maxEqDiag, ws.eqPerm.data());
  }

  run.refreshU();
  run.bnorm = run.b.head(m).norm();
  run.localTol = std::max(1e-14, 1e-2 * run.options.tolerance);
  run.err = errorFromU(run.blocks, run.P.data(), run.U.data(), run.bnorm);
  run.rep.residual = run.err;
  run.bestAll = run.err;  // the best NSGS iterate (returned if not converged)
  ws.Pbest.head(m) = run.P.head(m);
  run.sigma = 0;
  run.stallErr = run.err;
  run.stallIt = 0;
}

namespace {

// Which algorithm runs when. Auto: Newton after one sweep on small problems,
// else when the NSGS rate observed predicts more sweeps than Newton costs
// (checked after kSwitchSweeps, then at doubling sweep counts); NSGS to the
// end; a failed Newton hands back to NSGS where it started (the first failure
// restarts it from P = 0, then from the warm start), with up to kNewtonAttempts
// attempts in all between runs of sweeps; the proximal Newton (its own budget)
// when the last attempt fails, and again from the best iterate if all that fell
// short; then one long Newton; then the cone fixed point (cone_fixed_point.cpp)
// and a long Newton from its answer. False on a non-finite iterate.
bool runSchedule(SolveRun& run, bool newtonAllowed) {
  SolveRun::Workspace& ws = run.ws;
  const SolverOptions& options = run.options;
  SolverReport& rep = run.rep;
  int attempts = 0;
  // The proximal Newton from the best iterate. restore: if it fails, the run goes
  // on exactly as if it had not been tried (P, the best iterate and the Newton
  // start as they were).
  const auto runProximal = [&](bool restore) {
    const int m = run.m;
    // The NSGS state to go back to: vectors in ws.Pouter, scalars here.
    const double bestAll = run.bestAll, sigma = run.sigma, stallErr = run.stallErr;
    const int stallIt = run.stallIt;
    if (restore) {
      ws.Pouter.head(m) = run.P.head(m);
      ws.Pouter.segment(m, m) = ws.Pbest.head(m);
      ws.Pouter.segment(2 * m, m) = ws.Pstart.head(m);
    }
    if (run.bestAll < run.err) {
      run.P.head(m) = ws.Pbest.head(m);
      setUpRun(run, run.maxDiag);
    }
    if (runProximalNewton(run)) return true;
    if (restore) {
      run.P.head(m) = ws.Pouter.head(m);
      setUpRun(run, run.maxDiag);
      ws.Pbest.head(m) = ws.Pouter.segment(m, m);
      ws.Pstart.head(m) = ws.Pouter.segment(2 * m, m);
      run.bestAll = bestAll;
      run.sigma = sigma;
      run.stallErr = stallErr;
      run.stallIt = stallIt;
    }
    return false;
  };
  // A failed Newton hands back to NSGS where it started. The first failure
  // restarts from P = 0: a warm start carried over from the last step can sit
  // far out along the null space of W (hyperstatic sets), where the Newton
  // stalls; from a clean start it mostly converges.
  int firstSweeps = 0;  // sweeps before the first Newton attempt
  // A Newton from another start (P = 0 if start is null), one sweep on; the best
  // iterate so far stays on offer. True if the solve is over (converged, or a
  // non-finite sweep).
  const auto newtonFrom = [&](const double* start) {
    const int m = run.m;
    const double bestBefore = run.bestAll;
    ws.Pouter.head(m) = ws.Pbest.head(m);
    if (start) run.P.head(m) = Eigen::Map<const Eigen::VectorXd>(start, m);
    else run.P.head(m).setZero();
    setUpRun(run, run.maxDiag);
    if (bestBefore < run.bestAll) {
      run.bestAll = bestBefore;
      ws.Pbest.head(m) = ws.Pouter.head(m);
    }
    if (!runNsgs(run, rep.sweeps + 1) || rep.converged) return true;
    ws.Pstart.head(m) = run.P.head(m);
    return runNewton(run);
  };
  const auto tryNewton = [&] {
    if (++attempts == 1) firstSweeps = rep.sweeps;
    if (runNewton(run)) return;
    // All plain attempts failed: the proximal Newton, before the sweeps go on.
    if (attempts == kNewtonAttempts && runProximal(true)) return;
    resumeNsgs(run);
    if (attempts != 1) return;
    const double bestBefore = run.bestAll;
    if (newtonFrom(nullptr)) return;
    // A third start: the warm start, one sweep on, when the first one was many
    // sweeps away from it (a C-60 handle step: the Newton converges in 31
    // iterations from there, and from neither of the other two).
    if (firstSweeps > 1 && ws.Pinitial.head(run.m).cwiseAbs().maxCoeff() > 0 &&
        newtonFrom(ws.Pinitial.data()))
      return;
    // All starts failed: the sweeps go on from the best iterate so far.
    if (run.bestAll < bestBefore || run.bestAll >= run.err) {
      resumeNsgs(run);
      return;
    }
    run.P.head(run.m) = ws.Pbest.head(run.m);
    setUpRun(run, run.maxDiag);
    run.stallIt = rep.sweeps;
  };
  bool ok = true;
  if (newtonAllowed && options.method == SolverMethod::ProximalNewton) {
    ok = runNsgs(run, 1);
    if (ok && !rep.converged) {
      ++attempts;
      runProximalNewton(run);
      attempts = kNewtonAttempts;  // no plain Newton after it
    }
  } else if (newtonAllowed && (options.method == SolverMethod::Newton || run.m <= kNewtonSmallRows)) {
    ok = runNsgs(run, 1);
    if (ok && !rep.converged) tryNewton();
  } else if (newtonAllowed) {
    const double newtonCost = kNewtonCostIterations * (1 + run.m / kLuRowsPerSweep);
    int check = kSwitchSweeps;
    double errRef = run.err;
    int itRef = 0;
    while (ok && !rep.converged && attempts == 0 && rep.sweeps < options.max_iterations) {
      ok = runNsgs(run, std::min(check, options.max_iterations));
      if (!ok || rep.converged || rep.sweeps >= options.max_iterations) break;
      const double rate = std::pow(run.err / errRef, 1.0 / (rep.sweeps - itRef));
      const double remaining =
          rate < 1 ? std::log(options.tolerance / run.err) / std::log(rate) : INFINITY;
      if (remaining > newtonCost) tryNewton();
      errRef = run.err;
      itRef = rep.sweeps;
      check *= 2;
    }
  }
  // NSGS to the end; after a failed Newton, a few sweeps move the iterate to
  // another start for a new Newton attempt.
  while (ok && !rep.converged && rep.sweeps < options.max_iterations) {
    const bool retry = attempts > 0 && attempts < kNewtonAttempts;
    ok = runNsgs(run, retry ? std::min(rep.sweeps + kSwitchSweeps, options.max_iterations)
                            : options.max_iterations);
    if (ok && !rep.converged && retry && rep.sweeps < options.max_iterations) tryNewton();
  }
  // Last resort: the proximal Newton from the best iterate.
  if (ok && !rep.converged && newtonAllowed) runProximal(false);
  // Then one long Newton from P = 0. Some frictional sets converge only after a
  // few hundred Newton steps whose error does not halve every 25 (a C-60 trip
  // step of 22 contacts: 305 steps; Siconos's NSN-AC takes 638): too slow to try
  // on every hard solve, where the sweeps and short attempts usually win, but
  // better than returning unconverged. If it fails, the best iterate stays.
  if (ok && !rep.converged && newtonAllowed) {
    const double bestBefore = std::min(run.bestAll, run.err);
    if (run.bestAll < run.err) ws.Pouter.head(run.m) = ws.Pbest.head(run.m);
    else ws.Pouter.head(run.m) = run.P.head(run.m);
    run.P.head(run.m).setZero();
    setUpRun(run, run.maxDiag);
    if (!rep.converged && !runNewton(run, kNewtonLastResort) && bestBefore < run.err) {
      run.P.head(run.m) = ws.Pouter.head(run.m);
      setUpRun(run, run.maxDiag);
    }
  }
  // Then the cone fixed point, where the Newton stages fail for conditioning.
  if (ok && !rep.converged && newtonAllowed) runConeFixedPoint(run);
  return ok;
}

// The report; if not converged, the best iterate and its error on the exact U.
void finishRun(SolveRun& run, bool ok) {
  SolverReport& rep = run.rep;
  rep.iterations = rep.sweeps + rep.newton_iterations + rep.interior_point_iterations;
  if (!ok) {
    rep.residual = INFINITY;
    return;
  }
  if (!rep.converged) {
    if (run.bestAll < run.err) run.P.head(run.m) = run.ws.Pbest.head(run.m);
    run.refreshU();
    run.err = errorFromU(run.blocks, run.P.data(), run.U.data(), run.bnorm);
  }
  rep.residual = run.err;
}

}  // namespace

double errorFromU(const std::vector<ProblemBlock>& blocks, const double* P, const double* U,
                  double bnorm) {
  double s = 0;
  for (const ProblemBlock& bl : blocks) s += blockError2(bl, P + bl.row, U + bl.row);
  return std::sqrt(s) / std::max(1.0, bnorm);
}

double solverError(const Eigen::Ref<const Eigen::MatrixXd>& W,
                   const Eigen::Ref<const Eigen::VectorXd>& b,
                   const Eigen::Ref<const Eigen::VectorXd>& P,
                   const std::vector<ProblemBlock>& blocks) {
  const int m = problemRows(blocks);
  if (m == 0) return 0;
  if (!validBlocks(blocks, std::min({W.rows(), W.cols(), b.size(), P.size()}))) return INFINITY;
  double s = 0;
  for (const ProblemBlock& bl : blocks) {
    // Row block of U = W P + b, fixed-capacity result: no allocation.
    BVec u = b.segment(bl.row, bl.size);
    u.noalias() += W.block(bl.row, 0, bl.size, m) * P.head(m);
    s += blockError2(bl, P.data() + bl.row, u.data());
  }
  const double bnorm = b.head(m).norm();
  if (!std::isfinite(bnorm)) return INFINITY;
  const double e = std::sqrt(s) / std::max(1.0, bnorm);
  return std::isfinite(e) ? e : INFINITY;
}

SolverReport FrictionContactSolver::solve(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                          const Eigen::Ref<const Eigen::VectorXd>& b,
                                          const std::vector<ProblemBlock>& blocks,
                                          const SolverOptions& options,
                                          Eigen::Ref<Eigen::VectorXd> P) {
  SolverReport rep;
  rep.residual = INFINITY;
  const int m = problemRows(blocks);
  if (m == 0) {
    rep.residual = 0;
    rep.converged = true;
    return rep;
  }
  if (!validBlocks(blocks, std::min({W.rows(), W.cols(), b.size(), P.size()}))) return rep;
  if (solveSingleContact(W, b, blocks, options, P, rep)) return rep;
  double maxDiag = 0;
  if (!finiteProblem(W, b, m, maxDiag)) return rep;
  if (!P.head(m).allFinite()) P.head(m).setZero();  // a poisoned warm start is dropped
  const bool newtonAllowed = options.method != SolverMethod::NSGS && m <= kNewtonMaxRows;
  growWorkspace(ws_, m, newtonAllowed);

  SolveRun run(W, b, blocks, options, P, ws_, m);
  setUpRun(run, maxDiag);
  ws_.Pinitial.head(m) = P.head(m);
  if (run.err <= options.tolerance) {
    run.rep.converged = true;
    return run.rep;
  }
  const bool ok = runSchedule(run, newtonAllowed);
  finishRun(run, ok);
  return run.rep;
}

}  // namespace nscd
