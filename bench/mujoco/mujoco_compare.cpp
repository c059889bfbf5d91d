// nscd_mujoco_compare: nscd_sim and MuJoCo side by side, in one process, on a
// pendulum, a double pendulum, a four-bar and a ball (compare_models.hpp). Each run
// goes to t = 1 s and is compared with a converged reference there; the runs of the
// engines are interleaved, one level of their grids at a time, so that the load of a
// shared machine falls on all of them alike.
//   OUT/runs.csv        one row per run: steps, wall and CPU time of the stepping, errors
//   OUT/references.csv  each reference's self-check (its step against twice its step)
// scripts/analysis/mujoco_compare.py turns them into tables.
//
// usage: nscd_mujoco_compare [--out DIR] [--quick] [--scenes a,b] [--min-seconds S] [--adaptive-dt S]
//        nscd_mujoco_compare --order-table [--scenes a,b]   (error at t = 1 s of adaptive steps of a
//          fixed length H with every extrapolation level up to max_order K, for K = 2..6: the order)
//        nscd_mujoco_compare --single SCENE METHOD SETTING --steps N   (one run, for callgrind)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "../../tools/command_line.hpp"
#include "compare_models.hpp"

using namespace nscd_mujoco;

namespace {

struct Grid {
  Method method;
  std::vector<double> settings;
};

std::vector<Grid> grids(bool quick) {
  if (quick)
    return {{Method::MujocoEuler, {1e-3, 1e-4}},
            {Method::MujocoRk4, {1e-2, 1e-3, 1e-4}},
            {Method::NscdFixed, {1e-3, 1e-4}},
            {Method::NscdAdaptive, {1e-4, 1e-6}}};
  return {{Method::MujocoEuler, {1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5}},
          {Method::MujocoRk4, {5e-2, 4e-2, 2.5e-2, 2e-2, 1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5}},
          {Method::NscdFixed, {1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5}},
          {Method::NscdAdaptive, {1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 1e-7, 1e-8}}};
}

Method methodNamed(const std::string& name) {
  for (Method m : {Method::NscdFixed, Method::NscdAdaptive, Method::MujocoEuler, Method::MujocoRk4})
    if (name == methodName(m)) return m;
  std::fprintf(stderr, "unknown method '%s' (nscd_fixed, nscd_adaptive, mujoco_euler, mujoco_rk4)\n", name.c_str());
  std::exit(2);
}

RunResult run(const std::string& src, const SceneSpec& s, Method m, double setting, const RunOptions& o) {
  return isMujoco(m) ? runMujoco(src, s, m, setting, o) : runNscd(src, s, m, setting, o);
}

struct Options {
  std::string out = ".", src = NSCD_SOURCE_DIR, scene_list = "pendulum,double_pendulum,fourbar,ball";
  bool quick = false;
  RunOptions run;
  std::vector<std::string> single;  // --single: scene, method, setting
  bool order_table = false;         // --order-table: the measured order, a markdown table
};

// False after the usage line (an unknown option).
bool parseOptions(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] { return nscd_cli::optionValue(a, argc, argv, i); };
    if (a == "--out") o.out = next();
    else if (a == "--source") o.src = next();
    else if (a == "--scenes") o.scene_list = next();
    else if (a == "--quick") o.quick = true;
    else if (a == "--min-seconds") o.run.min_seconds = std::atof(next().c_str());
    else if (a == "--steps") o.run.fixed_steps = std::atol(next().c_str());
    else if (a == "--adaptive-dt") o.run.adaptive_dt = std::atof(next().c_str());
    else if (a == "--order-table") o.order_table = true;
    else if (a == "--single") {
      o.single = {next(), next(), next()};
    } else {
      std::fprintf(stderr,
                   "usage: %s [--out DIR] [--quick] [--scenes pendulum,double_pendulum,fourbar,ball] "
                   "[--min-seconds S] [--source DIR] [--adaptive-dt S]\n"
                   "       %s --single SCENE METHOD SETTING --steps N\n",
                   argv[0], argv[0]);
      return false;
    }
  }
  return true;
}

// One run, once: what callgrind counts (scripts/mujoco_compare.sh --instructions).
int runSingle(Options o) {
  o.run.max_repetitions = 1;
  const RunResult r = run(o.src, sceneNamed(o.single[0]), methodNamed(o.single[1]), std::atof(o.single[2].c_str()), o.run);
  if (!r.error.empty()) {
    std::fprintf(stderr, "%s\n", r.error.c_str());
    return 1;
  }
  std::printf("%s %s %s steps=%ld wall_s=%.6g\n", o.single[0].c_str(), o.single[1].c_str(), o.single[2].c_str(),
              r.steps, r.wall_s);
  return 0;
}

// Every grid's runs on scene s, one level of the grids at a time, each compared with
// the reference; a row each in runs and on standard output, the reference's self-check in refs.
void runScene(const SceneSpec& s, const std::vector<Grid>& gs, const Options& o, FILE* runs, FILE* refs) {
  const RunOptions& ro = o.run;
  const EndState ref = referenceEnd(s.id, ro.duration);
  const Errors self = referenceSelfCheck(s.id, ro.duration);
  std::fprintf(refs, "%s,%g,%.3g,%.3g\n", s.name, ro.duration, self.angle, self.position);
  size_t levels = 0;
  for (const Grid& g : gs) levels = std::max(levels, g.settings.size());
  for (size_t level = 0; level < levels; ++level)
    for (const Grid& g : gs) {
      if (level >= g.settings.size()) continue;
      const double setting = g.settings[level];
      const RunResult r = run(o.src, s, g.method, setting, ro);
      const Errors e = r.error.empty() ? compareEnd(r.end, ref) : Errors{NAN, NAN};
      std::string err = r.error;
      for (char& c : err)
        if (c == ',' || c == '\n') c = ';';
      std::fprintf(runs, "%s,%s,%g,%ld,%ld,%ld,%d,%.6g,%.6g,%.6g,%.4g,%.4g,%s\n", s.name,
                   methodName(g.method), setting, r.steps, r.rejected, r.unconverged, r.repetitions, r.wall_s,
                   r.cpu_s, r.steps ? 1e6 * r.wall_s / r.steps : 0.0, e.angle, e.position, err.c_str());
      std::fflush(runs);
      std::printf("%-16s %-14s %-8g steps %-7ld wall %9.3f ms  %8.3f us/step  angle err %.3e  pos err %.3e%s%s\n",
                  s.name, methodName(g.method), setting, r.steps, 1e3 * r.wall_s,
                  r.steps ? 1e6 * r.wall_s / r.steps : 0.0, e.angle, e.position, err.empty() ? "" : "  ERROR: ",
                  err.c_str());
      std::fflush(stdout);
    }
}

// The order each max_order reaches: adaptive steps of a fixed length H (dt = dt_min
// = H, a tolerance no level meets), the angle error at the end against the
// reference, as markdown rows: scene, max_order, then the error (rad) at each H.
int printOrderTable(const std::vector<const SceneSpec*>& chosen, Options o) {
  const std::vector<double> hs = {0.04, 0.02, 0.01, 0.005, 0.0025};
  o.run.max_repetitions = 1;
  std::printf("| scene | max_order |");
  for (double H : hs) std::printf(" H %g |", H);
  std::printf("\n|---|---|");
  for (size_t i = 0; i < hs.size(); ++i) std::printf("---|");
  std::printf("\n");
  for (const SceneSpec* s : chosen) {
    const EndState ref = referenceEnd(s->id, o.run.duration);
    for (int K = 2; K <= 6; ++K) {
      o.run.fixed_order = K;
      std::printf("| %s | %d |", s->name, K);
      for (double H : hs) {
        const RunResult r = runNscd(o.src, *s, Method::NscdAdaptive, H, o.run);
        if (r.error.empty()) std::printf(" %.3g |", compareEnd(r.end, ref).angle);
        else std::printf(" %s |", r.error.c_str());
      }
      std::printf("\n");
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parseOptions(argc, argv, o)) return 2;
  try {
    if (!o.single.empty()) return runSingle(o);
    std::vector<const SceneSpec*> chosen;
    for (const std::string& name : nscd_cli::splitCommas(o.scene_list)) chosen.push_back(&sceneNamed(name));
    if (o.order_table) return printOrderTable(chosen, o);
    FILE* runs = std::fopen((o.out + "/runs.csv").c_str(), "w");
    FILE* refs = std::fopen((o.out + "/references.csv").c_str(), "w");
    if (!runs || !refs) {
      std::fprintf(stderr, "cannot write into %s\n", o.out.c_str());
      return 1;
    }
    std::fprintf(runs, "scene,method,setting,steps,rejected,unconverged,repetitions,wall_s,cpu_s,us_per_step,"
                       "err_angle,err_pos,error\n");
    std::fprintf(refs, "scene,t,self_check_angle,self_check_pos\n");
    const std::vector<Grid> gs = grids(o.quick);
    for (const SceneSpec* s : chosen) runScene(*s, gs, o, runs, refs);
    std::fclose(runs);
    std::fclose(refs);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nscd_mujoco_compare: %s\n", e.what());
    return 2;
  }
  return 0;
}
