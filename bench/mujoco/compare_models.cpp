// The scene table of the MuJoCo comparison and the comparison of end states.
#include "compare_models.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nscd_mujoco {

const std::vector<SceneSpec>& scenes() {
  static const std::vector<SceneSpec> table = {
      {SceneId::Pendulum, "pendulum", "urdf/pendulum.urdf", "bench/mujoco/pendulum.xml", {"bob"}},
      {SceneId::DoublePendulum, "double_pendulum", "test/scenes/double_pendulum.urdf",
       "bench/mujoco/double_pendulum.xml", {"upper", "lower"}},
      {SceneId::Fourbar, "fourbar", "urdf/fourbar.urdf", "bench/mujoco/fourbar.xml", {"crank", "coupler", "rocker"}},
      {SceneId::Ball, "ball", "urdf/ball.urdf", "bench/mujoco/ball.xml", {"ball"}},
  };
  return table;
}

const SceneSpec& scene(SceneId id) {
  for (const SceneSpec& s : scenes())
    if (s.id == id) return s;
  throw std::invalid_argument("unknown scene id");
}

const SceneSpec& sceneNamed(const std::string& name) {
  for (const SceneSpec& s : scenes())
    if (name == s.name) return s;
  throw std::invalid_argument("unknown scene '" + name + "' (pendulum, double_pendulum, fourbar, ball)");
}

Errors compareEnd(const EndState& run, const EndState& reference) {
  Errors e;
  if (run.pitch.size() != reference.pitch.size() || run.com.size() != reference.com.size()) return {NAN, NAN};
  constexpr double kTwoPi = 6.283185307179586;
  for (size_t i = 0; i < run.pitch.size(); ++i) {
    const double d = run.pitch[i] - reference.pitch[i];
    e.angle = std::max(e.angle, std::abs(d - kTwoPi * std::round(d / kTwoPi)));
  }
  for (size_t i = 0; i < run.com.size(); ++i) {
    double s = 0;
    for (int k = 0; k < 3; ++k) s += (run.com[i][k] - reference.com[i][k]) * (run.com[i][k] - reference.com[i][k]);
    e.position = std::max(e.position, std::sqrt(s));
  }
  return e;
}

const char* methodName(Method m) {
  switch (m) {
    case Method::NscdFixed: return "nscd_fixed";
    case Method::NscdAdaptive: return "nscd_adaptive";
    case Method::MujocoEuler: return "mujoco_euler";
    case Method::MujocoRk4: return "mujoco_rk4";
  }
  return "?";
}

bool isMujoco(Method m) { return m == Method::MujocoEuler || m == Method::MujocoRk4; }

}  // namespace nscd_mujoco
