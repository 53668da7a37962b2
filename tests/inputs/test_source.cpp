// Source: views delivered as block means when the caller negotiates them, across seeks and
// changes of the block.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "core/user_error.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/video_source.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::make_media;
using test::TempDir;

class SourceTest : public ::testing::Test {
 protected:
  void SetUp() override { quiet_ffmpeg_logs(true); }
  TempDir dir;
};

// Mean of channel c over a tightly packed RGBA8 view.
double channel_mean(const std::vector<std::uint8_t>& rgba, int c) {
  double sum = 0.0;
  for (std::size_t i = static_cast<std::size_t>(c); i < rgba.size(); i += 4) sum += rgba[i];
  return sum / static_cast<double>(rgba.size() / 4) / 255.0;
}

SourceRequest request_for(const std::string& input) {
  return SourceRequest{input, "", StereoLayout::sbs, false, std::nullopt, true, false};
}

// Red left view, blue right view, 64×36 each, 20 frames at 10 fps.
std::string make_sbs_clip(const TempDir& dir) {
  return make_media(dir / "sbs.mkv", test::two_colour_input(64, 36, false, 20, 10) + " -c:v ffv1 -pix_fmt yuv420p")
      .string();
}

void expect_views(const StereoVideoFrame& f, std::array<int, 2> block) {
  EXPECT_EQ(f.width, 64);
  EXPECT_EQ(f.height, 36);
  EXPECT_EQ(f.block, block);
  const std::size_t bytes = static_cast<std::size_t>(64 / block[0]) * (36 / block[1]) * 4;
  ASSERT_EQ(f.left.size(), bytes);
  ASSERT_EQ(f.right.size(), bytes);
  EXPECT_GT(channel_mean(f.left, 0), 0.9);
  EXPECT_LT(channel_mean(f.left, 2), 0.1);
  EXPECT_GT(channel_mean(f.right, 2), 0.9);
  EXPECT_LT(channel_mean(f.right, 0), 0.1);
}

TEST_F(SourceTest, DeliversTheNegotiatedBlockMeansFromTheFirstFrameOn) {
  auto source = open_source(request_for(make_sbs_clip(dir)));
  const ViewGeometry view = source->info().view;
  EXPECT_EQ(view.width, 64);  // the view, not the frame
  EXPECT_EQ(view.height, 36);
  EXPECT_EQ(source->negotiate({{4, 4}}), (ViewFormat{{4, 4}}));
  const auto first = source->next();
  ASSERT_TRUE(first);
  expect_views(*first, {4, 4});
  EXPECT_NEAR(first->pts_s, 0.0, 1e-6);
}

TEST_F(SourceTest, ASeekKeepsTheViewsReduced) {
  auto source = open_source(request_for(make_sbs_clip(dir)));
  source->negotiate({{2, 3}});
  ASSERT_TRUE(source->next());
  ASSERT_TRUE(source->next());
  source->seek(1.0);
  const auto after = source->next();
  ASSERT_TRUE(after);
  EXPECT_NEAR(after->pts_s, 1.0, 1e-6);
  expect_views(*after, {2, 3});
  source->seek(0.0);  // back to the start, as a player does
  const auto again = source->next();
  ASSERT_TRUE(again);
  EXPECT_NEAR(again->pts_s, 0.0, 1e-6);
  expect_views(*again, {2, 3});
}

TEST_F(SourceTest, TheBlockCanChangeMidStreamAndBackToWholeViews) {
  auto source = open_source(request_for(make_sbs_clip(dir)));
  const auto whole = source->next();
  ASSERT_TRUE(whole);
  expect_views(*whole, {1, 1});
  EXPECT_EQ(source->negotiate({{4, 2}}), (ViewFormat{{4, 2}}));
  const auto reduced = source->next();
  ASSERT_TRUE(reduced);
  EXPECT_NEAR(reduced->pts_s, 0.1, 1e-6);  // no frame lost or repeated by the change
  expect_views(*reduced, {4, 2});
  EXPECT_EQ(source->negotiate({}), (ViewFormat{{1, 1}}));
  const auto back = source->next();
  ASSERT_TRUE(back);
  EXPECT_NEAR(back->pts_s, 0.2, 1e-6);
  expect_views(*back, {1, 1});
}

TEST_F(SourceTest, ABlockThatDoesNotDivideTheViewGivesWholeViews) {
  auto source = open_source(request_for(make_sbs_clip(dir)));
  EXPECT_EQ(source->negotiate({{5, 5}}), (ViewFormat{{1, 1}}));
  const auto f = source->next();
  ASSERT_TRUE(f);
  expect_views(*f, {1, 1});
}

TEST_F(SourceTest, ChangingTheBlockBeforeTheFirstFrameReconvertsIt) {
  // The first frame is decoded while opening (layout detection); asking afterwards must not hand
  // it out at the old size.
  auto source = open_source(request_for(make_sbs_clip(dir)));
  EXPECT_EQ(source->negotiate({{2, 2}}), (ViewFormat{{2, 2}}));
  const auto first = source->next();
  ASSERT_TRUE(first);
  EXPECT_NEAR(first->pts_s, 0.0, 1e-6);
  expect_views(*first, {2, 2});
}

TEST_F(SourceTest, SyntheticSourceAlwaysDeliversWholeViews) {
  auto source = open_source(request_for("synthetic:duration=1"));
  EXPECT_EQ(source->negotiate({{2, 2}}), (ViewFormat{{1, 1}}));
  const auto f = source->next();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->block, (std::array<int, 2>{1, 1}));
  EXPECT_EQ(f->left.size(), static_cast<std::size_t>(f->width) * f->height * 4);
  EXPECT_EQ(source->info().view, (ViewGeometry{f->width, f->height, f->aspect}));
}

TEST(SourceDrivers, EachRequestGoesToTheFirstRowThatAcceptsItAndTheFileDriverTakesTheRest) {
  const auto drivers = source_drivers();
  ASSERT_GE(drivers.size(), 2u);
  EXPECT_EQ(drivers.back().name, "file");
  for (const SourceDriver& driver : drivers) {
    SCOPED_TRACE(std::string(driver.name));
    EXPECT_FALSE(driver.help.empty());
    EXPECT_EQ(std::count(driver.help.begin(), driver.help.end(), '\n'), 0);
  }
  EXPECT_EQ(source_driver_for(request_for("synthetic:duration=1")).name, "synthetic");
  EXPECT_EQ(source_driver_for(request_for("movie.mkv")).name, "file");
  EXPECT_EQ(source_driver_for(request_for("https://example.com/a.mp4")).name, "file");
}

// A source that does not override seek() (a live capture, say) refuses it in one line naming the
// input, with status 1, and says so in info().
class OneFrameSource final : public Source {
 public:
  SourceInfo info() const override {
    SourceInfo info;
    info.frame_rate = 30;
    info.live = true;
    info.description = "capture:test";
    return info;
  }
  std::optional<StereoVideoFrame> next() override { return std::nullopt; }
};

TEST(SourceDefaults, ASourceThatCannotSeekRefusesInOneLine) {
  OneFrameSource source;
  EXPECT_FALSE(source.info().seekable);
  try {
    source.seek(1.0);
    FAIL() << "seek() succeeded";
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), "capture:test: this input cannot seek");
    EXPECT_EQ(e.status(), 1);
  }
}

TEST_F(SourceTest, AFileSaysItsRateFramesDurationAndThatItCanSeek) {
  auto source = open_source(request_for(make_sbs_clip(dir)));
  const SourceInfo info = source->info();
  EXPECT_DOUBLE_EQ(info.frame_rate, 10.0);
  ASSERT_TRUE(info.duration_s);
  EXPECT_NEAR(*info.duration_s, 2.0, 1e-6);
  EXPECT_TRUE(info.seekable);
  EXPECT_FALSE(info.live);
  EXPECT_NE(info.description.find("128x36 ffv1, layout sbs (flag)"), std::string::npos) << info.description;
}

}  // namespace
}  // namespace nelf
