// Helpers shared by the unit tests: paths, running nscd_run, temporary files.
#pragma once

#include <string>

namespace nscd_test {

std::string sourceDir();                 // the package source directory
std::string scenePath(const std::string& rel);  // sourceDir()/rel
std::string runExe();                    // path of the built nscd_run

struct RunResult {
  int status = -1;   // exit status
  std::string out;   // stdout
  std::string err;   // stderr
};
// Runs nscd_run with the given argument string (shell-quoted by the caller).
RunResult runNscd(const std::string& args);
// Runs another program the same way (e.g. toolExe("nscd_sweep")).
RunResult runProgram(const std::string& exe, const std::string& args);
// Path of a tool built beside nscd_run (same devel bin folder).
std::string toolExe(const std::string& name);

// Heap allocations (global operator new calls) since the test program
// started: test_support.cpp replaces operator new in every unit test with one
// that counts, to check that code allocates nothing.
long allocationCount();

// Writes text to a fresh temporary file with the given suffix; returns its path.
std::string writeTemp(const std::string& text, const std::string& suffix = ".urdf");

}  // namespace nscd_test
