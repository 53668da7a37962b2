// The contract of every file sink (hmz_output/frame_sink.hpp), run over every file row of the
// table in hmz_output/output_drivers.cpp: N frames written then finish() leave an output holding N
// frames; a sink destroyed before finish() leaves nothing behind; description() names the output.
// A row is covered by giving it a case maker below; a row without one fails the suite.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "hmz_output/display_drivers.hpp"
#include "hmz_output/file_sink_drivers.hpp"
#include "hmz_output/sink.hpp"
#include "support/image_files.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::files_in;
using test::run_command;
using test::q;
using test::TempDir;

constexpr int kWidth = 64, kHeight = 32;  // even: 4:2:0 encoders take it
constexpr double kRate = 10.0;

// A pipe whose read end does not block: the raw sink writes into it, the test reads what came.
struct Pipe {
  int read_end = -1, write_end = -1;
  Pipe() {
    int fds[2];
    if (::pipe(fds) != 0) throw std::runtime_error("pipe failed");
    read_end = fds[0];
    write_end = fds[1];
    ::fcntl(read_end, F_SETFL, O_NONBLOCK);
  }
  ~Pipe() {
    ::close(read_end);
    ::close(write_end);
  }
  Pipe(const Pipe&) = delete;
  Pipe& operator=(const Pipe&) = delete;
  std::size_t drain() const {
    std::size_t total = 0;
    char buffer[4096];
    for (;;) {
      const ssize_t n = ::read(read_end, buffer, sizeof buffer);
      if (n > 0) {
        total += static_cast<std::size_t>(n);
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      return total;
    }
  }
};

struct SinkCase {
  std::string what;    // for the failure messages
  std::string output;  // the output name, a path in the test directory or `-`
  int bits = 8;
  long frames = 3;
  std::string described_as;  // what description() must contain
  int raw_fd = 1;
  // How many frames the finished output holds, read back independently of nelf.
  std::function<long()> frames_found;
  std::shared_ptr<const Pipe> pipe;  // kept open while the case lives
};

long video_frames(const std::filesystem::path& file) {
  const auto r = run_command(
      "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
      "stream=nb_read_frames,width,height -of csv=p=0 " +
      q(file));
  int width = 0, height = 0;
  long frames = -1;
  if (std::sscanf(r.out.c_str(), "%d,%d,%ld", &width, &height, &frames) != 3) return -1;
  if (width != kWidth || height != kHeight) return -1;
  return frames;
}

// Every image of the sequence `name(i)` for i = 1…, as long as they exist and read back at the
// packed size.
long images_found(const std::function<std::filesystem::path(int)>& name) {
  long count = 0;
  for (int i = 1; std::filesystem::exists(name(i)); ++i) {
    const test::ReadBack image = test::read_back(name(i));
    if (image.width != kWidth || image.height != kHeight) return -1;
    ++count;
  }
  return count;
}

using CaseMaker = std::vector<SinkCase> (*)(const std::filesystem::path& dir);

const std::map<std::string, CaseMaker, std::less<>>& case_makers() {
  static const std::map<std::string, CaseMaker, std::less<>> makers = {
      {"raw",
       [](const std::filesystem::path&) {
         std::vector<SinkCase> cases;
         for (int bits : {8, 16}) {
           auto pipe = std::make_shared<const Pipe>();
           SinkCase c{"raw " + std::to_string(bits) + "-bit", "-", bits, 3, "stdout", pipe->write_end, {}, pipe};
           // 8-bit RGBA whatever the packed depth: N × w × h × 4 bytes, nothing more.
           c.frames_found = [pipe] {
             const std::size_t bytes = pipe->drain();
             const std::size_t frame = static_cast<std::size_t>(kWidth) * kHeight * 4;
             return bytes % frame == 0 ? static_cast<long>(bytes / frame) : -1L;
           };
           cases.push_back(std::move(c));
         }
         return cases;
       }},
      {"image",
       [](const std::filesystem::path& dir) {
         const std::string pattern = (dir / "frame_%03d.png").string();
         const std::string one = (dir / "one.png").string();
         SinkCase sequence{"image sequence", pattern, 8, 3, pattern, 1, {}, {}};
         sequence.frames_found = [dir] {
           return images_found([&](int i) {
             char name[32];
             std::snprintf(name, sizeof name, "frame_%03d.png", i);
             return dir / name;
           });
         };
         SinkCase sequence16{"16-bit image sequence", (dir / "deep_%d.tif").string(), 16, 2, "deep_%d.tif", 1, {}, {}};
         sequence16.frames_found = [dir] {
           return images_found([&](int i) { return dir / ("deep_" + std::to_string(i) + ".tif"); });
         };
         SinkCase single{"one image", one, 8, 1, one, 1, {}, {}};
         single.frames_found = [one] {
           return std::filesystem::exists(one) && test::read_back(one).width == kWidth ? 1L : 0L;
         };
         return std::vector<SinkCase>{sequence, sequence16, single};
       }},
      {"encoded",
       [](const std::filesystem::path& dir) {
         const std::string mkv = (dir / "out.mkv").string();
         const std::string mp4 = (dir / "out.mp4").string();
         SinkCase a{"encoded mkv", mkv, 8, 5, mkv, 1, [mkv] { return video_frames(mkv); }, {}};
         SinkCase b{"encoded 10-bit mp4", mp4, 16, 4, mp4, 1, [mp4] { return video_frames(mp4); }, {}};
         return std::vector<SinkCase>{a, b};
       }},
  };
  return makers;
}

PackedFrame packed_frame(int bits, long index) {
  PackedFrame f{kWidth, kHeight, bits,
                std::vector<std::uint8_t>(static_cast<std::size_t>(kWidth) * kHeight * bytes_per_pixel(bits)),
                static_cast<double>(index) / kRate};
  for (std::size_t i = 0; i < f.rgba.size(); ++i) f.rgba[i] = static_cast<std::uint8_t>(i * 7 + index * 31);
  return f;
}

std::unique_ptr<FrameSink> open_case(const FileSinkDriver& row, const SinkCase& c) {
  FrameSinkRequest request;
  request.output = c.output;
  request.width = kWidth;
  request.height = kHeight;
  request.bits = c.bits;
  request.frame_rate = kRate;
  request.raw_fd = c.raw_fd;
  return row.open_file(std::move(request));
}

// Runs `check` on each case of every row, in a fresh directory each; a row without cases fails.
void for_every_case(const std::function<void(const FileSinkDriver&, const SinkCase&, const TempDir&)>& check) {
  ASSERT_FALSE(file_sink_drivers().empty());
  for (const FileSinkDriver& row : file_sink_drivers()) {
    SCOPED_TRACE(std::string(row.name));
    const auto maker = case_makers().find(row.name);
    if (maker == case_makers().end()) {
      ADD_FAILURE() << "file sink row '" << row.name << "' has no case maker in this suite";
      continue;
    }
    TempDir probe_dir;
    const std::size_t count = maker->second(probe_dir.path()).size();
    EXPECT_GT(count, 0u);
    for (std::size_t i = 0; i < count; ++i) {
      TempDir dir;
      const SinkCase c = maker->second(dir.path())[i];
      SCOPED_TRACE(c.what);
      check(row, c, dir);
    }
  }
}

TEST(FileSinkConformance, EachCaseIsTakenByItsOwnRow) {
  for_every_case([](const FileSinkDriver& row, const SinkCase& c, const TempDir&) {
    EXPECT_TRUE(row.accepts(c.output));
    EXPECT_EQ(file_sink_driver_for(c.output).name, row.name) << c.output;
    EXPECT_FALSE(row.help.empty());
  });
}

TEST(FileSinkConformance, FinishedOutputHoldsEveryFrameWritten) {
  for_every_case([](const FileSinkDriver& row, const SinkCase& c, const TempDir&) {
    {
      auto sink = open_case(row, c);
      for (long i = 0; i < c.frames; ++i) sink->write(packed_frame(c.bits, i));
      sink->finish();
    }
    EXPECT_EQ(c.frames_found(), c.frames);
  });
}

TEST(FileSinkConformance, UnfinishedSinkLeavesNothingBehind) {
  for_every_case([](const FileSinkDriver& row, const SinkCase& c, const TempDir& dir) {
    {
      auto sink = open_case(row, c);
      for (long i = 0; i < c.frames; ++i) sink->write(packed_frame(c.bits, i));
    }
    EXPECT_EQ(files_in(dir.path()), std::vector<std::string>{});
  });
}

TEST(FileSinkConformance, DescriptionNamesTheOutput) {
  for_every_case([](const FileSinkDriver& row, const SinkCase& c, const TempDir&) {
    const std::unique_ptr<Sink> sink = open_case(row, c);
    EXPECT_NE(sink->description().find(c.described_as), std::string::npos) << sink->description();
    EXPECT_EQ(sink->refresh_hz(), 0.0);  // untimed
  });
}

// One table of all outputs: the live rows open displays, the file rows sinks, and the two views
// of it (--output of play and calibrate, convert's choice by name) are its two parts.
TEST(FileSinkConformance, TheFileRowsAreTheTablesRowsThatAreNotLive) {
  const auto all = output_drivers();
  const auto live = display_drivers();
  const auto files = file_sink_drivers();
  ASSERT_EQ(live.size() + files.size(), all.size());
  EXPECT_EQ(live.data(), all.data());
  EXPECT_EQ(files.data(), all.data() + live.size());
  for (const OutputDriver& row : live) {
    SCOPED_TRACE(std::string(row.name));
    EXPECT_TRUE(row.live);
    EXPECT_NE(row.open_display, nullptr);
    EXPECT_EQ(row.open_file, nullptr);
    EXPECT_EQ(find_display_driver(row.name), &row);
  }
  for (const OutputDriver& row : files) {
    SCOPED_TRACE(std::string(row.name));
    EXPECT_FALSE(row.live);
    EXPECT_NE(row.accepts, nullptr);
    EXPECT_NE(row.open_file, nullptr);
    EXPECT_EQ(row.open_display, nullptr);
    EXPECT_EQ(find_display_driver(row.name), nullptr);  // play --output raw stays unknown
  }
  EXPECT_EQ(display_driver_names(), "window, fullscreen, kms, quad-buffer or offscreen");
}

// The sequence's own check: a frame whose name is an input is refused before it is written.
TEST(FileSinkConformance, ImageSequenceAsksBeforeEachFrame) {
  TempDir dir;
  FrameSinkRequest request;
  request.output = (dir / "f_%d.png").string();
  request.width = kWidth;
  request.height = kHeight;
  request.frame_rate = kRate;
  std::vector<std::string> asked;
  request.refuse_as_output = [&](const std::string& name) {
    asked.push_back(std::filesystem::path(name).filename().string());
    if (asked.size() == 2) throw std::runtime_error("an input");
  };
  auto sink = file_sink_driver_for(request.output).open_file(std::move(request));
  sink->write(packed_frame(8, 0));
  EXPECT_THROW(sink->write(packed_frame(8, 1)), std::runtime_error);
  EXPECT_EQ(asked, (std::vector<std::string>{"f_1.png", "f_2.png"}));
  EXPECT_EQ(files_in(dir.path()), std::vector<std::string>{"f_1.png"});
}

}  // namespace
}  // namespace nelf
