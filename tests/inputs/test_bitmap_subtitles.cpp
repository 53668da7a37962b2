// Bitmap subtitle tracks: PGS pictures (a .sup written by tests/support/pgs_subtitles.hpp) shown in
// their time and scaled from the canvas they were authored on to the view; the same pictures as
// DVB and VobSub subtitles (made from it by the ffmpeg CLI) land in the same place; pictures
// authored per eye (--sub-stereo) go each to its own eye.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/user_error.hpp"
#include "inputs/subtitle_track.hpp"
#include "support/media.hpp"
#include "support/pgs_subtitles.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::PgsBox;
using test::PgsCue;
using test::TempDir;

// The box of the pixels of `rgba` (`width` wide) with alpha above half.
struct Box {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
  bool empty() const { return x1 < 0; }
};
Box covered(const std::vector<std::uint8_t>& rgba, int width) {
  Box b;
  for (std::size_t i = 0; i < rgba.size() / 4; ++i)
    if (rgba[i * 4 + 3] > 127) {
      const int x = static_cast<int>(i % static_cast<std::size_t>(width)),
                y = static_cast<int>(i / static_cast<std::size_t>(width));
      b.x0 = std::min(b.x0, x), b.x1 = std::max(b.x1, x);
      b.y0 = std::min(b.y0, y), b.y1 = std::max(b.y1, y);
    }
  return b;
}

void expect_box(const Box& b, int x0, int y0, int x1, int y1) {
  EXPECT_NEAR(b.x0, x0, 1);
  EXPECT_NEAR(b.y0, y0, 1);
  EXPECT_NEAR(b.x1, x1, 1);
  EXPECT_NEAR(b.y1, y1, 1);
}

// A half side-by-side movie's PGS: authored on its whole 640x180 frame, one box in the middle from
// 0.5 to 1.5 s, another at the top left from 2 to 3 s.
std::filesystem::path two_cues(const TempDir& dir) {
  return test::write_pgs(dir / "movie.sup", 640, 180,
                         {PgsCue{0.5, 1.5, {PgsBox{240, 120, 160, 30}}}, PgsCue{2.0, 3.0, {PgsBox{0, 0, 64, 32}}}});
}

TEST(BitmapSubtitles, PgsPicturesShowInTheirTimeScaledFromTheirCanvasToTheView) {
  TempDir dir;
  SubtitleTrack track(two_cues(dir).string(), 0.0);
  EXPECT_NE(track.description().find("pgssub"), std::string::npos) << track.description();
  EXPECT_TRUE(track.render(0.2, 320, 180, 16.0 / 9.0).empty());
  const SubtitleBitmap on = track.render(1.0, 320, 180, 16.0 / 9.0);
  ASSERT_FALSE(on.empty());
  EXPECT_TRUE(on.right_rgba.empty());                     // one picture for both eyes
  expect_box(covered(on.rgba, 320), 120, 120, 199, 149);  // halved across, as the view is
  const std::uint8_t* centre = &on.rgba[(135u * 320u + 160u) * 4u];
  for (int c = 0; c < 4; ++c) EXPECT_GE(centre[c], 250) << c;    // opaque white
  EXPECT_TRUE(track.render(1.7, 320, 180, 16.0 / 9.0).empty());  // the clearing display set
  expect_box(covered(track.render(2.5, 320, 180, 16.0 / 9.0).rgba, 320), 0, 0, 31, 31);
  EXPECT_TRUE(track.render(3.2, 320, 180, 16.0 / 9.0).empty());
  // Back in time: read again.
  expect_box(covered(track.render(1.0, 320, 180, 16.0 / 9.0).rgba, 320), 120, 120, 199, 149);
}

TEST(BitmapSubtitles, DvbAndVobSubMadeByTheFfmpegCliLandWherePgsDoes) {
  TempDir dir;
  // A DVD's or an SD broadcast's 720x576 canvas, shown in a 320x180 view.
  const auto sup = test::write_pgs(dir / "sd.sup", 720, 576, {PgsCue{0.5, 1.5, {PgsBox{270, 480, 180, 48}}}});
  for (const char* codec : {"copy", "dvbsub", "dvdsub"}) {
    SCOPED_TRACE(codec);
    const std::filesystem::path mkv = dir / (std::string(codec) + ".mkv");
    // PGS says no end of its own: -fix_sub_duration gives each picture its time until the next.
    test::make_media(mkv, "-fix_sub_duration -copyts -i " + test::q(sup) + " -c:s " + codec);
    SubtitleTrack track(mkv.string(), 0.0);
    EXPECT_TRUE(track.render(0.2, 320, 180, 0.0).empty());
    expect_box(covered(track.render(1.0, 320, 180, 0.0).rgba, 320), 120, 150, 199, 164);
    EXPECT_TRUE(track.render(1.7, 320, 180, 0.0).empty());
  }
}

TEST(BitmapSubtitles, PicturesAuthoredPerEyeGoEachToItsOwnEye) {
  TempDir dir;
  // Side by side: the left eye's box in the left half of the canvas, the right eye's elsewhere in
  // the right half.
  const auto sbs =
      test::write_pgs(dir / "sbs.sup", 640, 180, {PgsCue{0.5, 1.5, {PgsBox{40, 60, 80, 40}, PgsBox{520, 60, 80, 40}}}});
  {
    SubtitleTrack flat(sbs.string(), 0.0);
    const SubtitleBitmap both = flat.render(1.0, 320, 180, 0.0);
    EXPECT_TRUE(both.right_rgba.empty());
    expect_box(covered(both.rgba, 320), 20, 60, 299, 99);  // both boxes, halved across
  }
  SubtitleTrack track(sbs.string(), 0.0);
  track.set_stereo(SubtitleStereo::side_by_side);
  const SubtitleBitmap eyes = track.render(1.0, 320, 180, 0.0);
  ASSERT_EQ(eyes.right_rgba.size(), eyes.rgba.size());
  expect_box(covered(eyes.rgba, 320), 40, 60, 119, 99);
  expect_box(covered(eyes.right_rgba, 320), 200, 60, 279, 99);

  const auto tab = test::write_pgs(dir / "tab.sup", 320, 360,
                                   {PgsCue{0.5, 1.5, {PgsBox{40, 60, 80, 40}, PgsBox{200, 240, 80, 40}}}});
  SubtitleTrack stacked(tab.string(), 0.0);
  stacked.set_stereo(SubtitleStereo::top_bottom);
  const SubtitleBitmap rows = stacked.render(1.0, 320, 180, 0.0);
  expect_box(covered(rows.rgba, 320), 40, 60, 119, 99);
  expect_box(covered(rows.right_rgba, 320), 200, 60, 279, 99);
}

TEST(BitmapSubtitles, TextIsNotAuthoredPerEye) {
  TempDir dir;
  test::write_file(dir / "movie.srt", "1\n00:00:01,000 --> 00:00:02,000\nHELLO\n\n");
  SubtitleTrack track((dir / "movie.srt").string(), 0.0);
  try {
    track.set_stereo(SubtitleStereo::side_by_side);
    FAIL() << "accepted";
  } catch (const UserError& e) {
    EXPECT_EQ(e.status(), 2);
    EXPECT_NE(std::string(e.what()).find("--sub-stereo"), std::string::npos) << e.what();
  }
  track.set_stereo(SubtitleStereo::flat);  // what text is anyway
}

}  // namespace
}  // namespace nelf
