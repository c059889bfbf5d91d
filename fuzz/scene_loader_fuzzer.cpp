// Fuzz target: the scene loader from memory (URDF + <nscd>, as the node's
// robot_description). A bad scene must be refused with one line naming the scene;
// a scene that loads is assembled and stepped 3 times (fuzz_support.hpp's checks)
// with its budgets bounded (boundBudget), and not after a step left unsolved: a
// C-60 bench with a link's inertial origin moved 701 m took 25 s for its first
// step in Release with its own 2000 iterations and 8 halvings, 11 s for three
// bounded ones (4 min under the fuzz build), 0.8 s for the first bounded one.
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "nscd_sim/scene_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  nscd::Model model;
  try {
    model = nscd::loadSceneFromString(text, "fuzz.urdf");
  } catch (const nscd::SceneError& e) {
    nscd_fuzz::expectOneLine(e.what(), "fuzz.urdf");
    return 0;
  }
  nscd_fuzz::boundBudget(model.settings);
  nscd_fuzz::stepAndCheck(std::move(model), 3, {}, {}, {}, /*stop_when_unsolved=*/true);
  return 0;
}
