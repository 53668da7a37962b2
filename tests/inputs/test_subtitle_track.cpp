// Subtitle tracks: an SRT line laid out by libass at the view's own aspect, timed, found beside a
// movie, and a file that is no subtitles refused in one line.
#include <gtest/gtest.h>

#include <fstream>

#include "core/user_error.hpp"
#include "inputs/subtitle_track.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {
// This file's own names: its suite is compiled as one unit (tests/CMakeLists.txt).
namespace test_subtitle_track {

using test::TempDir;

const char* const kSrt =
    "1\n00:00:01,000 --> 00:00:02,000\nHELLO WORLD\n\n"
    "2\n00:00:03,000 --> 00:00:04,000\nSECOND LINE\n\n";

// The box of the pixels a subtitle covers (alpha above 0).
struct Box {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
  int width() const { return x1 - x0 + 1; }
  int height() const { return y1 - y0 + 1; }
};
Box covered(const SubtitleBitmap& s) {
  Box b;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x)
      if (s.rgba[(static_cast<std::size_t>(y) * s.width + x) * 4 + 3] > 0) {
        b.x0 = std::min(b.x0, x), b.x1 = std::max(b.x1, x);
        b.y0 = std::min(b.y0, y), b.y1 = std::max(b.y1, y);
      }
  return b;
}

TEST(SubtitleTrack, RendersAnSrtLineCentredAtTheBottomWhileItIsOn) {
  TempDir dir;
  test::write_file(dir / "movie.srt", kSrt);
  SubtitleTrack track((dir / "movie.srt").string(), 0.0);
  EXPECT_TRUE(track.render(0.5, 640, 360, 0.0).empty());
  const SubtitleBitmap on = track.render(1.5, 640, 360, 0.0);
  ASSERT_FALSE(on.empty());
  ASSERT_EQ(on.rgba.size(), 640u * 360u * 4u);
  const Box box = covered(on);
  EXPECT_NEAR((box.x0 + box.x1) / 2.0, 320.0, 8.0);
  EXPECT_GT(box.y0, 360 * 2 / 3);
  EXPECT_GT(box.width(), 100);
  EXPECT_TRUE(track.render(2.5, 640, 360, 0.0).empty());
  EXPECT_FALSE(track.render(3.5, 640, 360, 0.0).empty());
  EXPECT_FALSE(track.render(1.2, 640, 360, 0.0).empty());  // back in time
}

TEST(SubtitleTrack, ASqueezedViewGetsLettersSqueezedToLookRightWhenStretched) {
  TempDir dir;
  test::write_file(dir / "movie.srt", kSrt);
  SubtitleTrack track((dir / "movie.srt").string(), 0.0);
  // A half side-by-side view: 320x360 pixels shown at 16:9, as a 640x360 view is.
  const Box full = covered(track.render(1.5, 640, 360, 16.0 / 9.0));
  const Box half = covered(track.render(1.5, 320, 360, 16.0 / 9.0));
  EXPECT_NEAR(half.width(), full.width() / 2.0, 4.0);
  EXPECT_NEAR(half.height(), full.height(), 2.0);
}

TEST(SubtitleTrack, StartMovesTheCallersTimeZero) {
  TempDir dir;
  test::write_file(dir / "movie.srt", kSrt);
  SubtitleTrack track((dir / "movie.srt").string(), 3.0);  // --start 3
  EXPECT_FALSE(track.render(0.5, 320, 180, 0.0).empty());
  EXPECT_TRUE(track.render(1.5, 320, 180, 0.0).empty());
}

TEST(SubtitleTrack, FindsTheFilesBesideAMovieAsMpvDoes) {
  TempDir dir;
  for (const char* name :
       {"movie.mkv", "movie.srt", "movie.en.ass", "movie.de.vtt", "movie.fr.sup", "other.srt", "movie.txt"})
    test::write_file(dir / name, "x");
  const std::vector<std::string> expected{(dir / "movie.srt").string(), (dir / "movie.de.vtt").string(),
                                          (dir / "movie.en.ass").string(), (dir / "movie.fr.sup").string()};
  EXPECT_EQ(SubtitleTrack::beside((dir / "movie.mkv").string()), expected);
  EXPECT_TRUE(SubtitleTrack::beside((dir / "missing.mkv").string()).empty());
}

TEST(SubtitleTrack, AFileThatIsNoSubtitlesIsOneLine) {
  TempDir dir;
  std::ofstream(dir / "bad.srt", std::ios::binary) << std::string("\x00\x01\x02\xff\xfe garbage", 14);
  try {
    SubtitleTrack track((dir / "bad.srt").string(), 0.0);
    FAIL() << "opened";
  } catch (const UserError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.srt"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_THROW(SubtitleTrack((dir / "none.srt").string(), 0.0), UserError);
  EXPECT_FALSE(SubtitleTrack::has_subtitles((dir / "none.srt").string()));
}

}  // namespace test_subtitle_track
}  // namespace
}  // namespace nelf
