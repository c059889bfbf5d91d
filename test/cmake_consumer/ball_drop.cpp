// The installed engine's consumer (test/cmake_consumer/check_install.sh): loads a ball
// dropped from 1 m (urdf/ball.urdf), steps it through its free fall, and checks the
// height against the scheme's own free fall; then through the first bounce. Exit 0 when
// both hold, 1 otherwise, 2 on a bad scene.
#include <cmath>
#include <cstdio>
#include <fstream>

#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: ball_drop SCENE (urdf/ball.urdf)\n");
    return 2;
  }
  nscd::Model model;
  try {
    model = nscd::loadScene(argv[1]);
  } catch (const nscd::SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  const int ball = model.findBody("ball");
  if (ball < 0) {
    std::fprintf(stderr, "%s: no body 'ball'\n", argv[1]);
    return 2;
  }
  const double h = model.settings.dt, theta = model.settings.theta, g = -model.settings.gravity.z();
  nscd::Simulator sim(std::move(model));
  const double z0 = sim.state().bodies[ball].x.z();

  // Free fall until 0.4 s (the ball touches the plane at 0.4515 s): with
  // v_{k+1} = v_k - g h and z_{k+1} = z_k + h (theta v_{k+1} + (1 - theta) v_k),
  // z_k = z0 - g h^2 (k^2 / 2 + (theta - 1/2) k), exact up to rounding.
  const int fall_steps = static_cast<int>(std::lround(0.4 / h));
  for (int k = 0; k < fall_steps; ++k)
    if (sim.step() != nscd::StepStatus::Ok) {
      std::fprintf(stderr, "step %d did not converge\n", k);
      return 1;
    }
  const double k = fall_steps;
  const double z_scheme = z0 - g * h * h * (0.5 * k * k + (theta - 0.5) * k);
  const double z_fall = sim.state().bodies[ball].x.z();
  const bool fall_ok = std::abs(z_fall - z_scheme) < 1e-9;

  // Through the bounce (e = 0.9): at 0.6 s the ball is on its way up, above the plane.
  double z_min = z_fall;
  for (int s = fall_steps; s < static_cast<int>(std::lround(0.6 / h)); ++s) {
    sim.step();
    z_min = std::min(z_min, sim.state().bodies[ball].x.z());
  }
  const double vz = sim.state().bodies[ball].v.z();
  const bool bounce_ok = z_min > 0.05 - 1e-6 && vz > 0;

  std::printf("ball_drop: z(0.4 s) = %.12g m (scheme's free fall %.12g m), lowest centre %.6g m, "
              "vz(0.6 s) = %.6g m/s; nscd_run installed at %s: %s\n",
              z_fall, z_scheme, z_min, vz, NSCD_RUN_EXE,
              std::ifstream(NSCD_RUN_EXE).good() ? "yes" : "no");
  if (!fall_ok) std::fprintf(stderr, "free fall off the scheme's by %.3g m\n", z_fall - z_scheme);
  if (!bounce_ok) std::fprintf(stderr, "no bounce above the plane\n");
  return fall_ok && bounce_ok && std::ifstream(NSCD_RUN_EXE).good() ? 0 : 1;
}
