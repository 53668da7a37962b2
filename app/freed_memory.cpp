#include "app/freed_memory.hpp"

#include <fmt/format.h>
#include <malloc.h>

namespace nelf::app {
namespace {

constexpr int kHeapBlockMax = 32 << 20;
constexpr int kHeapTopKept = 256 << 20;

}  // namespace

void keep_freed_memory() {
  mallopt(M_MMAP_THRESHOLD, kHeapBlockMax);
  mallopt(M_TRIM_THRESHOLD, kHeapTopKept);
}

std::string freed_memory_tunables(const char* user_tunables) {
  std::string tunables =
      fmt::format("glibc.malloc.mmap_threshold={}:glibc.malloc.trim_threshold={}", kHeapBlockMax, kHeapTopKept);
  if (user_tunables && *user_tunables) tunables += fmt::format(":{}", user_tunables);
  return tunables;
}

}  // namespace nelf::app
