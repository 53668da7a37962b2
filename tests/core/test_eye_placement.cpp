// place_eyes and require_eyes_fit (core/packed_layout.hpp): the packed layout as the one placement
// policy, the same frame as hmz_output's pack_eyes for every signal and eye size, smaller or larger
// than the area a signal reserves.
#include <gtest/gtest.h>

#include <string>

#include "core/packed_layout.hpp"
#include "core/user_error.hpp"
#include "hmz_output/packing.hpp"
#include "hmz_output/signal.hpp"

namespace nelf {
namespace {

// Every pixel different, so that a misplaced or mirrored copy shows.
Image ramp(int w, int h, float tint) {
  Image image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) image.at(x, y) = Rgba{x / float(w), y / float(h), tint, 1.f};
  return image;
}

bool same(const Image& a, const Image& b) {
  if (a.width() != b.width() || a.height() != b.height()) return false;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      const Rgba &p = a.at(x, y), &q = b.at(x, y);
      if (p.r != q.r || p.g != q.g || p.b != q.b || p.a != q.a) return false;
    }
  return true;
}

TEST(EyePlacement, PlaceEyesIsPackEyesForEverySignalAndEyeSize) {
  for (const auto& name : signal_names()) {
    const Signal signal = *find_signal(name);
    for (const std::array<int, 2> eye :
         {std::array<int, 2>{320, 180}, std::array<int, 2>{1280, 720}, std::array<int, 2>{1301, 733}}) {
      SCOPED_TRACE(std::string(name) + " " + std::to_string(eye[0]) + "x" + std::to_string(eye[1]));
      const EyeImages eyes{ramp(eye[0], eye[1], 0.25f), ramp(eye[0], eye[1], 0.75f)};
      EXPECT_TRUE(same(place_eyes(packed_layout(signal, eye), eyes), pack_eyes(signal, eyes)));
    }
  }
}

TEST(EyePlacement, PlaceEyesRefusesEyesOfAnotherSize) {
  const PackedLayout layout = packed_layout(*find_signal("sbs"), {64, 32});
  EXPECT_THROW(place_eyes(layout, {ramp(64, 32, 0.f), ramp(63, 32, 0.f)}), std::invalid_argument);
}

TEST(EyePlacement, RequireEyesFitNamesPanelProfileAreaAndSignal) {
  const Signal hdmi = *find_signal("hdmi-fp-720p60");
  EXPECT_NO_THROW(require_eyes_fit(packed_layout(hdmi, {1280, 720}), "hmz-t1", hdmi.name));
  EXPECT_NO_THROW(require_eyes_fit(packed_layout(*find_signal("sbs"), {4000, 3000}), "big", "sbs"));
  try {
    require_eyes_fit(packed_layout(hdmi, {1920, 1080}), "big", hdmi.name, "; use --signal sbs");
    FAIL() << "no error";
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(),
                 "the 1920x1080 panel of profile big does not fit the 1280x720 eye area of signal hdmi-fp-720p60; use "
                 "--signal sbs");
    EXPECT_EQ(e.status(), 2);
  }
}

}  // namespace
}  // namespace nelf
