// Small command-line helpers of the programs that read their options by hand
// (tools/fclib/nscd_fclib.cpp, bench/mujoco/mujoco_compare.cpp). Header-only and
// included by relative path: an optional target that uses it links nothing new.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace nscd_cli {

// The next argument, argv[i + 1] (i then points at it), as the value of `option`
// (an option may take several); without one, "OPTION needs a value" and exit status 2.
inline std::string optionValue(const std::string& option, int argc, char** argv, int& i) {
  if (i + 1 >= argc) {
    std::fprintf(stderr, "%s needs a value\n", option.c_str());
    std::exit(2);
  }
  return argv[++i];
}

// "a,b,c" -> {"a", "b", "c"}; empty items are kept ("" -> {""}).
inline std::vector<std::string> splitCommas(const std::string& s) {
  std::vector<std::string> out;
  size_t a = 0;
  while (a <= s.size()) {
    const size_t b = s.find(',', a);
    out.push_back(s.substr(a, b == std::string::npos ? std::string::npos : b - a));
    if (b == std::string::npos) break;
    a = b + 1;
  }
  return out;
}

}  // namespace nscd_cli
