// Problem dumps (Simulator::setProblemObserver, problem files, nscd_run
// --dump-problems): a dumped problem reads back bit for bit, and solving it again
// from its warm start gives the run's answer exactly, so a dump is a faithful
// copy of what the step solved.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <typeinfo>
#include <vector>

#include <gtest/gtest.h>

#include "nscd_sim/problem_file.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "test_support.hpp"

using namespace nscd;

TEST(ProblemFile, ReadsBackBitForBitAndResolvesToTheRunsAnswer) {
  Simulator sim(loadScene(nscd_test::scenePath("urdf/clearance_pendulum.urdf")));
  const std::string path = nscd_test::writeTemp("", ".txt");
  int seen = 0;
  sim.setProblemObserver([&](const ProblemView& v) {
    if (++seen != 40) return;  // a problem from the middle of the swing
    writeProblemFile(path, v);
  });
  for (int k = 0; k < 2000 && seen < 40; ++k) ASSERT_NE(sim.step(), StepStatus::NonFinite);
  ASSERT_GE(seen, 40);
  const ProblemFile p = readProblemFile(path);
  ASSERT_GT(p.b.size(), 0);
  // Bit for bit: writing what was read gives the same text.
  const std::string again = nscd_test::writeTemp("", ".txt");
  SolverReport rep;
  rep.residual = p.residual;
  rep.converged = p.converged;
  rep.iteration_sum = p.iterations;
  writeProblemFile(again, ProblemView{p.t, p.round, p.W, p.b, p.blocks, p.P_start, p.P, rep});
  std::FILE* a = std::fopen(path.c_str(), "r");
  std::FILE* b = std::fopen(again.c_str(), "r");
  ASSERT_TRUE(a && b);
  int ca = 0, cb = 0;
  long n = 0;
  do {
    ca = std::fgetc(a);
    cb = std::fgetc(b);
    ++n;
  } while (ca == cb && ca != EOF);
  std::fclose(a);
  std::fclose(b);
  EXPECT_EQ(ca, cb) << "files differ at byte " << n;
  // The same solver from the same warm start: the run's answer.
  FrictionContactSolver solver;
  SolverOptions o;
  o.tolerance = sim.model().settings.tolerance;
  o.max_iterations = sim.model().settings.max_iterations;
  Eigen::VectorXd P = p.P_start;
  const SolverReport r = solver.solve(p.W, p.b, p.blocks, o, P);
  EXPECT_EQ(r.converged, p.converged);
  EXPECT_EQ(r.iteration_sum, p.iterations);
  EXPECT_EQ((P - p.P).cwiseAbs().maxCoeff(), 0.0);
  std::remove(path.c_str());
  std::remove(again.c_str());
}

TEST(ProblemFile, NotAProblemFileIsRefusedWithItsName) {
  const std::string path = nscd_test::writeTemp("nscd-friction-contact-problem 1\nt 0 round 0 rows 3\n", ".txt");
  try {
    readProblemFile(path);
    FAIL() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

namespace {

// A one-contact problem file whose header says `rows` and whose block line is `block`.
std::string oneContactFile(const std::string& rows, const std::string& block) {
  return "nscd-friction-contact-problem 1\nt 0 round 0 rows " + rows + " blocks 1\n"
         "residual 0 converged 0 iterations 0\n" + block + "\n"
         "W 2 0 0\nW 0 2 0\nW 0 0 2\nb -1 0 0\nP_start 0 0 0\nP 0.5 0 0\n";
}

// readProblemFile(path) refuses with one std::runtime_error naming the file; anything
// else (accepted, another exception) is a failure.
void expectRefusedWithItsName(const std::string& path, const std::string& what) {
  try {
    readProblemFile(path);
    ADD_FAILURE() << what << ": accepted";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(path + ": not a problem file: ", 0), 0u) << what << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << what << ": " << message;
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": not a refusal but " << typeid(e).name() << ": " << e.what();
  }
}

}  // namespace

// The problem_file fuzz target's finding: a rows count the file does not hold was
// allocated before any row was read. 2147483647 rows asked Eigen for 2^62 entries,
// whose std::bad_alloc (not a refusal) ended the fuzz target and would have ended
// nscd_solve_problems with "std::bad_alloc" alone; a million rows asked for 8 TB.
TEST(ProblemFile, RowsCountBeyondWhatTheFileHoldsIsRefusedWithItsName) {
  for (const char* rows : {"2147483647", "1518500250", "1000000", "20000", "4"}) {
    const std::string path = nscd_test::writeTemp(oneContactFile(rows, "block F 0 3 0.5"), ".txt");
    expectRefusedWithItsName(path, std::string("rows ") + rows);
    std::remove(path.c_str());
  }
}

// A block's row + size was summed in int: a row near INT_MAX overflowed (undefined;
// it wrapped negative, and the block past the rows was read as if inside them).
TEST(ProblemFile, BlockPastTheRowsIsRefusedWhateverItsRow) {
  for (const char* block : {"block F 2147483647 3 0.5", "block F 2147483646 3 0.5", "block F 1 2147483647 0.5",
                            "block F 1 3 0.5", "block F -1 3 0.5", "block F 0 0 0.5"}) {
    const std::string path = nscd_test::writeTemp(oneContactFile("3", block), ".txt");
    expectRefusedWithItsName(path, block);
    std::remove(path.c_str());
  }
  // The same file with its block inside the rows reads.
  const std::string path = nscd_test::writeTemp(oneContactFile("3", "block F 0 3 0.5"), ".txt");
  const ProblemFile p = readProblemFile(path);
  EXPECT_EQ(p.W, 2 * Eigen::Matrix3d::Identity());
  EXPECT_EQ(p.b, Eigen::Vector3d(-1, 0, 0));
  EXPECT_EQ(p.P, Eigen::Vector3d(0.5, 0, 0));
  ASSERT_EQ(p.blocks.size(), 1u);
  EXPECT_EQ(p.blocks[0].row, 0);
  EXPECT_EQ(p.blocks[0].size, 3);
  std::remove(path.c_str());
}

TEST(ProblemFile, NscdRunDumpsAndRefusesBadDumpOptions) {
  char dir[] = "/tmp/nscd_dumpXXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string scene = nscd_test::scenePath("urdf/clearance_pendulum.urdf");
  const nscd_test::RunResult ok =
      nscd_test::runNscd(scene + " --duration 0.01 --dump-problems " + dir + " --dump-when 10");
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(ok.err.find("problems written to"), std::string::npos) << ok.err;
  const nscd_test::RunResult when = nscd_test::runNscd(scene + " --dump-problems " + dir + " --dump-when often");
  EXPECT_EQ(when.status, 2);
  EXPECT_NE(when.err.find("--dump-when"), std::string::npos) << when.err;
  const nscd_test::RunResult where = nscd_test::runNscd(scene + " --dump-problems /nonexistent/dir");
  EXPECT_EQ(where.status, 2);
  EXPECT_NE(where.err.find("not a writable folder"), std::string::npos) << where.err;
  std::system((std::string("rm -rf ") + dir).c_str());
}

namespace {

// The count of stage `name` in the "solver_stages" object of an nscd_run summary (-1: absent).
long stageCount(const std::string& json, const std::string& name) {
  const size_t block = json.find("\"solver_stages\":{");
  if (block == std::string::npos) return -1;
  const size_t at = json.find("\"" + name + "\":", block);
  if (at == std::string::npos || at > json.find('}', block)) return -1;
  return std::stol(json.substr(at + name.size() + 3));
}

long filesIn(const std::string& dir) {
  long n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) n += entry.is_regular_file();
  return n;
}

}  // namespace

// nscd_run's summary counts every solve under the stage that finished it: with
// --dump-when all it writes as many problems as the counts add up to, with
// --dump-when stage=NAME as many as that stage finished.
TEST(ProblemFile, SummaryCountsEverySolveByItsStage) {
  const std::string scene = nscd_test::scenePath("urdf/clearance_pendulum.urdf");
  char all[] = "/tmp/nscd_dumpXXXXXX", one[] = "/tmp/nscd_dumpXXXXXX";
  ASSERT_NE(mkdtemp(all), nullptr);
  ASSERT_NE(mkdtemp(one), nullptr);
  const nscd_test::RunResult r =
      nscd_test::runNscd(scene + " --duration 0.05 --dump-problems " + all + " --dump-when all");
  ASSERT_EQ(r.status, 0) << r.err;
  long total = 0, most = 0;
  std::string busiest;
  for (int s = 0; s < kSolverStageCount; ++s) {
    const std::string name = solverStageName(static_cast<SolverStage>(s));
    const long n = stageCount(r.out, name);
    ASSERT_GE(n, 0) << name << " missing in " << r.out;
    total += n;
    if (n > most) most = n, busiest = name;
  }
  EXPECT_GT(total, 0);
  EXPECT_EQ(filesIn(all), total);
  EXPECT_NE(r.out.find("\"rescues\":{\"cold_retry\":"), std::string::npos) << r.out;
  const nscd_test::RunResult s =
      nscd_test::runNscd(scene + " --duration 0.05 --dump-problems " + one + " --dump-when stage=" + busiest);
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_EQ(filesIn(one), most) << busiest;
  const nscd_test::RunResult bad = nscd_test::runNscd(scene + " --dump-problems " + one + " --dump-when stage=nope");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("no solver stage 'nope'"), std::string::npos) << bad.err;
  std::system((std::string("rm -rf ") + all + " " + one).c_str());
}
