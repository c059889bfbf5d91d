// Fuzz target: nscd_run --set KEY=VALUE (src/nscd_run/set_option.cpp, then
// nscd::applySetting as the scene loader applies overrides). Each input line is
// one --set; they override the clearance pendulum's settings. A bad one is refused
// with one line; a scene that loads (with budgets small enough, fuzz_support.hpp)
// is stepped 20 times.
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "set_option.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string scene = nscd_fuzz::repoFile("urdf/clearance_pendulum.urdf");
  std::vector<nscd::SettingOverride> overrides;
  for (const std::string& line : nscd_fuzz::lines(data, size)) {
    nscd::SettingOverride o;
    if (!nscd_run::parseSetOption(line, o)) continue;  // nscd_run: "--set X: expected key=value"
    if (o.key.empty() || o.key.find('=') != std::string::npos || o.origin != "--set")
      nscd_fuzz::fail("parseSetOption split '" + line + "' wrongly");
    overrides.push_back(o);
  }
  nscd::Model model;
  try {
    model = nscd::loadSceneFromString(scene, "pendulum.urdf", overrides);
  } catch (const nscd::SceneError& e) {
    const std::string m = e.what();
    nscd_fuzz::expectOneLine(m, m.rfind("--set", 0) == 0 ? "--set: " : "pendulum.urdf");
    return 0;
  }
  if (nscd_fuzz::boundedBudget(model.settings)) nscd_fuzz::stepAndCheck(std::move(model), 20);
  return 0;
}
