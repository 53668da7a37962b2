// A game's depth buffers turned into disparity (inputs/game_depth.hpp), on eyes made here: a
// textured rectangle in front of a textured background, each at a known disparity and depth-buffer
// value, the right eye made from the left by that disparity (the rectangle occluding the background).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "inputs/game_depth.hpp"

namespace nelf {
namespace {

constexpr int kWidth = 256, kHeight = 128;
constexpr int kRectX0 = 80, kRectX1 = 160, kRectY0 = 30, kRectY1 = 90;  // in the left eye
constexpr float kNearValue = 0.80f, kFarValue = 0.95f;                  // depth-buffer values
constexpr int kNearDisparity = 12, kFarDisparity = -6;

std::uint8_t noise(int x, int y, int layer) {
  std::uint32_t h = static_cast<std::uint32_t>(x) * 73856093u ^ static_cast<std::uint32_t>(y) * 19349663u ^
                    static_cast<std::uint32_t>(layer) * 83492791u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return static_cast<std::uint8_t>(40 + h % 200);
}

// Both eyes, top row first; `flat`: one grey everywhere (nothing to match).
struct MadeEyes {
  std::vector<std::uint8_t> colour[2];
  std::vector<float> depth[2];
  GameEyes eyes() const {
    GameEyes e;
    e.width = kWidth;
    e.height = kHeight;
    for (int i = 0; i < 2; ++i) {
      e.colour[i] = {colour[i].data(), kWidth * 4};
      e.depth[i] = {depth[i].data(), kWidth};
    }
    return e;
  }
};

MadeEyes make_eyes(bool flat = false, bool empty_depth = false) {
  MadeEyes m;
  for (int i = 0; i < 2; ++i) {
    m.colour[i].resize(kWidth * kHeight * 4);
    m.depth[i].resize(kWidth * kHeight);
  }
  const auto in_rect = [](int x, int y) { return x >= kRectX0 && x < kRectX1 && y >= kRectY0 && y < kRectY1; };
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      for (int i = 0; i < 2; ++i) {
        // The left eye's point shown at x: the right eye shows at x the point the left shows at x + d.
        const bool near = i == 0 ? in_rect(x, y) : in_rect(x + kNearDisparity, y);
        const int left_x = i == 0 ? x : x + (near ? kNearDisparity : kFarDisparity);
        const std::size_t p = static_cast<std::size_t>(y) * kWidth + x;
        for (int c = 0; c < 3; ++c) m.colour[i][4 * p + c] = flat ? 128 : noise(left_x + c * 1000, y, near ? 1 : 0);
        m.colour[i][4 * p + 3] = 255;
        m.depth[i][p] = empty_depth ? 1.0f : (near ? kNearValue : kFarValue);
      }
  return m;
}

TEST(GameDepth, TheRelationOfDepthValueToDisparityIsFittedFromTheViews) {
  const MadeEyes made = make_eyes();
  GameDepthRelation relation;
  const auto d = relation.disparity(made.eyes(), {1, 1});
  ASSERT_TRUE(d) << "gap " << static_cast<int>(relation.gap());
  EXPECT_EQ(d->origin, DisparityOrigin::game);
  const double slope = (kNearDisparity - kFarDisparity) / static_cast<double>(kNearValue - kFarValue);
  ASSERT_TRUE(relation.relation());
  EXPECT_NEAR(relation.relation()->slope, slope, 0.02 * std::abs(slope));
  EXPECT_NEAR(relation.relation()->at(kNearValue), kNearDisparity, 0.1);
  EXPECT_NEAR(relation.relation()->at(kFarValue), kFarDisparity, 0.1);
  // Every pixel from its own depth value: the rectangle and the background, in both views.
  ASSERT_EQ(d->left.width, kWidth);
  ASSERT_EQ(d->left.height, kHeight);
  EXPECT_NEAR(d->left.d[60 * kWidth + 120], kNearDisparity, 0.1);
  EXPECT_NEAR(d->left.d[10 * kWidth + 20], kFarDisparity, 0.1);
  EXPECT_NEAR(d->right.d[60 * kWidth + (120 - kNearDisparity)], kNearDisparity, 0.1);
  EXPECT_NEAR(d->right.d[110 * kWidth + 200], kFarDisparity, 0.1);
}

TEST(GameDepth, BlockMeansGiveTheMapInTheirOwnPixels) {
  const MadeEyes made = make_eyes();
  GameDepthRelation relation;
  const auto d = relation.disparity(made.eyes(), {2, 2});
  ASSERT_TRUE(d);
  ASSERT_EQ(d->left.width, kWidth / 2);
  ASSERT_EQ(d->left.height, kHeight / 2);
  EXPECT_NEAR(d->left.d[30 * (kWidth / 2) + 60], kNearDisparity / 2.0, 0.1);
  EXPECT_NEAR(d->left.d[5 * (kWidth / 2) + 10], kFarDisparity / 2.0, 0.1);
}

TEST(GameDepth, EmptyDepthBuffersGiveNoDisparity) {
  const MadeEyes made = make_eyes(false, true);
  GameDepthRelation relation;
  EXPECT_FALSE(relation.disparity(made.eyes(), {1, 1}));
  EXPECT_EQ(relation.gap(), GameDepthGap::empty_buffers);
}

TEST(GameDepth, ViewsWithNothingToMatchGiveNoDisparityUntilTheyHave) {
  GameDepthRelation relation;
  const MadeEyes flat = make_eyes(true);
  EXPECT_FALSE(relation.disparity(flat.eyes(), {1, 1}));
  EXPECT_EQ(relation.gap(), GameDepthGap::too_few_matches);
  // Once a frame has texture, the relation is learnt and kept through a flat frame after it.
  const MadeEyes textured = make_eyes();
  EXPECT_TRUE(relation.disparity(textured.eyes(), {1, 1}));
  const auto kept = relation.disparity(flat.eyes(), {1, 1});
  ASSERT_TRUE(kept);
  EXPECT_NEAR(kept->left.d[60 * kWidth + 120], kNearDisparity, 0.1);
}

}  // namespace
}  // namespace nelf
