#pragma once
// Timing helpers shared by the benchmarks (not tests: run by hand, DESIGN.md §10).
#include <algorithm>
#include <chrono>
#include <functional>
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

}  // namespace nelf::bench
