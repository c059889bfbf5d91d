// Fuzz target: the scene loader from memory (URDF + <nscd>, as the node's
// robot_description). A bad scene must be refused with one line naming the scene;
// a scene that loads is assembled and stepped 3 times (fuzz_support.hpp's checks).
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
  nscd_fuzz::stepAndCheck(std::move(model), 3);
  return 0;
}
