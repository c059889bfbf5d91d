// Runs f(i) for i in [0, n) on `jobs` threads. Each call must be independent
// (one Simulator per call); results go to slot i, so the output order, and the
// bytes written from it, do not depend on the thread count or the scheduling.
#pragma once

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace nscd::sweep {

inline int defaultJobs() { return std::max(1u, std::thread::hardware_concurrency()); }

template <class F>
void parallelFor(long n, int jobs, F&& f) {
  jobs = static_cast<int>(std::max(1L, std::min<long>(jobs, n)));
  std::atomic<long> next{0};
  auto worker = [&] {
    for (long i = next++; i < n; i = next++) f(i);
  };
  if (jobs == 1) {
    worker();
    return;
  }
  std::vector<std::thread> pool;
  for (int j = 0; j < jobs; ++j) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
}

}  // namespace nscd::sweep
