// Fuzz target: a YAML settings file (nscd_run --config: nscd::readSettingsYaml),
// applied to the clearance pendulum. A bad file is refused with one line naming
// it; a scene that loads (with budgets small enough, fuzz_support.hpp) is stepped
// 20 times.
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "nscd_sim/scene_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string scene = nscd_fuzz::repoFile("urdf/clearance_pendulum.urdf");
  const std::string path = nscd_fuzz::scratchFile(data, size, ".yaml");
  std::vector<nscd::SettingOverride> overrides;
  try {
    overrides = nscd::readSettingsYaml(path);
  } catch (const nscd::SceneError& e) {
    nscd_fuzz::expectOneLine(e.what(), path);
    return 0;
  }
  nscd::Model model;
  try {
    model = nscd::loadSceneFromString(scene, "pendulum.urdf", overrides);
  } catch (const nscd::SceneError& e) {
    nscd_fuzz::fail(std::string("settings readSettingsYaml accepted were refused: ") + e.what());
  }
  if (nscd_fuzz::boundedBudget(model.settings)) nscd_fuzz::stepAndCheck(std::move(model), 20);
  return 0;
}
