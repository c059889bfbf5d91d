// The comparison scenes in MuJoCo (its C API, bench/mujoco/*.xml): the time step and
// the integrator set on the compiled model, the start state set in mjData, mj_step
// round(duration / dt) times.
#include <mujoco/mujoco.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "compare_models.hpp"

namespace nscd_mujoco {
namespace {

constexpr double kPi = 3.14159265358979323846;

double threadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

// The scene's start, as the URDF has it (the four-bar's rates: fourbarStartJointRates).
void setStart(SceneId id, const mjModel* m, mjData* d) {
  mj_resetData(m, d);
  switch (id) {
    case SceneId::Pendulum:
      d->qpos[0] = kPi / 6;
      break;
    case SceneId::DoublePendulum:
      d->qpos[0] = -kPi / 2;
      d->qpos[1] = 0;
      break;
    case SceneId::Fourbar: {
      const std::array<double, 3> w = fourbarStartJointRates();
      for (int i = 0; i < 3; ++i) d->qvel[i] = w[i];
      break;
    }
    case SceneId::Ball:
      break;  // qpos0: the body's place in the file
  }
}

std::unique_ptr<mjModel, ModelDeleter> load(const std::string& source_dir, const SceneSpec& s) {
  char error[1000] = "";
  std::unique_ptr<mjModel, ModelDeleter> m(mj_loadXML((source_dir + "/" + s.mjcf).c_str(), nullptr, error, sizeof error));
  if (!m) throw std::runtime_error(std::string(s.mjcf) + ": " + error);
  return m;
}

}  // namespace

double mujocoStartEnergy(const std::string& source_dir, const SceneSpec& s) {
  std::unique_ptr<mjModel, ModelDeleter> m = load(source_dir, s);
  m->opt.enableflags |= mjENBL_ENERGY;
  std::unique_ptr<mjData, DataDeleter> d(mj_makeData(m.get()));
  setStart(s.id, m.get(), d.get());
  mj_forward(m.get(), d.get());
  mj_energyPos(m.get(), d.get());
  mj_energyVel(m.get(), d.get());
  return d->energy[0] + d->energy[1];
}

RunResult runMujoco(const std::string& source_dir, const SceneSpec& s, Method method, double dt,
                    const RunOptions& o) {
  RunResult res;
  try {
    if (!isMujoco(method)) throw std::invalid_argument("runMujoco: not a MuJoCo method");
    std::unique_ptr<mjModel, ModelDeleter> m = load(source_dir, s);
    m->opt.timestep = dt;
    m->opt.integrator = method == Method::MujocoRk4 ? mjINT_RK4 : mjINT_EULER;
    // The loop's connect equality as stiff as MuJoCo allows: time constant 2 dt (the
    // floor MuJoCo clamps it to), critically damped; solimp 0.9999 from the file.
    for (int e = 0; e < m->neq; ++e) {
      m->eq_solref[mjNREF * e] = 2 * dt;
      m->eq_solref[mjNREF * e + 1] = 1;
    }
    std::unique_ptr<mjData, DataDeleter> d(mj_makeData(m.get()));
    std::vector<int> bodies;
    for (const std::string& name : s.links) {
      const int b = mj_name2id(m.get(), mjOBJ_BODY, name.c_str());
      if (b < 0) throw std::runtime_error(std::string(s.mjcf) + ": no body '" + name + "'");
      bodies.push_back(b);
    }
    const long n = o.fixed_steps > 0 ? o.fixed_steps : std::lround(o.duration / dt);
    double total = 0;
    for (int rep = 0; rep < o.max_repetitions && (rep == 0 || (total < o.min_seconds && o.fixed_steps == 0));
         ++rep) {
      setStart(s.id, m.get(), d.get());
      const double cpu0 = threadCpuSeconds();
      const auto t0 = std::chrono::steady_clock::now();
      for (long k = 0; k < n; ++k) mj_step(m.get(), d.get());
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double cpu = threadCpuSeconds() - cpu0;
      total += wall;
      res.wall_s = rep == 0 ? wall : std::min(res.wall_s, wall);
      res.cpu_s = rep == 0 ? cpu : std::min(res.cpu_s, cpu);
      res.repetitions = rep + 1;
    }
    res.steps = n;
    for (int i = 0; i < m->nq; ++i)
      if (!std::isfinite(d->qpos[i])) throw std::runtime_error("non-finite state");
    mj_kinematics(m.get(), d.get());  // the poses of the final qpos (mj_step leaves those of the last step's start)
    for (int b : bodies) {
      const mjtNum* q = d->xquat + 4 * b;  // w, x, y, z
      const mjtNum* c = d->xipos + 3 * b;
      res.end.pitch.push_back(2 * std::atan2(q[2], q[0]));
      res.end.com.push_back({c[0], c[1], c[2]});
    }
  } catch (const std::exception& e) {
    res.error = e.what();
  }
  return res;
}

}  // namespace nscd_mujoco
