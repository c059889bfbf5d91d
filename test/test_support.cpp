#include "test_support.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <new>
#include <sstream>
#include <stdexcept>

// Counts heap allocations (nscd_test::allocationCount()). Out of line, so that
// the compiler cannot see through the calls and drop an allocation.
static std::atomic<long> g_allocations{0};
__attribute__((noinline)) void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
__attribute__((noinline)) void operator delete(void* p) noexcept { std::free(p); }
__attribute__((noinline)) void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace nscd_test {

long allocationCount() { return g_allocations.load(); }

std::string sourceDir() { return NSCD_SOURCE_DIR; }
std::string scenePath(const std::string& rel) { return sourceDir() + "/" + rel; }
std::string runExe() { return NSCD_RUN_EXE; }

static std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

RunResult runNscd(const std::string& args) { return runProgram(runExe(), args); }

std::string toolExe(const std::string& name) {
  const std::string run = runExe();
  return run.substr(0, run.rfind('/') + 1) + name;
}

RunResult runProgram(const std::string& exe, const std::string& args) {
  char out_tmpl[] = "/tmp/nscd_test_outXXXXXX";
  char err_tmpl[] = "/tmp/nscd_test_errXXXXXX";
  int fo = mkstemp(out_tmpl);
  int fe = mkstemp(err_tmpl);
  if (fo < 0 || fe < 0) throw std::runtime_error("mkstemp failed");
  close(fo);
  close(fe);
  std::string cmd = exe + " " + args + " >" + out_tmpl + " 2>" + err_tmpl;
  int rc = std::system(cmd.c_str());
  RunResult r;
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  r.out = slurp(out_tmpl);
  r.err = slurp(err_tmpl);
  std::remove(out_tmpl);
  std::remove(err_tmpl);
  return r;
}

std::string writeTemp(const std::string& text, const std::string& suffix) {
  std::string tmpl = "/tmp/nscd_test_XXXXXX" + suffix;
  std::string buf = tmpl;
  int fd = mkstemps(&buf[0], static_cast<int>(suffix.size()));
  if (fd < 0) throw std::runtime_error("mkstemps failed");
  ssize_t n = write(fd, text.data(), text.size());
  close(fd);
  if (n != static_cast<ssize_t>(text.size())) throw std::runtime_error("short write");
  return buf;
}

}  // namespace nscd_test
