// nscd_run's --set KEY=VALUE, split into a settings override (the value is checked
// when the scene applies it: nscd::applySetting).
#pragma once

#include <string>

#include "nscd_sim/scene_loader.hpp"

namespace nscd_run {

// "key=value" -> {key, value, "--set"} (split at the first '='); false when the
// text has no '=' or nothing before it.
bool parseSetOption(const std::string& text, nscd::SettingOverride& out);

}  // namespace nscd_run
