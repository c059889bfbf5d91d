// Text helpers shared by the scene loader, the settings and the command
// schedules. Internal to the engine.
#pragma once

#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>
#include <string>
#include <system_error>

namespace nscd {

inline std::string trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}

// Locale-independent whole-string parse; false when s is not a number. An
// out-of-range value becomes HUGE_VAL, so a finiteness check refuses it.
inline bool parseNumber(const std::string& in, double& out) {
  std::string s = trim(in);
  if (!s.empty() && s[0] == '+') s.erase(0, 1);
  if (s.empty()) return false;
  auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  if (r.ptr != s.data() + s.size()) return false;
  if (r.ec == std::errc::result_out_of_range) out = HUGE_VAL;
  else if (r.ec != std::errc()) return false;
  return true;
}

// x as the shortest %g-like text, for messages ("1e-05", "0.5").
inline std::string num(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

}  // namespace nscd
