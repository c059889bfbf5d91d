// nscd_solve_problems: solves friction-contact problem files (nscd_run
// --dump-problems) with FrictionContactSolver and prints, per file, whether it
// converged, the iterations, the residual, the solver stage that gave the answer
// and the time, then how many problems each stage finished; a solver study tool.
//   nscd_solve_problems [--tol 1e-8] [--max-iter 200] [--method auto|nsgs|newton|prox]
//                       [--cold] [--repeat N] [--skip-stage NAME]... FILE...
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "nscd_sim/friction_contact_solver.hpp"
#include "nscd_sim/problem_file.hpp"

int main(int argc, char** argv) {
  CLI::App app{"nscd_solve_problems: solve dumped friction-contact problems"};
  std::vector<std::string> files;
  double tol = 1e-8;
  int max_iter = 200, repeat = 1;
  std::string method = "auto";
  bool cold = false, worst_blocks = false;
  std::string solution_dir;
  std::vector<std::string> skip;
  app.add_option("files", files, "problem files")->required();
  app.add_option("--tol", tol, "tolerance (normalised residual)");
  app.add_option("--max-iter", max_iter, "solver budget");
  app.add_option("--method", method, "auto, nsgs, newton or prox")->check(CLI::IsMember({"auto", "nsgs", "newton", "prox"}));
  app.add_flag("--cold", cold, "start from P = 0 instead of the run's warm start");
  app.add_option("--write-solutions", solution_dir, "write each answer P (one number per line) to DIR/FILE.P");
  app.add_flag("--worst-blocks", worst_blocks, "print the 4 blocks of largest error after each solve");
  app.add_option("--repeat", repeat, "solves per file for the timing (the fastest is shown)");
  app.add_option("--skip-stage", skip, "leave this stage of the solver's schedule out (docs/solver.md; repeatable)");
  CLI11_PARSE(app, argc, argv);

  nscd::SolverOptions opt;
  opt.tolerance = tol;
  opt.max_iterations = max_iter;
  opt.method = method == "nsgs" ? nscd::SolverMethod::NSGS
               : method == "newton" ? nscd::SolverMethod::Newton
               : method == "prox"   ? nscd::SolverMethod::ProximalNewton
                                    : nscd::SolverMethod::Auto;
  for (const std::string& name : skip) {
    int st = 0;
    while (st < nscd::kSolverStageCount && name != nscd::solverStageName(static_cast<nscd::SolverStage>(st))) ++st;
    if (st == nscd::kSolverStageCount) {
      std::fprintf(stderr, "nscd_solve_problems: --skip-stage %s: no such stage (docs/solver.md)\n", name.c_str());
      return 2;
    }
    opt.skip_stages |= 1u << st;
  }
  nscd::FrictionContactSolver solver;
  long finished[nscd::kSolverStageCount] = {};
  int solved = 0;
  long iters = 0;
  double total_us = 0;
  std::printf("%-28s %5s %6s %9s %6s %6s %10s %-16s %10s\n", "file", "rows", "conv", "iters", "sweeps",
              "newton", "residual", "stage", "us");
  for (const std::string& f : files) {
    nscd::ProblemFile p;
    try {
      p = nscd::readProblemFile(f);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return 2;
    }
    nscd::SolverReport rep;
    double best = 1e300;
    for (int k = 0; k < repeat; ++k) {
      Eigen::VectorXd P = cold ? Eigen::VectorXd::Zero(p.b.size()) : p.P_start;
      const auto t0 = std::chrono::steady_clock::now();
      rep = solver.solve(p.W, p.b, p.blocks, opt, P);
      best = std::min(best, std::chrono::duration<double, std::micro>(
                                std::chrono::steady_clock::now() - t0).count());
    }
    const std::string name = f.substr(f.find_last_of('/') + 1);
    std::printf("%-28s %5d %6s %9d %6d %6d %10.3g %-16s %10.1f\n", name.c_str(), int(p.b.size()),
                rep.converged ? "yes" : "NO", rep.iteration_sum, rep.sweeps, rep.newton_iterations,
                rep.residual, nscd::solverStageName(rep.stage), best);
    ++finished[static_cast<int>(rep.stage)];
    if (!solution_dir.empty()) {
      Eigen::VectorXd P = cold ? Eigen::VectorXd::Zero(p.b.size()) : p.P_start;
      solver.solve(p.W, p.b, p.blocks, opt, P);
      const std::string out = solution_dir + "/" + f.substr(f.find_last_of('/') + 1) + ".P";
      if (std::FILE* o = std::fopen(out.c_str(), "w")) {
        for (Eigen::Index i = 0; i < P.size(); ++i) std::fprintf(o, "%.17g\n", P(i));
        std::fclose(o);
      }
    }
    if (worst_blocks) {
      Eigen::VectorXd P = cold ? Eigen::VectorXd::Zero(p.b.size()) : p.P_start;
      solver.solve(p.W, p.b, p.blocks, opt, P);
      std::vector<std::pair<double, int>> errs;
      const Eigen::VectorXd U = p.W * P + p.b;
      for (size_t i = 0; i < p.blocks.size(); ++i) {
        const nscd::ProblemBlock& bl = p.blocks[i];
        double e = 0;
        if (bl.kind == nscd::BlockKind::Frictional)
          e = nscd::localCoulombError(P.segment<3>(bl.row), U.segment<3>(bl.row), bl.mu);
        else if (bl.kind == nscd::BlockKind::Bilateral)
          e = U.segment(bl.row, bl.size).norm();
        else
          e = std::abs(P(bl.row) - std::max(0.0, P(bl.row) - U(bl.row)));
        errs.push_back({e, int(i)});
      }
      std::sort(errs.rbegin(), errs.rend());
      for (size_t k = 0; k < std::min<size_t>(4, errs.size()); ++k) {
        const nscd::ProblemBlock& bl = p.blocks[errs[k].second];
        std::printf("    block %d kind %d rows %d..%d mu %.2g  error %.3g  diag W %.3g  P %.3g %.3g %.3g  U %.3g %.3g %.3g\n",
                    errs[k].second, int(bl.kind), bl.row, bl.row + bl.size - 1, bl.mu, errs[k].first,
                    p.W(bl.row, bl.row), P(bl.row), P(bl.row + 1), P(bl.row + 2), U(bl.row),
                    U(bl.row + 1), U(bl.row + 2));
      }
    }
    solved += rep.converged;
    iters += rep.iteration_sum;
    total_us += best;
  }
  std::printf("stages:");
  for (int st = 0; st < nscd::kSolverStageCount; ++st)
    if (finished[st] > 0) std::printf(" %s %ld", nscd::solverStageName(static_cast<nscd::SolverStage>(st)), finished[st]);
  std::printf("\nsolved %d of %zu, iterations %ld, time %.1f us\n", solved, files.size(), iters, total_us);
  return 0;
}
