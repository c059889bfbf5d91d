// SceneError keeps its message on one line (scene_loader.hpp).
#include <cstdio>

#include "nscd_sim/scene_loader.hpp"

namespace nscd {
namespace {

// Control characters of the quoted input as C escapes: a line break in an
// attribute or a YAML key must not split the one line a refusal is.
std::string oneLine(const std::string& what) {
  std::string out;
  out.reserve(what.size());
  for (const char c : what) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (u < 0x20 && c != '\t') {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", u);
      out += hex;
    } else if (u == 0x7f) out += "\\x7f";
    else out += c;
  }
  return out;
}

}  // namespace

SceneError::SceneError(const std::string& what) : std::runtime_error(oneLine(what)) {}

}  // namespace nscd
