#pragma once
// The rows of play's --log-frames CSV (one a presented refresh), as the cli tests read them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace nelf::test {

struct LogRow {
  std::string event;
  double pts = 0, clock = 0;  // pts -1: the row has none
  std::string audio_clock;
  bool ahead = false;  // shown as composited ahead on the CPU tables' worker
};

inline std::vector<LogRow> read_log(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("refresh,event,pts_s,clock_s,audio_clock_s,shown,repeated,dropped", 0), 0u) << line;
  std::vector<LogRow> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream s(line);
    std::string field;
    while (std::getline(s, field, ',')) f.push_back(field);
    if (f.size() < 5) continue;
    rows.push_back({f[1], f[2].empty() ? -1 : std::stod(f[2]), std::stod(f[3]), f[4], f.size() > 12 && f[12] == "1"});
  }
  return rows;
}

}  // namespace nelf::test
