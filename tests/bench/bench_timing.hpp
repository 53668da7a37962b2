#pragma once
// Timing helpers shared by the benchmarks (not tests: run by hand, DESIGN.md §10).
#include <algorithm>
#include <chrono>
#include <functional>
#include <utility>
#include <vector>

namespace nelf::bench {

// Wall milliseconds of one call of `body` (which waits for what it timed, e.g. glFinish).
inline double elapsed_ms(const std::function<void()>& body) {
  const auto start = std::chrono::steady_clock::now();
  body();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

inline double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// The medians of `runs` timed calls of `peer` and of `own`, called in turn so that both see the
// same machine; the first call of each is dropped (it warms caches and allocations).
inline std::pair<double, double> interleaved_medians(int runs, const std::function<void()>& peer,
                                                     const std::function<void()>& own) {
  std::vector<double> peer_ms, own_ms;
  for (int i = 0; i <= runs; ++i) {
    const double p = elapsed_ms(peer), o = elapsed_ms(own);
    if (i > 0) peer_ms.push_back(p), own_ms.push_back(o);
  }
  return {median(peer_ms), median(own_ms)};
}

}  // namespace nelf::bench
