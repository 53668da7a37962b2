#include <gtest/gtest.h>

#include "hmz_output/packing.hpp"
#include "hmz_output/signal.hpp"

namespace nelf {
namespace {
// This file's own names: its suite is compiled as one unit (tests/CMakeLists.txt).
namespace test_packing {

Image filled(int w, int h, Rgba colour) {
  Image image(w, h);
  for (Rgba& px : image.pixels()) px = colour;
  return image;
}

constexpr Rgba kLeft{0.9f, 0.1f, 0.2f, 1.f};
constexpr Rgba kRight{0.1f, 0.2f, 0.8f, 1.f};
constexpr Rgba kBlack{0.f, 0.f, 0.f, 1.f};

bool same(const Rgba& a, const Rgba& b) { return a.r == b.r && a.g == b.g && a.b == b.b && a.a == b.a; }

// Counts pixels in rows [y0, y1) that are not `colour`.
int count_not(const Image& image, int y0, int y1, Rgba colour) {
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < image.width(); ++x) n += !same(image.at(x, y), colour);
  return n;
}

Signal signal(const char* name) {
  auto s = find_signal(name);
  if (!s) throw std::runtime_error(std::string("no signal ") + name);
  return *s;
}

TEST(Signal, TableMatchesTheHdmiFormats) {
  EXPECT_EQ(signal_names().size(), 7u);
  EXPECT_FALSE(find_signal("hdmi-fp-1080p60"));
  const Signal s60 = signal("hdmi-fp-720p60");
  ASSERT_TRUE(s60.timing);
  EXPECT_EQ(s60.timing->h_total, 1650);
  EXPECT_EQ(s60.timing->v_total, 1500);
  EXPECT_EQ(s60.timing->v_active, 1470);
  EXPECT_NEAR(s60.timing->refresh_hz(), 60.0, 1e-9);
  const Signal s50 = signal("hdmi-fp-720p50");
  EXPECT_EQ(s50.timing->h_total, 1980);
  EXPECT_NEAR(s50.timing->refresh_hz(), 50.0, 1e-9);
  const Signal s24 = signal("hdmi-fp-1080p24");
  EXPECT_EQ(s24.timing->h_total, 2750);
  EXPECT_EQ(s24.timing->v_total, 2250);
  EXPECT_EQ(s24.timing->v_active, 2205);
  EXPECT_NEAR(s24.timing->refresh_hz(), 24.0, 1e-9);
  for (const Signal& s : {s60, s50, s24}) {
    EXPECT_EQ(s.timing->h_active, s.eye_width);
    EXPECT_EQ(s.timing->v_active, s.packed_height(0));
    EXPECT_LT(s.timing->h_active, s.timing->h_sync_start);
    EXPECT_LT(s.timing->h_sync_start, s.timing->h_sync_end);
    EXPECT_LT(s.timing->h_sync_end, s.timing->h_total);
    EXPECT_LT(s.timing->v_active, s.timing->v_sync_start);
    EXPECT_LT(s.timing->v_sync_end, s.timing->v_total);
    EXPECT_DOUBLE_EQ(s.timing->pixel_clock_mhz, 148.5);
  }
  EXPECT_FALSE(signal("sbs").timing);
}

struct FramePackedCase {
  const char* name;
  int w, eye_h, gap;
};

TEST(Packing, FramePackedGeometryAndBlackGap) {
  for (const auto& c :
       {FramePackedCase{"hdmi-fp-720p60", 1280, 720, 30}, FramePackedCase{"hdmi-fp-720p50", 1280, 720, 30},
        FramePackedCase{"hdmi-fp-1080p24", 1920, 1080, 45}}) {
    SCOPED_TRACE(c.name);
    const Image frame = pack_eyes(signal(c.name), filled(c.w, c.eye_h, kLeft), filled(c.w, c.eye_h, kRight));
    ASSERT_EQ(frame.width(), c.w);
    ASSERT_EQ(frame.height(), 2 * c.eye_h + c.gap);
    EXPECT_EQ(count_not(frame, 0, c.eye_h, kLeft), 0);
    EXPECT_EQ(count_not(frame, c.eye_h, c.eye_h + c.gap, kBlack), 0);
    EXPECT_EQ(count_not(frame, c.eye_h + c.gap, frame.height(), kRight), 0);
  }
}

TEST(Packing, FramePackedKeepsPixelPositions) {
  Image left(1280, 720), right(1280, 720);
  left.at(0, 0) = {1, 1, 1, 1};
  left.at(1279, 719) = {0.5f, 0.5f, 0.5f, 1};
  right.at(0, 0) = {0.25f, 0.25f, 0.25f, 1};
  right.at(1279, 719) = {0.75f, 0.75f, 0.75f, 1};
  const Image frame = pack_eyes(signal("hdmi-fp-720p60"), left, right);
  EXPECT_EQ(frame.at(0, 0).r, 1.f);
  EXPECT_EQ(frame.at(1279, 719).r, 0.5f);
  EXPECT_EQ(frame.at(0, 750).r, 0.25f);
  EXPECT_EQ(frame.at(1279, 1469).r, 0.75f);
  EXPECT_EQ(frame.at(0, 749).r, 0.f);
}

TEST(Packing, SmallerEyesAreCentredOneToOne) {
  // A 1280x720 panel on the 1080p24 signal: 320 columns and 180 rows of black border each side.
  const Image frame = pack_eyes(signal("hdmi-fp-1080p24"), filled(1280, 720, kLeft), filled(1280, 720, kRight));
  ASSERT_EQ(frame.width(), 1920);
  ASSERT_EQ(frame.height(), 2205);
  EXPECT_TRUE(same(frame.at(320, 180), kLeft));
  EXPECT_TRUE(same(frame.at(1599, 899), kLeft));
  EXPECT_TRUE(same(frame.at(319, 180), kBlack));
  EXPECT_TRUE(same(frame.at(1600, 899), kBlack));
  EXPECT_TRUE(same(frame.at(320, 179), kBlack));
  EXPECT_TRUE(same(frame.at(320, 900), kBlack));
  EXPECT_TRUE(same(frame.at(320, 1125 + 180), kRight));
  EXPECT_TRUE(same(frame.at(320, 1125 + 179), kBlack));
  EXPECT_TRUE(same(frame.at(1599, 1125 + 899), kRight));
  EXPECT_EQ(count_not(frame, 1080, 1125, kBlack), 0);
}

TEST(Packing, LargerEyesAreCroppedEvenly) {
  Image left = filled(1920, 1080, kLeft);
  left.at(320, 180) = {1, 1, 1, 1};  // lands on the top-left pixel of the 1280x720 eye area
  const Image frame = pack_eyes(signal("hdmi-fp-720p60"), left, filled(1920, 1080, kRight));
  ASSERT_EQ(frame.height(), 1470);
  EXPECT_EQ(frame.at(0, 0).r, 1.f);
  EXPECT_EQ(count_not(frame, 720, 750, kBlack), 0);
  EXPECT_EQ(count_not(frame, 750, 1470, kRight), 0);
}

TEST(PackedLayout, IsWhereEveryOutputPutsTheEyes) {
  // The same 1280x720 panel on 1080p24 as above: the areas are the signal's, the origins centred.
  const PackedLayout fp = packed_layout(signal("hdmi-fp-1080p24"), {1280, 720});
  EXPECT_EQ(fp.packed, (std::array<int, 2>{1920, 2205}));
  EXPECT_EQ(fp.eye, (std::array<int, 2>{1280, 720}));
  ASSERT_TRUE(fp.areas[0] && fp.areas[1]);
  EXPECT_EQ(fp.areas[1]->y, 1125);
  EXPECT_EQ(fp.areas[1]->width, 1920);
  EXPECT_EQ(fp.origins[0], (std::pair{320, 180}));
  EXPECT_EQ(fp.origins[1], (std::pair{320, 1125 + 180}));
  // Larger eyes: negative offsets, cropped evenly (pack_eyes above puts (320, 180) at (0, 0)).
  EXPECT_EQ(packed_layout(signal("hdmi-fp-720p60"), {1920, 1080}).origins[0], (std::pair{-320, -180}));
  const PackedLayout sbs = packed_layout(signal("sbs"), {640, 360});
  EXPECT_EQ(sbs.packed, (std::array<int, 2>{1280, 360}));
  EXPECT_EQ(sbs.origins[1], (std::pair{640, 0}));
  const PackedLayout right = packed_layout(signal("right"), {640, 360});
  EXPECT_FALSE(right.areas[0]);
  EXPECT_FALSE(right.origins[0]);
  EXPECT_EQ(right.origins[1], (std::pair{0, 0}));
}

TEST(Packing, PlainOutputs) {
  const Image left = filled(64, 36, kLeft), right = filled(64, 36, kRight);
  const Image sbs = pack_eyes(signal("sbs"), left, right);
  ASSERT_EQ(sbs.width(), 128);
  ASSERT_EQ(sbs.height(), 36);
  EXPECT_TRUE(same(sbs.at(63, 0), kLeft));
  EXPECT_TRUE(same(sbs.at(64, 0), kRight));
  EXPECT_TRUE(same(sbs.at(127, 35), kRight));

  const Image tab = pack_eyes(signal("tab"), left, right);
  ASSERT_EQ(tab.width(), 64);
  ASSERT_EQ(tab.height(), 72);
  EXPECT_EQ(count_not(tab, 0, 36, kLeft), 0);
  EXPECT_EQ(count_not(tab, 36, 72, kRight), 0);

  const Image only_left = pack_eyes(signal("left"), left, right);
  ASSERT_EQ(only_left.width(), 64);
  ASSERT_EQ(only_left.height(), 36);
  EXPECT_EQ(count_not(only_left, 0, 36, kLeft), 0);
  const Image only_right = pack_eyes(signal("right"), left, right);
  EXPECT_EQ(count_not(only_right, 0, 36, kRight), 0);
}

TEST(Packing, RejectsMismatchedEyes) {
  EXPECT_THROW(pack_eyes(signal("sbs"), filled(64, 36, kLeft), filled(64, 35, kRight)), std::invalid_argument);
  EXPECT_THROW(pack_eyes(signal("hdmi-fp-720p60"), Image(), Image()), std::invalid_argument);
  EyeImages eyes{filled(8, 4, kLeft), filled(8, 4, kRight)};
  EXPECT_TRUE(same(pack_eyes(signal("sbs"), eyes).at(8, 0), kRight));
}

}  // namespace test_packing
}  // namespace
}  // namespace nelf
