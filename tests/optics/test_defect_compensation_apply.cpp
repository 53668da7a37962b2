// The per-frame half of the defect compensation: plans made by hand (plain data), applied to float
// images and to 8- and 16-bit RGBA bytes.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <vector>

#include "optics/defect_compensation.hpp"

namespace nelf {
namespace {

PixelDefect dead(int x, int y) { return {Eye::left, x, y, DefectKind::dead, {0, 0, 0}}; }
PixelDefect stuck(int x, int y, std::array<std::uint8_t, 3> rgb) { return {Eye::left, x, y, DefectKind::stuck, rgb}; }

EyeDefectPlan plan_of(std::vector<DefectCorrection> corrections, std::array<int, 2> panel = {8, 6}) {
  EyeDefectPlan plan;
  plan.panel = panel;
  plan.corrections = std::move(corrections);
  return plan;
}

Image grey(float value, int width = 8, int height = 6) {
  Image image(width, height);
  for (auto& p : image.pixels()) p = {value, value, value, 1.f};
  return image;
}

TEST(DefectCompensationApply, AddsEachShareOfADeadPixelsShortfall) {
  const EyeDefectPlan plan = plan_of({{dead(3, 2), {{1, 2, 0.25f}, {5, 2, 0.5f}}}});
  Image image = grey(0.4f);
  image.at(3, 2) = {0.8f, 0.4f, 0.2f, 1.f};
  compensate_defects(plan, image);
  EXPECT_FLOAT_EQ(image.at(1, 2).r, 0.4f + 0.25f * 0.8f);
  EXPECT_FLOAT_EQ(image.at(1, 2).g, 0.4f + 0.25f * 0.4f);
  EXPECT_FLOAT_EQ(image.at(1, 2).b, 0.4f + 0.25f * 0.2f);
  EXPECT_FLOAT_EQ(image.at(5, 2).r, 0.4f + 0.5f * 0.8f);
  EXPECT_FLOAT_EQ(image.at(3, 2).r, 0.8f);  // the defect itself shows what it shows
  EXPECT_FLOAT_EQ(image.at(1, 2).a, 1.f);
  EXPECT_FLOAT_EQ(image.at(0, 0).r, 0.4f);  // nothing else changes
  EXPECT_FLOAT_EQ(image.at(4, 2).r, 0.4f);
}

TEST(DefectCompensationApply, TakesAStuckPixelsExcessAwayClippedAtBlack) {
  const EyeDefectPlan plan = plan_of({{stuck(3, 2, {255, 255, 0}), {{2, 2, 0.5f}, {4, 2, 0.5f}}}});
  Image image = grey(0.4f);
  compensate_defects(plan, image);
  EXPECT_FLOAT_EQ(image.at(2, 2).r, 0.1f);         // 0.4 − 0.5 × 0.6
  EXPECT_FLOAT_EQ(image.at(2, 2).b, 0.4f + 0.2f);  // stuck at 0 in blue: a shortfall there
  Image dark = grey(0.1f);
  compensate_defects(plan, dark);
  EXPECT_FLOAT_EQ(dark.at(4, 2).r, 0.f);  // 0.1 − 0.45, clipped
}

TEST(DefectCompensationApply, ClipsAtWhite) {
  const EyeDefectPlan plan = plan_of({{dead(3, 2), {{2, 2, 1.f}}}});
  Image image = grey(0.9f);
  compensate_defects(plan, image);
  EXPECT_FLOAT_EQ(image.at(2, 2).r, 1.f);
}

TEST(DefectCompensationApply, SharesMeetingOnAPixelAddUpAndClipOnce) {
  // Pixel (4, 2) takes a share of a dead pixel's shortfall and of a white stuck pixel's excess:
  // 0.9 + 0.5 × 0.9 − 0.5 × 0.1 = 1.3 → 1 when clipped once at the end, whatever the order (added
  // one at a time and clipped in between it would be 0.95 in one order, 1 in the other).
  for (bool dead_first : {true, false}) {
    DefectCorrection a{dead(3, 2), {{4, 2, 0.5f}}};
    DefectCorrection b{stuck(5, 2, {255, 255, 255}), {{4, 2, 0.5f}}};
    Image image = grey(0.9f);
    const EyeDefectPlan plan = dead_first ? plan_of({a, b}) : plan_of({b, a});
    compensate_defects(plan, image);
    EXPECT_FLOAT_EQ(image.at(4, 2).r, 1.f) << dead_first;
  }
  // Within range both shares count.
  const EyeDefectPlan plan = plan_of({{dead(3, 2), {{4, 2, 0.25f}}}, {dead(5, 2), {{4, 2, 0.25f}}}});
  Image image = grey(0.4f);
  compensate_defects(plan, image);
  EXPECT_FLOAT_EQ(image.at(4, 2).r, 0.4f + 0.25f * 0.4f * 2.f);
}

TEST(DefectCompensationApply, WorksFromTheImageAsGivenNotThePartlyCorrectedOne) {
  // The second defect's pixel takes a share of the first (a plan would not do that, but its value
  // must be read as it was given): its own shortfall is 0.4, not 0.4 + 0.5 × 0.4.
  const EyeDefectPlan plan = plan_of({{dead(1, 1), {{2, 1, 0.5f}}}, {dead(2, 1), {{3, 1, 1.f}}}});
  Image image = grey(0.4f);
  compensate_defects(plan, image);
  EXPECT_FLOAT_EQ(image.at(3, 1).r, 0.8f);
  EXPECT_FLOAT_EQ(image.at(2, 1).r, 0.6f);
}

TEST(DefectCompensationApply, AnEmptyPlanOrACorrectionWithoutSharesChangesNothing) {
  Image image = grey(0.4f);
  image.at(2, 2).r = 0.7f;
  const Image before = image;
  compensate_defects(EyeDefectPlan{}, image);
  compensate_defects(plan_of({{dead(2, 2), {}}}), image);
  EXPECT_EQ(std::memcmp(image.data(), before.data(), image.pixels().size() * sizeof(Rgba)), 0);
}

TEST(DefectCompensationApply, RefusesAPlanForAnotherPanel) {
  Image image = grey(0.4f, 9, 6);
  EXPECT_THROW(compensate_defects(plan_of({{dead(1, 1), {{2, 1, 0.5f}}}}), image), std::invalid_argument);
}

// An eye area inside a larger packed frame: the eye's (0, 0) at (2, 1), rows `stride` pixels apart.
template <class Channel>
struct Bytes {
  static constexpr int width = 12, height = 8, ox = 2, oy = 1;
  std::vector<Channel> channels = std::vector<Channel>(width * height * 4);
  Channel* at(int x, int y) { return &channels[((y + oy) * width + x + ox) * 4]; }
  void fill(Channel v) {
    for (std::size_t i = 0; i < channels.size(); ++i)
      channels[i] = i % 4 == 3 ? std::numeric_limits<Channel>::max() : v;
  }
  void compensate(const EyeDefectPlan& plan) {
    compensate_defects(plan, reinterpret_cast<std::uint8_t*>(at(0, 0)), sizeof(Channel) * 8,
                       width * 4 * sizeof(Channel));
  }
};

TEST(DefectCompensationApply, EightBitBytesRoundAndClipTo0And255) {
  Bytes<std::uint8_t> frame;
  frame.fill(100);
  frame.at(3, 2)[0] = 200;
  frame.at(3, 2)[1] = 100;
  frame.at(3, 2)[2] = 0;
  const EyeDefectPlan plan =
      plan_of({{dead(3, 2), {{1, 2, 0.25f}, {5, 2, 1.f}}}, {stuck(6, 4, {255, 255, 255}), {{7, 4, 1.f}}}});
  frame.compensate(plan);
  EXPECT_EQ(frame.at(1, 2)[0], 150);  // 100 + 50
  EXPECT_EQ(frame.at(1, 2)[1], 125);
  EXPECT_EQ(frame.at(1, 2)[2], 100);
  EXPECT_EQ(frame.at(1, 2)[3], 255);  // alpha as it was
  EXPECT_EQ(frame.at(5, 2)[0], 255);  // 100 + 200, clipped
  EXPECT_EQ(frame.at(5, 2)[1], 200);
  EXPECT_EQ(frame.at(7, 4)[0], 0);  // 100 − 155, clipped
  EXPECT_EQ(frame.at(3, 2)[0], 200);
  // Nothing outside the shares, the eye area's own row stride respected.
  EXPECT_EQ(frame.channels[0], 100);
  EXPECT_EQ(frame.at(2, 2)[0], 100);
  EXPECT_EQ(frame.at(1, 1)[0], 100);
  EXPECT_EQ(frame.at(1, 3)[0], 100);
}

TEST(DefectCompensationApply, SixteenBitBytesClipTo65535) {
  Bytes<std::uint16_t> frame;
  frame.fill(30000);
  const EyeDefectPlan plan =
      plan_of({{dead(3, 2), {{1, 2, 0.5f}, {5, 2, 2.f}}}, {stuck(6, 4, {255, 255, 255}), {{7, 4, 0.5f}}}});
  frame.compensate(plan);
  EXPECT_EQ(frame.at(1, 2)[0], 45000);
  EXPECT_EQ(frame.at(5, 2)[0], 65535);
  EXPECT_NEAR(frame.at(7, 4)[0], 30000 - (65535 - 30000) / 2, 1);
  EXPECT_EQ(frame.at(7, 4)[3], 65535);
  EXPECT_EQ(frame.at(4, 2)[0], 30000);
}

TEST(DefectCompensationApply, BytesAndFloatsAgree) {
  const EyeDefectPlan plan = plan_of({{dead(3, 2), {{1, 2, 0.3f}, {5, 2, 0.3f}, {3, 0, 0.2f}, {3, 4, 0.2f}}},
                                      {stuck(5, 3, {255, 0, 128}), {{5, 2, 0.4f}, {5, 4, 0.6f}}}});
  Bytes<std::uint8_t> frame;
  frame.fill(90);
  Image image = grey(90 / 255.f);
  frame.compensate(plan);
  compensate_defects(plan, image);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 8; ++x) {
      EXPECT_NEAR(frame.at(x, y)[0], image.at(x, y).r * 255.f, 0.5f) << x << "," << y;
      EXPECT_NEAR(frame.at(x, y)[2], image.at(x, y).b * 255.f, 0.5f) << x << "," << y;
    }
}

TEST(DefectCompensationApply, RefusesOtherDepths) {
  std::vector<std::uint8_t> bytes(8 * 6 * 4);
  EXPECT_THROW(compensate_defects(plan_of({{dead(1, 1), {{2, 1, 0.5f}}}}), bytes.data(), 10, 8 * 4),
               std::invalid_argument);
}

TEST(DefectCompensationApply, ShowDefectsPaintsWhatTheEyesDefectsShow) {
  DefectMap map;
  map.defects = {dead(1, 1), stuck(2, 1, {255, 0, 51}), {Eye::right, 3, 3, DefectKind::dead, {}}};
  Image image = grey(0.5f);
  show_defects(map, Eye::left, image);
  EXPECT_FLOAT_EQ(image.at(1, 1).r, 0.f);
  EXPECT_FLOAT_EQ(image.at(1, 1).a, 1.f);
  EXPECT_FLOAT_EQ(image.at(2, 1).r, 1.f);
  EXPECT_FLOAT_EQ(image.at(2, 1).g, 0.f);
  EXPECT_FLOAT_EQ(image.at(2, 1).b, 0.2f);
  EXPECT_FLOAT_EQ(image.at(3, 3).r, 0.5f);  // the right eye's
  show_defects(map, Eye::right, image);
  EXPECT_FLOAT_EQ(image.at(3, 3).r, 0.f);
}

}  // namespace
}  // namespace nelf
