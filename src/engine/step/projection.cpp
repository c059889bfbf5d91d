// Stage 6: combined projection (Acary 2013). After the velocity step, positions
// are projected onto {g(q) >= 0, h(q) = 0} by a position-level complementarity
// problem on the normal rows: 0 <= g + G M^-1 G^T tau  _|_  tau >= 0 (equalities
// for bilateral rows), dq = M^-1 G^T tau, repeated until the violation is below
// the tolerance (a length, well below the smallest clearance). Each pass gathers
// the rows once: the check of its violation gives the rows it corrects. In a
// model of ideal joints alone, the first pass may take the velocity stage's
// operator instead of its own (velocityFactorReusable).
#include <algorithm>
#include <cmath>

#include "geometry/least_distance.hpp"
#include "step_stages.hpp"

namespace nscd {

// One pass over the rows (a projection pass's cost counts: see solvePass).
void positionProblem(const State& s, StepWorkspace& ws) {
  ws.problem.clear();
  for (const ConstraintBlock& blk : ws.blocks) {
    if (blk.kind != BlockKind::Bilateral) writeJacobianRows(s, blk, ws.G);  // see activateContacts
    ProblemBlock pb;
    pb.kind = blk.kind;
    pb.row = blk.row;
    pb.size = blk.size;
    ws.problem.push_back(pb);
    if (blk.kind == BlockKind::Bilateral)
      for (int k = 0; k < blk.size; ++k) ws.b[blk.row + k] = blk.error[k];
    else
      ws.b[blk.row] = blk.contact.cp.gap;
  }
}

namespace {

constexpr int kProjectionBacktracks = 4;
// The largest turn of a body over the step (rad) for which the first pass takes
// the velocity stage's operator (velocityFactorReusable).
constexpr double kMaxChordTurn = 0.02;
// A least-distance correction larger than this many times the unsolved
// complementarity answer it would replace is not used.
constexpr double kLeastDistanceGrowth = 10;

// The rows of the position-level problem at the state: bilateral rows and a
// normal row per contact candidate. `ring_hint` starts the ring searches.
// jacobian false (a model without contact sources): the bilateral rows'
// errors only, where appendBilateralRows can skip G (a check whose rows no
// pass uses); such rows are not keyed.
void gatherPositionRows(const Model& m, const State& s, CandidateMode mode, double extra_margin,
                        double* ring_hint, StepWorkspace& ws, bool jacobian = true) {
  clearConstraintRows(ws);
  // Prescribed rates do not matter at the position level.
  appendBilateralRows(m, s, ws.zero_rates, ws, jacobian);
  if (jacobian) keyRowsOnPoses(s, ws);  // the next step's rows, if the bodies stay here
  if (!hasContactSources(ws)) return;
  findContactCandidates(m, s, 0.0, mode, extra_margin, ring_hint, ws);
  activateContacts(m, s, 0.0, mode, ws);
}

double violationOfBlocks(const StepWorkspace& ws, double* bilateral) {
  double pen = 0, bil = 0;
  for (const ConstraintBlock& blk : ws.blocks) {
    if (blk.kind == BlockKind::Bilateral) {
      for (int k = 0; k < blk.size; ++k) bil = std::max(bil, std::abs(blk.error[k]));
    } else {
      pen = std::max(pen, -blk.contact.cp.gap);
    }
  }
  if (bilateral) *bilateral = bil;
  return pen;
}

// The correction of this pass as the least-distance problem it is the dual of:
// min |y| over G L y >= -g (= -err for bilateral rows), with L L^T = M^-1
// (planar-projected), dq = L y. For passes whose complementarity problem the
// solver did not solve. False (ws.dq kept) if infeasible. Allocates: a fallback.
bool leastDistanceCorrection(StepWorkspace& ws) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(ws.mass_inverse);
  const Eigen::VectorXd& lam = eig.eigenvalues();
  const double floor = 1e-12 * lam.maxCoeff();
  int k = 0;
  for (int i = 0; i < lam.size(); ++i) k += lam(i) > floor;
  Eigen::MatrixXd L(ws.n, k);
  for (int i = 0, j = 0; i < lam.size(); ++i)
    if (lam(i) > floor) L.col(j++) = eig.eigenvectors().col(i) * std::sqrt(lam(i));
  int rows = 0;
  for (const ConstraintBlock& blk : ws.blocks) rows += blk.kind == BlockKind::Bilateral ? 2 * blk.size : 1;
  Eigen::MatrixXd A(rows, k);
  Eigen::VectorXd c(rows);
  int i = 0;
  for (const ConstraintBlock& blk : ws.blocks) {
    if (blk.kind != BlockKind::Bilateral) {
      A.row(i) = ws.G.row(blk.row).head(ws.n) * L;
      c(i++) = -blk.contact.cp.gap;
      continue;
    }
    for (int q = 0; q < blk.size; ++q) {  // equality: both inequalities
      A.row(i) = ws.G.row(blk.row + q).head(ws.n) * L;
      c(i++) = -blk.error[q];
      A.row(i) = -A.row(i - 1);
      c(i) = -c(i - 1);
      ++i;
    }
  }
  Eigen::VectorXd y;
  if (!leastDistance(A, c, y)) return false;
  ws.dq.noalias() = L * y;
  return ws.dq.allFinite();
}

// The pass's problem from the rows gathered at the state: b = g (the bilateral
// rows' errors), W = G M^-1 G^T (and Y = M^-1 G^T), solved into ws.P. For the
// first pass of a step whose operator may be reused (reuse), the velocity
// stage's factor and Y instead, where the solver still holds it. True if
// solved (a reused factor always is).
// jacobian false (rows gathered without G): false unless the factor is reused.
bool solvePass(const State& s, StepWorkspace& ws, bool reuse, bool jacobian, const SolverOptions& opt) {
  const int r = ws.rows;
  positionProblem(s, ws);
  // The step's own factor (equality_step.cpp) where it took the direct path, else the solver's.
  if (reuse && ws.equality.factor_rows == r) {
    solveWithEqualityFactor(ws, r, ws.b.data(), ws.P.data());
    ws.projection_reused_factor = true;
  } else {
    ws.projection_reused_factor = reuse && ws.solver.solveEqualitiesAgain(ws.b.head(r), ws.P.head(r));
  }
  if (ws.projection_reused_factor) return true;
  if (!jacobian) return false;  // the caller gathers G and comes back
  assembleDelassus(ws.mass_inverse, true, ws, 0, r);  // M^-1: one block per body
  ws.P.head(r).setZero();
  return ws.solver.solve(ws.W.topLeftCorner(r, r), ws.b.head(r), ws.problem, opt, ws.P.head(r)).converged;
}

// The least-distance answer replaces the unsolved one unless it is far larger:
// a near-infeasible set of rows (a point reported deep behind a surface patch)
// made it move a C-60 plate by 0.37 m.
void replaceUnsolvedPass(StepWorkspace& ws, StepStats& st) {
  const double unsolved = ws.dq.lpNorm<Eigen::Infinity>();
  ws.saved_dq = ws.dq;
  if (!leastDistanceCorrection(ws)) return;
  if (ws.dq.allFinite() && ws.dq.lpNorm<Eigen::Infinity>() <= kLeastDistanceGrowth * unsolved)
    ++st.projection_least_distance;
  else
    ws.dq = ws.saved_dq;
}

// Backtracking: the linearised correction can overshoot where the gaps are
// curved on the scale of the correction (a journal far outside a small
// clearance, coupled joints) and the passes would then oscillate. Takes the
// longest of 1, 1/2, 1/4, 1/8 of it that lowers the violation (else 1/8).
// True if the rows in ws are those of the positions it leaves (its last check
// was of them, with the margin the next pass gathers with).
bool applyWithBacktracking(const Model& m, State& s, StepWorkspace& ws, double violation,
                           double* hint) {
  ws.saved_bodies = s.bodies;
  for (int k = 0; k < kProjectionBacktracks; ++k) {
    if (k > 0) {
      s.bodies = ws.saved_bodies;
      ws.dq *= 0.5;
    }
    applyDisplacement(s, ws.dq);
    if (k + 1 == kProjectionBacktracks) return false;
    gatherPositionRows(m, s, CandidateMode::Projection, 0.0, hint, ws);
    double bil_t = 0;
    const double pen_t = violationOfBlocks(ws, &bil_t);
    // Without contacts the margin changes nothing: these rows are the next pass's.
    if (std::max(pen_t, bil_t) < violation) return !hasContactSources(ws);
  }
  return false;
}

}  // namespace

bool velocityFactorReusable(double h, const StepWorkspace& ws) {
  // Only where the rows are the same ones (no contacts to come and go) and the
  // step's operator is the projection's (Ŵ = M^-1).
  if (hasContactSources(ws) || ws.facts.stiff || ws.rows == 0) return false;
  double w2 = 0;
  for (int b = 0; b < ws.nbodies; ++b)
    w2 = std::max({w2, ws.vk.segment<3>(6 * b + 3).squaredNorm(), ws.vnew.segment<3>(6 * b + 3).squaredNorm()});
  return h * h * w2 <= kMaxChordTurn * kMaxChordTurn;
}

double measureViolation(const Model& m, const State& s, StepWorkspace& ws, double* bilateral) {
  ws.ring_hint = s.ring_hint;  // a copy: a query leaves the state as it is
  gatherPositionRows(m, s, CandidateMode::Measure, 0.0, ws.ring_hint.data(), ws);
  return violationOfBlocks(ws, bilateral);
}

int projectPositions(const Model& m, State& s, StepWorkspace& ws, int max_passes, double tol,
                     double& violation, StepStats& st, bool reuse, int stall_passes) {
  // Penetrating rings get tangent facets (CandidateMode::Projection) from the
  // first pass; backtracking only from the second, which is needed only where
  // the first pass was not enough.
  const CandidateMode mode = CandidateMode::Projection;
  double* hint = s.ring_hint.data();
  double extra = 0;
  SolverOptions opt;
  opt.tolerance = 0.01 * tol;
  opt.max_iterations = 500;
  bool rows_current = false;  // ws holds the rows of the state as it is
  double mark = 0;            // the violation the passes since mark_pass have to halve
  int mark_pass = 0;
  for (int pass = 0;; ++pass) {
    copyRingHints(s.ring_hint, ws.check_hint);  // same size: no allocation
    // The first check before a pass on the velocity stage's operator needs the
    // rows' errors only (reuse: no contact sources); G is gathered where it
    // turns out to be needed after all (the next step's rows, or a pass on its
    // own operator).
    const bool jacobian = !(reuse && pass == 0);
    if (!rows_current) gatherPositionRows(m, s, mode, extra, hint, ws, jacobian);
    double bil = 0;
    const double pen = violationOfBlocks(ws, &bil);
    violation = std::max(pen, bil);
    if (stall_passes > 0 && (pass == 0 || violation <= 0.5 * mark)) {
      mark = violation;
      mark_pass = pass;
    }
    const bool stalled = stall_passes > 0 && pass - mark_pass >= stall_passes;
    if (violation <= tol || pass >= max_passes || stalled) {
      if (!jacobian) {  // the same state (no contacts: jacobian is false only without them)
        completeBilateralRows(m, s, ws);
        keyRowsOnPoses(s, ws);
      }
      // The last check leaves the ring hints as it found them: the next step's
      // search starts where this one did, and may take its points (exact).
      copyRingHints(ws.check_hint, s.ring_hint);
      return pass;
    }
    // Contacts within reach of the correction join the problem so that fixing
    // one violation does not create another.
    if (extra < 2 * violation && hasContactSources(ws)) {
      extra = 2 * violation;
      gatherPositionRows(m, s, mode, extra, hint, ws);
    }
    bool solved = solvePass(s, ws, reuse && pass == 0, jacobian, opt);
    if (!solved && !jacobian) {  // the factor was not there to reuse
      gatherPositionRows(m, s, mode, extra, hint, ws);
      solved = solvePass(s, ws, false, true, opt);
    }
    ws.dq.noalias() = ws.Y.leftCols(ws.rows) * ws.P.head(ws.rows);
    if (!solved) replaceUnsolvedPass(ws, st);
    if (!ws.dq.allFinite()) return pass;
    rows_current = false;
    if (pass == 0) {
      ws.unprojected_bodies = s.bodies;  // same size: no allocation (the energy take-back's reference)
      applyDisplacement(s, ws.dq);
    } else {
      rows_current = applyWithBacktracking(m, s, ws, violation, hint);
    }
  }
}

}  // namespace nscd
