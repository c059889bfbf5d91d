// nscd_run's --set KEY=VALUE (set_option.hpp).
#include "set_option.hpp"

namespace nscd_run {

bool parseSetOption(const std::string& text, nscd::SettingOverride& out) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) return false;
  out = {text.substr(0, eq), text.substr(eq + 1), "--set"};
  return true;
}

}  // namespace nscd_run
