// The layout detection chain (DESIGN.md §6) as a pure function of the evidence.
#include <gtest/gtest.h>

#include "inputs/layout_chain.hpp"
#include "inputs/layout_detection_hooks.hpp"

namespace nelf {
namespace {

LayoutEvidence plain(int width, int height, std::string path = "movie.mkv") {
  LayoutEvidence e;
  e.width = width;
  e.height = height;
  e.display_aspect = static_cast<double>(width) / height;
  e.path = std::move(path);
  return e;
}

TEST(LayoutChain, FlagWinsOverEverything) {
  LayoutEvidence e = plain(1280, 1470, "film.hsbs.mkv");
  e.metadata = StereoMetadata{StereoPacking::top_bottom, true};
  e.flag_layout = "sbs";
  const LayoutDecision d = decide_layout(e);
  EXPECT_EQ(d.layout, "sbs");
  EXPECT_EQ(d.rule, LayoutRule::flag);
  EXPECT_FALSE(d.swap_eyes) << "with an explicit layout only --swap-eyes swaps";
}

TEST(LayoutChain, MetadataWinsOverFrameSizeAndName) {
  LayoutEvidence e = plain(1920, 2205, "film.hsbs.mkv");
  e.metadata = StereoMetadata{StereoPacking::top_bottom, true};
  const LayoutDecision d = decide_layout(e);
  EXPECT_EQ(d.layout, "tab");  // 1920x2205 is taller than wide: full top-bottom
  EXPECT_TRUE(d.swap_eyes);
  EXPECT_EQ(d.rule, LayoutRule::metadata);
  e.flag_swap_eyes = true;  // --swap-eyes swaps what was detected
  EXPECT_FALSE(decide_layout(e).swap_eyes);
}

TEST(LayoutChain, HdmiFramePackedSizesAreFramePacked) {
  for (auto [w, h] : {std::pair{1280, 1470}, std::pair{1920, 2205}}) {
    const LayoutDecision d = decide_layout(plain(w, h, "film.sbs.mkv"));
    EXPECT_EQ(d.layout, "fp");
    EXPECT_EQ(d.rule, LayoutRule::frame_size);
  }
  EXPECT_NE(decide_layout(plain(1280, 1472)).rule, LayoutRule::frame_size);
}

TEST(LayoutChain, FilenameThenAspectThenMono) {
  const LayoutDecision by_name = decide_layout(plain(1920, 1080, "/films/Some.Movie.2011.H-SBS.1080p.mkv"));
  EXPECT_EQ(by_name.layout, "sbs-half");
  EXPECT_EQ(by_name.rule, LayoutRule::filename);

  const LayoutDecision by_aspect = decide_layout(plain(3840, 1080));
  EXPECT_EQ(by_aspect.layout, "sbs");
  EXPECT_EQ(by_aspect.rule, LayoutRule::aspect);

  const LayoutDecision fallback = decide_layout(plain(1920, 1080));
  EXPECT_EQ(fallback.layout, "mono");
  EXPECT_EQ(fallback.rule, LayoutRule::fallback);
  EXPECT_EQ(to_string(fallback.rule), "default");
  EXPECT_FALSE(fallback.warning.empty());
}

TEST(LayoutChain, UnsupportedMetadataIsAnErrorUnlessOverridden) {
  LayoutEvidence e = plain(1920, 1080);
  e.metadata = StereoMetadata{StereoPacking::checkerboard, false};
  EXPECT_THROW(decide_layout(e), UnsupportedStereoMetadata);
  e.flag_layout = "sbs-half";
  EXPECT_EQ(decide_layout(e).layout, "sbs-half");
}

TEST(LayoutHints, FilenameTokens) {
  const double hd = 16.0 / 9.0;
  EXPECT_EQ(layout_hint_from_filename("a.HSBS.mkv", hd)->layout, "sbs-half");
  EXPECT_EQ(layout_hint_from_filename("a.half-ou.mkv", hd)->layout, "tab-half");
  EXPECT_EQ(layout_hint_from_filename("a_h-tab.mkv", hd)->layout, "tab-half");
  EXPECT_EQ(layout_hint_from_filename("a.full-sbs.mkv", hd)->layout, "sbs");
  EXPECT_EQ(layout_hint_from_filename("a.FOU.mkv", hd)->layout, "tab");
  EXPECT_EQ(layout_hint_from_filename("a 3D.mkv", hd)->layout, "sbs-half");
  const auto rl = layout_hint_from_filename("holiday.rl.mp4", 2 * hd);
  ASSERT_TRUE(rl.has_value());
  EXPECT_EQ(rl->layout, "sbs");
  EXPECT_TRUE(rl->swap_eyes);
  EXPECT_FALSE(layout_hint_from_filename("/sbs/plain-movie.mkv", hd).has_value()) << "only the file's own name";
  EXPECT_FALSE(layout_hint_from_filename("subsonic.mkv", hd).has_value()) << "tokens, not substrings";
}

}  // namespace
}  // namespace nelf
