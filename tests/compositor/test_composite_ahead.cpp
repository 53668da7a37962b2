// Compositing ahead (compositor/cpu/composite_ahead): a packed frame is handed out only for the frame
// and the very setup it was made with; frames no longer wanted, made with an older setup or for
// other views are never handed out; memory stays bounded; the worker stops cleanly while busy.
// One-pixel eyes whose table shows the view's one pixel, so that the packed frame says which view
// went to which eye.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <thread>
#include <vector>

#include "compositor/cpu/composite_ahead.hpp"

namespace nelf {
namespace {

using namespace std::chrono_literals;

// A table for a 1×1 eye from a 1×1 view: the view's pixel as it is.
CompositeTable identity_table() {
  CompositeTable::Recording r;
  r.panel = {1, 1};
  r.reduced = {1, 1};
  r.prefiltered = {1, 1};
  r.horizontal = make_box_axis(1, 0.0, 1.0, 1.0, 1.0, 1, 1.0);
  r.vertical = make_box_axis(1, 0.0, 1.0, 1.0, 1.0, 1, 1.0);
  r.coordinates = {0.5f, 0.5f};
  return CompositeTable(r);
}

// Packed frame 3×1: the left eye at x 0, a black gap, the right eye at x 2.
std::shared_ptr<const CompositeSetup> make_setup(bool swap_eyes,
                                                 std::shared_ptr<const std::array<Image, 2>> grid = nullptr) {
  auto tables = std::make_shared<std::array<std::optional<CompositeTable>, 2>>();
  (*tables)[0] = identity_table();
  (*tables)[1] = identity_table();
  return std::make_shared<const CompositeSetup>(CompositeSetup{tables,
                                                               {std::pair{0, 0}, std::pair{2, 0}},
                                                               {3, 1},
                                                               swap_eyes,
                                                               std::move(grid),
                                                               1,
                                                               1,
                                                               {1, 1},
                                                               0.0,
                                                               nullptr,
                                                               {},
                                                               false,
                                                               nullptr});
}

using Pixel = std::array<int, 4>;
CompositeAhead::Frame make_frame(double pts, Pixel left, Pixel right, int width = 1) {
  auto f = std::make_shared<StereoVideoFrame>();
  f->width = width;
  f->height = 1;
  f->pts_s = pts;
  for (int x = 0; x < width; ++x)
    for (int c = 0; c < 4; ++c) {
      f->left.push_back(static_cast<std::uint8_t>(left[c]));
      f->right.push_back(static_cast<std::uint8_t>(right[c]));
    }
  return f;
}

// The packed frame's BGRA pixels, as RGBA.
std::array<Pixel, 3> pixels_of(const CompositeAhead::Packed& packed) {
  EXPECT_EQ(packed.size(), 12u);
  std::array<Pixel, 3> out{};
  constexpr std::array<int, 4> byte_of{2, 1, 0, 3};
  for (int x = 0; x < 3; ++x)
    for (int c = 0; c < 4; ++c) out[x][c] = packed.data()[x * 4 + byte_of[c]];
  return out;
}

void expect_near(const Pixel& a, const Pixel& b) {
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(a[c], b[c], 1) << "channel " << c;
}

const Pixel red{200, 40, 30, 255}, blue{20, 60, 190, 255}, black{0, 0, 0, 255};

TEST(CompositeAhead, HandsOutTheNextFramesMadeWithTheSetupTheyAreShownWith) {
  CompositeAhead ahead(2);
  const auto setup = make_setup(false);
  const std::vector frames{make_frame(0.0, red, blue), make_frame(0.04, blue, red)};
  ahead.want(setup, frames);
  EXPECT_EQ(ahead.wait_until_idle(5s), 2u);

  auto first = ahead.take(*frames[0], *setup);
  ASSERT_TRUE(first);
  const auto p = pixels_of(*first);
  expect_near(p[0], red);    // the left view on the left eye
  expect_near(p[1], black);  // the gap
  expect_near(p[2], blue);
  auto second = ahead.take(*frames[1], *setup);
  ASSERT_TRUE(second);
  expect_near(pixels_of(*second)[0], blue);
  // Taken: not handed out twice (a redraw of the frame composites it on the display's thread).
  EXPECT_FALSE(ahead.take(*frames[1], *setup));
}

TEST(CompositeAhead, NeverHandsOutAFrameMadeWithAnotherSetup) {
  CompositeAhead ahead(2);
  const auto before = make_setup(false);
  const std::vector frames{make_frame(0.0, red, blue), make_frame(0.04, red, blue)};
  ahead.want(before, frames);
  EXPECT_EQ(ahead.wait_until_idle(5s), 2u);

  // The same contents, another object: what a key makes (here eyes swapped).
  const auto after = make_setup(true);
  EXPECT_FALSE(ahead.take(*frames[0], *after));
  // Once wanted with the new setup, the frame is made again, with it.
  ahead.want(after, std::span(frames).subspan(1));
  EXPECT_EQ(ahead.wait_until_idle(5s), 1u);
  EXPECT_FALSE(ahead.take(*frames[1], *before));
  ahead.want(after, std::span(frames).subspan(1));
  EXPECT_EQ(ahead.wait_until_idle(5s), 1u);
  const auto swapped = ahead.take(*frames[1], *after);
  ASSERT_TRUE(swapped);
  expect_near(pixels_of(*swapped)[0], blue);  // the right view on the left eye
  expect_near(pixels_of(*swapped)[2], red);
}

TEST(CompositeAhead, NothingIsMadeWithoutASetupAndWhatWasMadeIsForgotten) {
  CompositeAhead ahead(2);
  const auto setup = make_setup(false);
  const std::vector frames{make_frame(0.0, red, blue)};
  ahead.want(setup, frames);
  EXPECT_EQ(ahead.wait_until_idle(5s), 1u);
  // A message shows (GL path): no setup, nothing kept even if the same setup comes back.
  ahead.want(nullptr, frames);
  EXPECT_EQ(ahead.wait_until_idle(5s), 0u);
  EXPECT_FALSE(ahead.take(*frames[0], *setup));
}

TEST(CompositeAhead, FramesNoLongerWantedAreForgottenAsAfterASeek) {
  CompositeAhead ahead(2);
  const auto setup = make_setup(false);
  const std::vector old_frames{make_frame(5.0, red, blue), make_frame(5.04, red, blue)};
  ahead.want(setup, old_frames);
  EXPECT_EQ(ahead.wait_until_idle(5s), 2u);
  const std::vector new_frames{make_frame(0.0, blue, red)};
  ahead.want(setup, new_frames);
  EXPECT_EQ(ahead.wait_until_idle(5s), 1u);
  EXPECT_FALSE(ahead.take(*old_frames[0], *setup));
  const auto shown = ahead.take(*new_frames[0], *setup);
  ASSERT_TRUE(shown);
  expect_near(pixels_of(*shown)[0], blue);
}

TEST(CompositeAhead, TakingAFrameDropsTheFramesBeforeIt) {
  CompositeAhead ahead(3);
  const auto setup = make_setup(false);
  const std::vector frames{make_frame(0.0, red, blue), make_frame(0.04, blue, red), make_frame(0.08, red, red)};
  ahead.want(setup, frames);
  EXPECT_EQ(ahead.wait_until_idle(5s), 3u);
  EXPECT_TRUE(ahead.take(*frames[1], *setup));  // the scheduler dropped frames[0]
  EXPECT_FALSE(ahead.take(*frames[0], *setup));
  EXPECT_EQ(ahead.wait_until_idle(5s), 1u);
  EXPECT_TRUE(ahead.take(*frames[2], *setup));
}

TEST(CompositeAhead, DrawsTheCalibrationGridOverEachViewBeforeTheEyesAreSwapped) {
  CompositeAhead ahead(2);
  auto grid = std::make_shared<std::array<Image, 2>>(std::array<Image, 2>{Image(1, 1), Image(1, 1)});
  (*grid)[0].at(0, 0) = Rgba{1.f, 1.f, 0.f, 1.f};  // over the first view: yellow
  (*grid)[1].at(0, 0) = Rgba{0.f, 0.f, 0.f, 0.f};  // over the second: nothing
  const auto setup = make_setup(true, grid);
  const std::vector frames{make_frame(0.0, red, blue)};
  ahead.want(setup, frames);
  EXPECT_EQ(ahead.wait_until_idle(5s), 1u);
  const auto packed = ahead.take(*frames[0], *setup);
  ASSERT_TRUE(packed);
  expect_near(pixels_of(*packed)[0], blue);
  expect_near(pixels_of(*packed)[2], Pixel{255, 255, 0, 255});
  EXPECT_EQ(frames[0]->left[0], 200);  // the queued frame itself is not drawn on
}

TEST(CompositeAhead, DrawsTheMessageOverBothViewsAfterTheGrid) {
  CompositeAhead ahead(2);
  auto grid = std::make_shared<std::array<Image, 2>>(std::array<Image, 2>{Image(1, 1), Image(1, 1)});
  (*grid)[0].at(0, 0) = Rgba{1.f, 1.f, 0.f, 1.f};  // over the first view: yellow
  (*grid)[1].at(0, 0) = Rgba{0.f, 0.f, 0.f, 0.f};  // over the second: nothing
  // A message box half covering: grey at half opacity, over the grid, on both views.
  auto message = std::make_shared<Image>(1, 1);
  message->at(0, 0) = Rgba{0.2f, 0.2f, 0.2f, 0.5f};
  const auto base = make_setup(false, grid);
  auto with_message = std::make_shared<CompositeSetup>(*base);
  with_message->message = message;
  const std::shared_ptr<const CompositeSetup> setup = with_message;
  const std::vector frames{make_frame(0.0, red, blue)};
  ahead.want(setup, frames);
  EXPECT_EQ(ahead.wait_until_idle(5s), 1u);
  const auto packed = ahead.take(*frames[0], *setup);
  ASSERT_TRUE(packed);
  const auto over = [](int view, int text) { return static_cast<int>(std::lround(view * 0.5 + text * 0.5)); };
  expect_near(pixels_of(*packed)[0], Pixel{over(255, 51), over(255, 51), over(0, 51), 255});  // grid, then text
  expect_near(pixels_of(*packed)[2], Pixel{over(20, 51), over(60, 51), over(190, 51), 255});
  EXPECT_EQ(frames[0]->left[0], 200);  // the queued frame itself is not drawn on
}

TEST(CompositeAhead, FramesForOtherViewsAreLeftToTheDisplaysThread) {
  CompositeAhead ahead(2);
  const auto setup = make_setup(false);
  const std::vector frames{make_frame(0.0, red, blue, 2)};  // decoded at another size
  ahead.want(setup, frames);
  EXPECT_EQ(ahead.wait_until_idle(5s), 0u);
  EXPECT_FALSE(ahead.take(*frames[0], *setup));
}

TEST(CompositeAhead, KeepsAtMostDepthPlusOnePackedFrames) {
  CompositeAhead ahead(2);
  const auto setup = make_setup(false);
  std::vector<CompositeAhead::Frame> frames;
  for (int i = 0; i < 50; ++i) frames.push_back(make_frame(i / 30.0, red, blue));
  for (std::size_t i = 0; i < frames.size(); ++i) {
    ahead.want(setup, std::span(frames).subspan(i));
    EXPECT_LE(ahead.wait_until_idle(5s), 2u);
    const auto shown = ahead.take(*frames[i], *setup);
    EXPECT_TRUE(shown);
    EXPECT_LE(ahead.buffers(), 3u);
  }
  EXPECT_LE(ahead.buffers(), 3u);
}

TEST(CompositeAhead, StopsWhileFramesAreWanted) {
  const auto setup = make_setup(false);
  std::vector<CompositeAhead::Frame> frames;
  for (int i = 0; i < 4; ++i) frames.push_back(make_frame(i / 30.0, red, blue));
  for (int round = 0; round < 20; ++round) {
    CompositeAhead ahead(2);
    ahead.want(setup, frames);
  }  // each destructor returns (the test would hang otherwise)
}

// Each frame's surfaces are made once, whichever thread asks first, and a frame's unusable depth
// is refused each time it is asked for.
TEST(FrameSurfaces, MadeOncePerDisparityAndSharedRefusingUnusableMaps) {
  FrameSurfaces surfaces;
  const auto disparity = [](float value) {
    ViewDisparity map{4, 2, std::vector<float>(8, value)};
    return std::make_shared<const StereoDisparity>(StereoDisparity{map, map, DisparityOrigin::estimated});
  };
  const auto first = disparity(1.f), second = disparity(2.f);
  const FrameSurfaces::Pair a = surfaces.get(first);
  ASSERT_TRUE(a[0] && a[1]);
  EXPECT_EQ(surfaces.get(first), a);
  const FrameSurfaces::Pair b = surfaces.get(second);
  EXPECT_NE(b[0], a[0]);
  EXPECT_EQ(b[0]->front(), 2.f / 4.f);
  // From another thread: the same objects.
  FrameSurfaces::Pair from_worker;
  std::thread([&] { from_worker = surfaces.get(first); }).join();
  EXPECT_EQ(from_worker, a);
  const auto broken = std::make_shared<const StereoDisparity>(
      StereoDisparity{ViewDisparity{4, 2, std::vector<float>(3)}, ViewDisparity{4, 2, std::vector<float>(8)}});
  EXPECT_THROW(surfaces.get(broken), std::invalid_argument);
  EXPECT_THROW(surfaces.get(broken), std::invalid_argument);
  // Only the last few frames' are kept: an old one is made again, as new objects.
  for (int i = 0; i < 10; ++i) surfaces.get(disparity(static_cast<float>(i)));
  EXPECT_NE(surfaces.get(first)[0], a[0]);
}

}  // namespace
}  // namespace nelf
