// One FrictionContactSolver kept across problems (a Simulator keeps its own,
// nscd_solve_problems one for all its files) answers each as a fresh solver does,
// bit for bit: its buffers, grown to the largest problem seen and never shrunk,
// carry nothing from one solve into the next. The problem_file fuzz target solves
// each input on a solver of its own, so that a finding reproduces from its input
// alone; these tests are the check of reuse across sizes, block layouts and
// schedules, in many orders.
#include <algorithm>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "nscd_sim/friction_contact_solver.hpp"
#include "nscd_sim/problem_file.hpp"
#include "test_support.hpp"

using namespace nscd;

namespace {

struct Problem {
  std::string name;
  Eigen::MatrixXd W;
  Eigen::VectorXd b, P_start;
  std::vector<ProblemBlock> blocks;
  SolverOptions options;
};

struct Answer {
  Eigen::VectorXd P;
  SolverReport report;
};

Answer solveWith(FrictionContactSolver& solver, const Problem& p) {
  Answer a{p.P_start, {}};
  a.report = solver.solve(p.W, p.b, p.blocks, p.options, a.P);
  return a;
}

// The same bits: P, the report's every field.
bool identical(const Answer& x, const Answer& y) {
  const SolverReport &r = x.report, &s = y.report;
  return x.P.size() == y.P.size() && std::memcmp(x.P.data(), y.P.data(), sizeof(double) * x.P.size()) == 0 &&
         std::memcmp(&r.residual, &s.residual, sizeof(double)) == 0 && r.converged == s.converged &&
         r.iteration_sum == s.iteration_sum && r.sweeps == s.sweeps && r.newton_iterations == s.newton_iterations &&
         r.interior_point_iterations == s.interior_point_iterations && r.stage == s.stage;
}

// The problem of the first n blocks of a file (rows up to the last of them).
Problem firstBlocks(const ProblemFile& f, const std::string& name, int n) {
  Problem p;
  p.name = name;
  int m = 0;
  for (int k = 0; k < n; ++k) {
    p.blocks.push_back(f.blocks[k]);
    m = std::max(m, f.blocks[k].row + f.blocks[k].size);
  }
  p.W = f.W.topLeftCorner(m, m);
  p.b = f.b.head(m);
  p.P_start = f.P_start.head(m);
  return p;
}

// The repository's problem files (a C-60 set of 60 rows, a slider-crank, two stress
// cases) and problems made from them: smaller ones (their first blocks), mu = 0,
// bilateral rows only (the direct solve), half bilateral, the blocks in reverse
// order, normal rows only (frictionless), no blocks, a contact doubled (W
// singular), a tangent row zeroed, W and b scaled, each schedule, a small budget,
// from zero.
std::vector<Problem> problems() {
  std::vector<Problem> out;
  for (const char* file : {"c60_handle_dt1e-5_step638.txt", "slider_crank_planar_dt2e-6_step14459.txt",
                           "stress_case384_step186.txt", "stress_case446_step402.txt"}) {
    const ProblemFile f = readProblemFile(nscd_test::sourceDir() + "/test/problems/" + file);
    const int nb = int(f.blocks.size());
    for (int n = 1; n < nb; n += std::max(1, nb / 5)) out.push_back(firstBlocks(f, file + (":" + std::to_string(n)), n));
    const Problem full = firstBlocks(f, file, nb);
    out.push_back(full);
    const auto variant = [&](const char* what, auto change) {
      Problem p = full;
      p.name += std::string(":") + what;
      change(p);
      out.push_back(p);
    };
    variant("cold", [](Problem& p) { p.P_start.setZero(); });
    variant("mu0", [](Problem& p) {
      for (ProblemBlock& bl : p.blocks) bl.mu = 0;
    });
    variant("bilateral", [](Problem& p) {
      for (ProblemBlock& bl : p.blocks) bl.kind = BlockKind::Bilateral;
    });
    variant("half_bilateral", [](Problem& p) {
      for (size_t k = 0; k < p.blocks.size(); k += 2) p.blocks[k].kind = BlockKind::Bilateral;
    });
    variant("reversed", [](Problem& p) { std::reverse(p.blocks.begin(), p.blocks.end()); });
    variant("no_blocks", [](Problem& p) { p.blocks.clear(); });
    variant("scaled", [](Problem& p) {
      p.W *= 1e6;
      p.b *= 1e-3;
    });
    variant("tangent_zeroed", [](Problem& p) {
      for (const ProblemBlock& bl : p.blocks)
        if (bl.kind == BlockKind::Frictional) {
          p.W.row(bl.row + 2).setZero();
          p.W.col(bl.row + 2).setZero();
          p.b(bl.row + 2) = 0;
        }
    });
    variant("doubled_contact", [](Problem& p) {  // rows 0-2 again in block 1's first rows: W singular
      const int r = p.blocks[1].row;
      for (int k = 0; k < 3; ++k) p.W.row(r + k) = p.W.row(k);
      for (int k = 0; k < 3; ++k) p.W.col(r + k) = p.W.col(k);
      p.b.segment<3>(r) = p.b.head<3>();
    });
    variant("nsgs", [](Problem& p) { p.options.method = SolverMethod::NSGS; });
    variant("newton", [](Problem& p) { p.options.method = SolverMethod::Newton; });
    variant("proximal", [](Problem& p) { p.options.method = SolverMethod::ProximalNewton; });
    variant("30_iterations", [](Problem& p) { p.options.max_iterations = 30; });
    variant("frictionless", [&](Problem& p) {  // the normal rows, one frictionless block each
      const int n = nb;
      p.W.resize(n, n);
      p.b.resize(n);
      p.P_start.resize(n);
      p.blocks.clear();
      for (int i = 0; i < n; ++i) {
        const int ri = f.blocks[i].row;
        for (int j = 0; j < n; ++j) p.W(i, j) = f.W(ri, f.blocks[j].row);
        p.b(i) = f.b(ri);
        p.P_start(i) = f.P_start(ri);
        p.blocks.push_back({BlockKind::Frictionless, i, 1, 0});
      }
    });
  }
  return out;
}

}  // namespace

TEST(SolverReuse, AnswersAsAFreshSolverWhateverItSolvedBefore) {
  const std::vector<Problem> all = problems();
  ASSERT_GT(all.size(), 60u);
  std::vector<Answer> fresh;
  for (const Problem& p : all) {
    FrictionContactSolver solver;
    fresh.push_back(solveWith(solver, p));
    EXPECT_NE(fresh.back().report.stage, SolverStage::Failed) << p.name;  // each a valid problem
  }
  // Orders: smallest first, largest first, and shuffles.
  std::vector<std::vector<size_t>> orders;
  std::vector<size_t> order(all.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  // std::sort with the index as tie-break: stable_sort's order. (GCC 12's stable_sort frees
  // its buffer in a way AddressSanitizer reports as an alloc-dealloc mismatch.)
  std::sort(order.begin(), order.end(), [&](size_t i, size_t j) {
    return all[i].b.size() != all[j].b.size() ? all[i].b.size() < all[j].b.size() : i < j;
  });
  orders.push_back(order);
  orders.emplace_back(order.rbegin(), order.rend());
  for (unsigned seed = 1; seed <= 6; ++seed) {
    std::mt19937 rng(seed);
    std::shuffle(order.begin(), order.end(), rng);
    orders.push_back(order);
  }
  int differ = 0;
  for (size_t o = 0; o < orders.size(); ++o) {
    FrictionContactSolver solver;
    for (size_t i : orders[o]) {
      const Answer a = solveWith(solver, all[i]);
      if (identical(a, fresh[i])) continue;
      ++differ;
      ADD_FAILURE() << "order " << o << ": " << all[i].name << " differs from a fresh solver's answer (stage "
                    << solverStageName(a.report.stage) << " / " << solverStageName(fresh[i].report.stage)
                    << ", iterations " << a.report.iteration_sum << " / " << fresh[i].report.iteration_sum << ")";
      if (differ > 20) return;
    }
  }
}

// Blocks that do not cover the rows once each (rows in no block, rows in two) are
// no problem of the contact law: Failed, P untouched. The Newton's Jacobian and
// the interior point's directions were written block by block, so such rows kept
// what an earlier solve had left: the answer depended on the solver's history.
TEST(SolverReuse, BlocksThatDoNotCoverTheRowsOnceEachFail) {
  const ProblemFile f = readProblemFile(nscd_test::sourceDir() + "/test/problems/c60_handle_dt1e-5_step638.txt");
  const Problem full = firstBlocks(f, "c60", int(f.blocks.size()));
  Problem overlap = full, gap = full, twice = full;
  overlap.blocks[1].row = overlap.blocks[0].row;  // rows of block 0 twice, block 1's in none
  gap.blocks.erase(gap.blocks.begin() + 1);        // block 1's rows in none
  twice.blocks.push_back(twice.blocks.back());     // the last block twice
  Problem other = firstBlocks(f, "c60:first", 4);  // something else solved before
  for (const Problem* p : {&overlap, &gap, &twice}) {
    FrictionContactSolver fresh_solver, used;
    const Answer fresh = solveWith(fresh_solver, *p);
    solveWith(used, full);
    solveWith(used, other);
    const Answer after = solveWith(used, *p);
    EXPECT_EQ(fresh.report.stage, SolverStage::Failed) << solverStageName(fresh.report.stage);
    EXPECT_FALSE(fresh.report.converged);
    EXPECT_EQ(std::memcmp(fresh.P.data(), p->P_start.data(), sizeof(double) * p->P_start.size()), 0);
    EXPECT_TRUE(identical(after, fresh)) << "stage " << solverStageName(after.report.stage) << " / "
                                         << solverStageName(fresh.report.stage) << ", iterations "
                                         << after.report.iteration_sum << " / " << fresh.report.iteration_sum;
  }
  // The same blocks in another order cover the rows once each: solved.
  Problem shuffled = full;
  std::mt19937 rng(3);
  std::shuffle(shuffled.blocks.begin(), shuffled.blocks.end(), rng);
  FrictionContactSolver solver;
  const Answer a = solveWith(solver, shuffled);
  EXPECT_NE(a.report.stage, SolverStage::Failed);
}
