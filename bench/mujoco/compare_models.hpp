// The MuJoCo comparison: four mechanisms built in both engines with the same masses,
// inertias and lengths (urdf/ and test/scenes/ for nscd_sim, bench/mujoco/*.xml for
// MuJoCo), one run of each engine, and a converged reference of each scene that
// depends on neither engine (reference_models.cpp).
#pragma once

#include <array>
#include <string>
#include <vector>

namespace nscd_mujoco {

enum class SceneId { Pendulum, DoublePendulum, Fourbar, Ball };

// A scene: its files (relative to the source tree) and the links compared, the
// same bodies in the same order in both engines. Every tracked link turns about y
// only (the pendulums, the four-bar) or not at all (the ball).
struct SceneSpec {
  SceneId id;
  const char* name;
  const char* urdf;
  const char* mjcf;
  std::vector<std::string> links;
};

const std::vector<SceneSpec>& scenes();
const SceneSpec& scene(SceneId id);
// The scene named `name`; throws std::invalid_argument if there is none.
const SceneSpec& sceneNamed(const std::string& name);

// What is compared at the end of a run: per tracked link, its rotation about y
// (rad, the link frame's pitch) and its centre of mass (world, m).
struct EndState {
  std::vector<double> pitch;
  std::vector<std::array<double, 3>> com;
};

// The errors of a run's end state against the reference's: the largest angle
// difference over the links (wrapped to (-pi, pi]) and the largest distance
// between centres of mass.
struct Errors {
  double angle = 0, position = 0;
};
Errors compareEnd(const EndState& run, const EndState& reference);

// nscd_sim with fixed steps (setting: dt), nscd_sim with adaptive steps (setting:
// rtol = atol; dt the largest step), MuJoCo's semi-implicit Euler and its RK4
// (setting: the time step).
enum class Method { NscdFixed, NscdAdaptive, MujocoEuler, MujocoRk4 };
const char* methodName(Method m);
bool isMujoco(Method m);

struct RunResult {
  long steps = 0;
  long rejected = 0;         // adaptive steps taken again with a shorter h
  long unconverged = 0;      // nscd steps whose solver did not converge
  double wall_s = 0;         // the stepping loop only, the fastest repetition
  double cpu_s = 0;          // CPU time of the thread over the same loop, the fastest
  int repetitions = 0;
  EndState end;
  std::string error;  // non-empty if the run failed
};

struct RunOptions {
  double duration = 1.0;
  double adaptive_dt = 1e-2;   // the largest adaptive step
  double min_seconds = 0.2;    // repeat a run until this much stepping is timed
  int max_repetitions = 20;
  long fixed_steps = 0;        // > 0: this many fixed steps instead of the duration (callgrind)
  // > 0: nscd_adaptive runs take steps of the fixed length `setting` with every level
  // of the extrapolation up to max_order = fixed_order (dt_min = dt, a tolerance no
  // step meets: each step kept at the floor): the order table (--order-table).
  int fixed_order = 0;
};

// source_dir: the source tree holding urdf/, test/scenes/ and bench/mujoco/.
RunResult runNscd(const std::string& source_dir, const SceneSpec& s, Method m, double setting,
                  const RunOptions& o);
RunResult runMujoco(const std::string& source_dir, const SceneSpec& s, Method m, double setting,
                    const RunOptions& o);
// The MuJoCo model's energy at its start (kinetic + gravity relative to the world
// origin, J), to check its masses, inertias and lengths against the scene's.
double mujocoStartEnergy(const std::string& source_dir, const SceneSpec& s);

// The converged answer at time t (reference_models.cpp), and the largest change of
// its end state between its step and twice that step (angle rad, position m): the
// reference's own error bound.
EndState referenceEnd(SceneId id, double t);
Errors referenceSelfCheck(SceneId id, double t);

// The four-bar's start, as every engine must have it: crank at 90 deg, the bars at
// rest but the crank turning at 5 rad/s about +y, made consistent with the loop by
// the velocity projection in the mass metric (what nscd_sim's assembly does). Joint
// rates of the open chain crank -> coupler -> rocker about +y, rad/s.
std::array<double, 3> fourbarStartJointRates();

}  // namespace nscd_mujoco
