// The fuzz targets' shared helpers (fuzz_support.hpp).
#include "fuzz_support.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "csv_writer.hpp"
#include "run_summary.hpp"
#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/key_figures.hpp"
#include "nscd_sim/simulator.hpp"

namespace nscd_fuzz {

std::string repoFile(const std::string& relative_path) {
  const std::string path = std::string(NSCD_SOURCE_DIR) + "/" + relative_path;
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("cannot read " + path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string scratchFile(const uint8_t* data, size_t size, const std::string& suffix) {
  const char* dir = std::getenv("TMPDIR");
  const std::string path = std::string(dir && *dir ? dir : "/tmp") + "/nscd_fuzz_" +
                           std::to_string(getpid()) + suffix;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f || (size > 0 && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0)
    fail("cannot write the scratch file " + path);
  return path;
}

void fail(const std::string& what) {
  std::fprintf(stderr, "nscd fuzz oracle: %s\n", what.c_str());
  std::abort();
}

void expectOneLine(const std::string& message, const std::string& prefix) {
  if (message.empty()) fail("empty error message");
  if (message.find('\n') != std::string::npos)
    fail("error message of more than one line: [" + message + "]");
  if (message.compare(0, prefix.size(), prefix) != 0)
    fail("error message does not start with '" + prefix + "': [" + message + "]");
}

bool readProblemInput(const uint8_t* data, size_t size, nscd::ProblemFile& p) {
  const std::string path = scratchFile(data, size, ".txt");
  try {
    p = nscd::readProblemFile(path);
  } catch (const std::runtime_error& e) {
    expectOneLine(e.what(), path);
    return false;
  }
  const Eigen::Index m = p.b.size();
  if (p.W.rows() != m || p.W.cols() != m || p.P_start.size() != m || p.P.size() != m)
    fail("a problem read with inconsistent sizes");
  for (const nscd::ProblemBlock& bl : p.blocks)
    if (bl.row < 0 || bl.size < 1 || bl.row + bl.size > m) fail("a block outside the rows was read");
  return true;
}

std::vector<std::string> lines(const uint8_t* data, size_t size) {
  std::vector<std::string> out;
  std::string cur;
  for (size_t i = 0; i < size; ++i) {
    if (data[i] == '\n') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += static_cast<char>(data[i]);
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

constexpr int kFuzzIterations = 1000;
constexpr int kFuzzHalvings = 4;

bool boundedBudget(const nscd::Settings& s) {
  return s.max_iterations <= kFuzzIterations && s.projection_max_iterations <= kFuzzIterations &&
         s.max_step_halvings <= kFuzzHalvings;
}

void boundBudget(nscd::Settings& s) {
  s.max_iterations = std::min(s.max_iterations, kFuzzIterations);
  s.projection_max_iterations = std::min(s.projection_max_iterations, kFuzzIterations);
  s.max_step_halvings = std::min(s.max_step_halvings, kFuzzHalvings);
}

namespace {

bool finite(double x) { return std::isfinite(x); }

}  // namespace

void checkStepOutputs(const nscd::Simulator& sim, int k, std::vector<double>& figures) {
  const nscd::State& s = sim.state();
  const auto where = [&](const std::string& what) {
    return "step " + std::to_string(k) + " reported finite but " + what + " is not finite";
  };
  if (!finite(s.t)) fail(where("t"));
  for (size_t b = 0; b < s.bodies.size(); ++b) {
    const nscd::BodyState& bs = s.bodies[b];
    if (!bs.x.allFinite() || !bs.q.coeffs().allFinite() || !bs.v.allFinite() || !bs.w.allFinite())
      fail(where("body " + std::to_string(b) + "'s state"));
  }
  const nscd::EnergyReport e = sim.energy();
  if (!finite(e.total())) fail(where("the energy"));
  const nscd::StepStats& st = sim.stats();
  if (!finite(st.max_penetration)) fail(where("max_penetration"));
  nscd::keyFigureValues(sim, figures);
  const std::vector<std::string> names = nscd::keyFigureNames(sim.model());
  for (size_t i = 0; i < figures.size(); ++i) {
    // A named contact whose shapes have no point to measure (a ring facing away
    // from a face) has the gap +inf: the geometric answer, not an overflow.
    const bool gap = names[i].size() > 4 && names[i].compare(names[i].size() - 4, 4, ".gap") == 0;
    if (!finite(figures[i]) && !(gap && figures[i] == HUGE_VAL)) fail(where("key figure " + names[i]));
  }
  for (const nscd::ContactReport& c : sim.contactPoints())
    if (!c.point.allFinite() || !c.normal.allFinite() || !finite(c.gap) || !finite(c.fn) || !c.ft.allFinite())
      fail(where("a contact report"));
}

void stepAndCheck(nscd::Model model, int steps, const std::vector<SteppingCommand>& commands,
                  const std::vector<std::string>& schedules, const std::vector<int>& resets,
                  bool stop_when_unsolved) {
  std::vector<nscd::BoundSchedule> bound;
  try {
    bound = nscd::bindCommandSchedules(schedules, model);
  } catch (const std::invalid_argument& e) {
    expectOneLine(e.what(), "");
    return;
  }
  std::unique_ptr<nscd::Simulator> sim;
  try {
    sim = std::make_unique<nscd::Simulator>(std::move(model));
  } catch (const std::runtime_error& e) {  // the assembly failed: a refusal
    expectOneLine(e.what(), "");
    return;
  }
  nscd::CsvWriter csv("/dev/null", *sim);
  std::vector<double> figures;
  const double h = sim->model().settings.dt;
  const double energy_initial = sim->energy().total();
  nscd::RunSummary summary;
  for (int k = 1; k <= steps; ++k) {
    for (int r : resets)
      if (r == k) sim->reset();
    for (const SteppingCommand& c : commands)
      if (c.step == k) sim->setCommand(c.actuator, c.value);
    nscd::applySchedules(bound, k * h, *sim);
    const nscd::StepStatus status = sim->step();
    const nscd::StepStats& st = sim->stats();
    summary.steps = k;
    summary.iters_sum += st.iterations;
    summary.residual_max = std::max(summary.residual_max, st.residual);
    if (status == nscd::StepStatus::NonFinite) break;  // reported: the runner stops (status 3)
    checkStepOutputs(*sim, k, figures);
    csv.writeRow(*sim);
    if (stop_when_unsolved && !st.converged) break;
  }
  summary.sim_time = sim->state().t;
  summary.energy_initial = energy_initial;
  summary.energy_final = sim->energy().total();
  const std::string json = nscd::runSummaryJson(summary);
  if (json.find("nan") != std::string::npos || json.find("inf") != std::string::npos)
    fail("the run summary holds a non-finite number: " + json);
}

}  // namespace nscd_fuzz
