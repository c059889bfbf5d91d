// The one-step nonsmooth problem: find impulses P and local velocities
// U = W P + b such that, block by block,
//   - Bilateral (size k rows): U = 0, P free;
//   - Frictionless (1 row: normal): 0 <= U_N  _|_  P_N >= 0;
//   - Frictional (3 rows: normal, tangent 1, tangent 2): Coulomb's law with
//     coefficient mu (equivalently the SOCCP K* ∋ U + mu|U_T| e_N  _|_  P ∈ K).
// b already holds the restitution term of the Newton impact law.
// Solved by a schedule of stages (src/engine/solver/solver_schedule.cpp,
// docs/solver.md). A problem of bilateral rows only (ideal joints; the
// position projection's joint rows) is a linear system: one LDLᵀ of W
// solves it (SolverStage::Equalities; rows so nearly dependent that it leaves
// them unsolved go on to the general schedule). Any other: nonsmooth
// Gauss-Seidel (NSGS) sweeps over the blocks with an exact local solver per
// block, warm-started from the P passed in (all Bilateral rows assembled into
// one equality block solved exactly in each sweep); a global semismooth Newton
// on the Alart-Curnier function when the sweeps converge slowly; and, for what
// they leave unsolved, the proximal Newton, a long Newton and the cone fixed
// point. SolverReport::stage names the stage that gave the answer.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

namespace nscd {

struct ConeFixedPointBuffers;  // cone_fixed_point.cpp

// The sticking stage's factor of the last matrix it factored, kept for the next call
// on the same contact (NSGS sweeps solve each contact again with the same W): used
// when that matrix is bit for bit the same, so the answer is the same as without it.
struct LocalFactorCache {
  bool valid = false;
  Eigen::Matrix3d W;
  // Its LDLT factor in place and the pivots (local_contact_solver.cpp), unless
  // factored is false (a zero first pivot: Eigen's LDLT is used instead).
  bool factored = false;
  Eigen::Matrix3d factor;
  int perm[3] = {0, 1, 2};
};

enum class BlockKind { Bilateral, Frictionless, Frictional };

struct ProblemBlock {
  BlockKind kind = BlockKind::Frictional;
  int row = 0;    // first row in W, b, P
  int size = 3;   // 1 for Frictionless, 3 for Frictional, 1..6 for Bilateral
  double mu = 0;  // Frictional only
};

// The rows a contact block of this kind has (3: normal and two tangents; 1); 0 for a
// bilateral block, whose size is its own. The solver answers `failed` to any other.
constexpr int rowsOfKind(BlockKind kind) {
  return kind == BlockKind::Frictional ? 3 : kind == BlockKind::Frictionless ? 1 : 0;
}

// Which schedule runs (solver_schedule.cpp). Auto: NSGS, switching to the
// global Newton after one sweep on small problems or when the measured NSGS rate
// predicts many more sweeps, then the stages for what that leaves unsolved;
// NSGS: sweeps only; Newton: as Auto, the Newton after one sweep whatever the
// size; ProximalNewton: one sweep, then the proximal Newton at once (for solver
// studies).
enum class SolverMethod { Auto, NSGS, Newton, ProximalNewton };

// The stages of a solve (solver_schedule.cpp, docs/solver.md), in the order the
// schedule runs them; SolverReport::stage names the one that gave the answer.
enum class SolverStage : std::uint8_t {
  NoRows,          // the problem has no rows
  LocalSolver,     // one frictional contact: the exact local solver alone
  Equalities,      // bilateral rows only: one LDLᵀ of W (and up to two refinements)
  WarmStart,       // the warm start already met the tolerance
  Sweeps,          // NSGS (proximal after stalls) until the Newton is expected to be cheaper
  Newton,          // a short global Newton from the sweeps' iterate
  NewtonFromZero,  // one sweep from P = 0, then a short Newton
  NewtonFromWarm,  // one sweep from the warm start, then a short Newton
  NewtonRetry,     // up to three more short Newtons, one sweep apart
  ProximalTrial,   // the proximal Newton after the last short Newton (dropped if it fails)
  SweepsToBudget,  // NSGS up to the sweep budget
  ProximalNewton,  // the proximal Newton from the best iterate
  LongNewton,      // a Newton of up to 500 iterations from P = 0
  ConeFixedPoint,  // the cone fixed point (interior-point solves), a Newton from its answer
  Unsolved,        // no stage met the tolerance: the best iterate is the answer
  Failed,          // invalid (a block past W's rows, rows not covered once each) or
                   // non-finite input, or a non-finite iterate
};
constexpr int kSolverStageCount = 16;
// "no_rows", "local_solver", "equalities", "warm_start", "sweeps", ... (snake case of the above).
const char* solverStageName(SolverStage stage);

struct SolverOptions {
  double tolerance = 1e-8;   // on the normalised error (see solverError)
  int max_iterations = 200;  // bounds the NSGS sweeps, and separately the Newton iterations
  SolverMethod method = SolverMethod::Auto;
  // Bit s set: the schedule's rows of SolverStage s are skipped (solver studies:
  // what the others do without it; nscd_solve_problems --skip-stage).
  std::uint32_t skip_stages = 0;
};

struct SolverReport {
  // sweeps + newton_iterations + interior_point_iterations: steps of unlike cost
  // summed into one work count (what StepStats::iterations and the CSV's iters add up).
  // (A direct solve, SolverStage::Equalities, counts its solves with the factor
  // as sweeps: one, or two or three with refinements.)
  int iteration_sum = 0;
  double residual = 0;        // solverError at exit
  bool converged = false;
  int sweeps = 0;             // NSGS sweeps
  int newton_iterations = 0;  // global Newton iterations (each: one m x m LU)
  int interior_point_iterations = 0;  // of the cone fixed point (each: one m x m LU)
  SolverStage stage = SolverStage::Failed;  // the stage that gave the answer
};

// Siconos-style error: sqrt(sum over blocks of e_c^2 (+ |U|^2 for bilateral
// rows)) / max(1, |b|), e_c = |P - proj_K(P - Uhat)| of a contact, raised to
// max(1, |b|) |P_N| if P_N < 0: a pull is no answer of the contact law, so an
// answer within a tolerance has P_N >= -tolerance on every contact, whatever |b|.
double solverError(const Eigen::Ref<const Eigen::MatrixXd>& W,
                   const Eigen::Ref<const Eigen::VectorXd>& b,
                   const Eigen::Ref<const Eigen::VectorXd>& P,
                   const std::vector<ProblemBlock>& blocks);

// Reusable solver: keeps its buffers between calls (no allocation once warm,
// as long as the problem does not grow).
class FrictionContactSolver {
 public:
  // W: m x m symmetric positive semidefinite Delassus operator (only the top-left
  // m x m part of the matrices passed is read; m: the last row of a block). The
  // blocks cover rows 0..m-1 once each, in any order (else Failed). P: in = warm
  // start, out = solution (if not converged: the best iterate the stages found).
  SolverReport solve(const Eigen::Ref<const Eigen::MatrixXd>& W,
                     const Eigen::Ref<const Eigen::VectorXd>& b,
                     const std::vector<ProblemBlock>& blocks, const SolverOptions& options,
                     Eigen::Ref<Eigen::VectorXd> P);

  // Another right-hand side for the W of the last problem solved, when that one
  // had bilateral rows only (SolverStage::Equalities factored its W): P = -W⁺ b
  // from the same factor (zero and dependent rows 0), m = P.size() rows. False,
  // P untouched, if the last solve made no such factor or had another size. The
  // caller vouches that W is the same (the position projection: step_stages.hpp).
  bool solveEqualitiesAgain(const Eigen::Ref<const Eigen::VectorXd>& b, Eigen::Ref<Eigen::VectorXd> P);

  // The solver's buffers, grown to the largest problem seen, never shrunk
  // (internal: src/engine/solver, solve_run.hpp).
  struct Buffers {
    int maxRows = 0;            // capacity in rows
    int maxEq = 0;              // capacity in equality rows
    Eigen::VectorXd U, Pbest, Pstart;  // running local velocities; best iterate; Newton start
    Eigen::VectorXd Pinitial;          // the warm start the solve was given
    Eigen::VectorXd Ptrial;            // a trial stage's iterate (kept only if it solves)
    Eigen::MatrixXd eqL;        // Cholesky factor of the assembled equality block
    Eigen::VectorXd eqRhs;
    std::vector<int> eqRows;    // rows of the equality block (W order)
    std::vector<int> eqPerm;    // its diagonal pivoting order
    int eqRank = 0;
    // An equality-only problem (SolverStage::Equalities): eqL holds the LDLᵀ
    // factor of its W scaled to a unit diagonal by eqScale (1 / sqrt(W_ii)),
    // in the order eqPerm; its size m while that factor stands
    // (solveEqualitiesAgain), else 0.
    Eigen::VectorXd eqScale;
    int equalityFactorRows = 0;
    Eigen::MatrixXd J;          // Newton: Jacobian, LU in place
    Eigen::VectorXd phi, d, Wd, Pt, Ut, phiT, rho;
    std::vector<int> piv;
    std::vector<char> zeroRow;  // W(i, i) negligible: P_i = 0
    // Proximal Newton: the shifted problem W + sigma D, b - sigma D P_k, its
    // centre P_k, and its best iterate.
    Eigen::MatrixXd Wprox;
    Eigen::VectorXd bprox, Pcentre, proxBest;
    // The cone fixed point's buffers, made when it first runs.
    std::shared_ptr<ConeFixedPointBuffers> cone;
    // NSGS: the local solver's sticking factor per row (a frictional block's first).
    std::vector<LocalFactorCache> localFactor;
  };

 private:
  Buffers buffers_;
};

// The exact local problem of one frictional contact:
// U = Wloc P + bloc, Coulomb's law with mu. Alart-Curnier semismooth Newton with a
// line search, a projection fixed point as fallback. Returns false if neither
// reached `tol` (P then holds the best iterate found).
bool solveLocalFrictional(const Eigen::Matrix3d& Wloc, const Eigen::Vector3d& bloc, double mu,
                          double tol, Eigen::Vector3d& P);

// Which stage of solveLocalFrictional produced the answer (for statistics/tests).
enum class LocalStage { TakeOff, Frictionless, WarmStart, Stick, Newton, FixedPoint, SlipAngle, Failed };
struct LocalSolveInfo {
  LocalStage stage = LocalStage::Failed;
  int newton_iterations = 0;
  double error = 0;  // localCoulombError at exit (absolute)
};
// Same as above, also reporting the stage that succeeded (info may be null).
bool solveLocalFrictional(const Eigen::Matrix3d& Wloc, const Eigen::Vector3d& bloc, double mu,
                          double tol, Eigen::Vector3d& P, LocalSolveInfo* info);

// Same as above with a LocalFactorCache (may be null).
bool solveLocalFrictional(const Eigen::Matrix3d& Wloc, const Eigen::Vector3d& bloc, double mu,
                          double tol, Eigen::Vector3d& P, LocalSolveInfo* info,
                          LocalFactorCache* cache);

// Projection onto K = {x : |x_T| <= mu x_N} (row 0 normal, rows 1-2 tangential).
Eigen::Vector3d projectFrictionCone(const Eigen::Vector3d& x, double mu);

// |P - proj_K(P - Uhat)| with Uhat = U + mu|U_T| e_N: zero iff (U, P) obey Coulomb's law.
double localCoulombError(const Eigen::Vector3d& P, const Eigen::Vector3d& U, double mu);

}  // namespace nscd
