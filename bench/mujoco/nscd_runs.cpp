// The comparison scenes in nscd_sim: the scene files as users run them, with the
// time step or the adaptive tolerances set by overrides, stepped by the front ends'
// loop (scheduled_step.hpp: the last adaptive step ends on the duration).
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "compare_models.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/scheduled_step.hpp"
#include "nscd_sim/simulator.hpp"

namespace nscd_mujoco {
namespace {

double threadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

int findLink(const nscd::Model& m, const std::string& name) {
  for (size_t i = 0; i < m.links.size(); ++i)
    if (m.links[i].name == name) return static_cast<int>(i);
  throw std::runtime_error("no link '" + name + "' in the scene");
}

}  // namespace

RunResult runNscd(const std::string& source_dir, const SceneSpec& s, Method method, double setting,
                  const RunOptions& o) {
  RunResult res;
  try {
    std::vector<nscd::SettingOverride> ov;
    if (method == Method::NscdAdaptive && o.fixed_order > 0) {
      ov = {{"step_control", "adaptive", "mujoco_compare"},
            {"dt", num(setting), "mujoco_compare"},
            {"dt_min", num(setting), "mujoco_compare"},
            {"rtol", "1e-15", "mujoco_compare"},
            {"atol", "1e-15", "mujoco_compare"},
            {"max_order", std::to_string(o.fixed_order), "mujoco_compare"}};
    } else if (method == Method::NscdAdaptive) {
      ov = {{"step_control", "adaptive", "mujoco_compare"},
            {"dt", num(o.adaptive_dt), "mujoco_compare"},
            {"rtol", num(setting), "mujoco_compare"},
            {"atol", num(setting), "mujoco_compare"}};
    } else if (method == Method::NscdFixed) {
      ov = {{"dt", num(setting), "mujoco_compare"}};
    } else {
      throw std::invalid_argument("runNscd: not an nscd method");
    }
    nscd::Simulator sim(nscd::loadScene(source_dir + "/" + s.urdf, ov));
    std::vector<int> links;
    for (const std::string& name : s.links) links.push_back(findLink(sim.model(), name));
    const std::vector<nscd::BoundSchedule> none;
    double total = 0;
    for (int rep = 0; rep < o.max_repetitions && (rep == 0 || (total < o.min_seconds && o.fixed_steps == 0));
         ++rep) {
      sim.reset();
      long k = 0, rejected = 0, unconverged = 0;
      const double cpu0 = threadCpuSeconds();
      const auto t0 = std::chrono::steady_clock::now();
      while (o.fixed_steps > 0 ? k < o.fixed_steps : !nscd::runFinished(sim, k, o.duration)) {
        ++k;
        nscd::prepareScheduledStep(sim, none, k, o.duration);
        const nscd::StepStatus st = sim.step();
        if (st == nscd::StepStatus::NonFinite) throw std::runtime_error("non-finite state");
        unconverged += st == nscd::StepStatus::NotConverged;
        rejected += sim.stats().rejected;
      }
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double cpu = threadCpuSeconds() - cpu0;
      total += wall;
      res.wall_s = rep == 0 ? wall : std::min(res.wall_s, wall);
      res.cpu_s = rep == 0 ? cpu : std::min(res.cpu_s, cpu);
      res.steps = k, res.rejected = rejected, res.unconverged = unconverged;
      res.repetitions = rep + 1;
    }
    for (int l : links) {
      const nscd::Pose p = sim.linkPose(l);
      const nscd::Vec3 c = sim.bodyPose(sim.model().links[l].body).p;
      res.end.pitch.push_back(2 * std::atan2(p.q.y(), p.q.w()));
      res.end.com.push_back({c.x(), c.y(), c.z()});
    }
  } catch (const std::exception& e) {
    res.error = e.what();
  }
  return res;
}

}  // namespace nscd_mujoco
