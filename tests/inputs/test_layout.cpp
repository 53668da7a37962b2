#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "inputs/stereo_layout.hpp"

namespace nelf {
namespace {

// Every pixel encodes its own position, so a view can be checked pixel by pixel against the place
// in the frame it must come from.
Image coordinate_frame(int w, int h) {
  Image frame(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) frame.at(x, y) = {static_cast<float>(x) / w, static_cast<float>(y) / h, 0.5f, 1.f};
  return frame;
}

// True when `view` is the w x h block of `frame` at (x0, y0).
::testing::AssertionResult is_block_of(const Image& view, const Image& frame, int x0, int y0, int w, int h) {
  if (view.width() != w || view.height() != h)
    return ::testing::AssertionFailure() << "view is " << view.width() << "x" << view.height() << ", expected " << w
                                         << "x" << h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Rgba &a = view.at(x, y), &b = frame.at(x0 + x, y0 + y);
      if (a.r != b.r || a.g != b.g || a.b != b.b || a.a != b.a)
        return ::testing::AssertionFailure()
               << "pixel (" << x << "," << y << ") is not frame pixel (" << x0 + x << "," << y0 + y << ")";
    }
  return ::testing::AssertionSuccess();
}

TEST(StereoLayout, NamesRoundTrip) {
  for (auto name : stereo_layout_names()) {
    const auto layout = parse_stereo_layout(name);
    ASSERT_TRUE(layout) << name;
    EXPECT_EQ(to_string(*layout), name);
  }
  EXPECT_EQ(stereo_layout_names().size(), 8u);
  EXPECT_EQ(parse_stereo_layout("sbs-half"), StereoLayout::sbs_half);
  EXPECT_FALSE(parse_stereo_layout("SBS"));
  EXPECT_FALSE(parse_stereo_layout("side-by-side"));
  EXPECT_FALSE(parse_stereo_layout(""));
}

TEST(StereoLayout, FullSideBySideKeepsEachViewsAspect) {
  // 3840x1080 scaled by 1/10 (the full size costs seconds under the sanitizers).
  const Image frame = coordinate_frame(384, 108);
  const StereoPair pair = split_frame(frame, StereoLayout::sbs);
  EXPECT_TRUE(is_block_of(pair.left.image, frame, 0, 0, 192, 108));
  EXPECT_TRUE(is_block_of(pair.right.image, frame, 192, 0, 192, 108));
  EXPECT_NEAR(pair.left.aspect(), 16.0 / 9.0, 1e-12);
  EXPECT_NEAR(pair.right.aspect(), 16.0 / 9.0, 1e-12);
}

TEST(StereoLayout, HalfSideBySideIsAnamorphic) {
  const Image frame = coordinate_frame(192, 108);  // 1920x1080 / 10
  const StereoPair pair = split_frame(frame, StereoLayout::sbs_half);
  EXPECT_TRUE(is_block_of(pair.left.image, frame, 0, 0, 96, 108));
  EXPECT_TRUE(is_block_of(pair.right.image, frame, 96, 0, 96, 108));
  EXPECT_NEAR(pair.left.aspect(), 16.0 / 9.0, 1e-12);
  EXPECT_NEAR(pair.right.aspect(), 16.0 / 9.0, 1e-12);
}

TEST(StereoLayout, FullTopBottom) {
  const Image frame = coordinate_frame(64, 72);
  const StereoPair pair = split_frame(frame, StereoLayout::tab);
  EXPECT_TRUE(is_block_of(pair.left.image, frame, 0, 0, 64, 36));
  EXPECT_TRUE(is_block_of(pair.right.image, frame, 0, 36, 64, 36));
  EXPECT_NEAR(pair.left.aspect(), 64.0 / 36.0, 1e-12);
}

TEST(StereoLayout, HalfTopBottomIsAnamorphic) {
  const Image frame = coordinate_frame(192, 108);
  const StereoPair pair = split_frame(frame, StereoLayout::tab_half);
  EXPECT_TRUE(is_block_of(pair.left.image, frame, 0, 0, 192, 54));
  EXPECT_TRUE(is_block_of(pair.right.image, frame, 0, 54, 192, 54));
  EXPECT_NEAR(pair.left.aspect(), 16.0 / 9.0, 1e-12);
  EXPECT_NEAR(pair.right.aspect(), 16.0 / 9.0, 1e-12);
}

TEST(StereoLayout, FramePacked720pSkipsTheGap) {
  const Image frame = coordinate_frame(1280, 1470);
  const StereoPair pair = split_frame(frame, StereoLayout::fp);
  EXPECT_TRUE(is_block_of(pair.left.image, frame, 0, 0, 1280, 720));
  EXPECT_TRUE(is_block_of(pair.right.image, frame, 0, 750, 1280, 720));
  EXPECT_NEAR(pair.left.aspect(), 16.0 / 9.0, 1e-12);
}

TEST(StereoLayout, FramePacked1080pSkipsTheGap) {
  const Image frame = coordinate_frame(1920, 2205);
  const StereoPair pair = split_frame(frame, StereoLayout::fp);
  EXPECT_TRUE(is_block_of(pair.left.image, frame, 0, 0, 1920, 1080));
  EXPECT_TRUE(is_block_of(pair.right.image, frame, 0, 1125, 1920, 1080));
  EXPECT_NEAR(pair.right.aspect(), 16.0 / 9.0, 1e-12);
}

TEST(StereoLayout, MonoGivesTheFrameToBothEyes) {
  const Image frame = coordinate_frame(40, 30);
  const StereoPair pair = split_frame(frame, StereoLayout::mono);
  EXPECT_TRUE(is_block_of(pair.left.image, frame, 0, 0, 40, 30));
  EXPECT_TRUE(is_block_of(pair.right.image, frame, 0, 0, 40, 30));
  EXPECT_NEAR(pair.left.aspect(), 4.0 / 3.0, 1e-12);
}

TEST(StereoLayout, SwapExchangesTheViews) {
  const Image frame = coordinate_frame(200, 50);
  for (StereoLayout layout : {StereoLayout::sbs, StereoLayout::sbs_half}) {
    const StereoPair pair = split_frame(frame, layout, true);
    EXPECT_TRUE(is_block_of(pair.left.image, frame, 100, 0, 100, 50));
    EXPECT_TRUE(is_block_of(pair.right.image, frame, 0, 0, 100, 50));
  }
  const Image tall = coordinate_frame(50, 200);
  const StereoPair pair = split_frame(tall, StereoLayout::tab, true);
  EXPECT_TRUE(is_block_of(pair.left.image, tall, 0, 100, 50, 100));
  EXPECT_TRUE(is_block_of(pair.right.image, tall, 0, 0, 50, 100));
  const Image packed = coordinate_frame(1280, 1470);
  const StereoPair fp = split_frame(packed, StereoLayout::fp, true);
  EXPECT_TRUE(is_block_of(fp.left.image, packed, 0, 750, 1280, 720));
}

std::string split_error(int w, int h, StereoLayout layout) {
  try {
    split_frame(Image(w, h), layout);
  } catch (const LayoutError& e) {
    return e.what();
  }
  return "";
}

TEST(StereoLayout, LayoutsThatDoNotFitAreClearErrors) {
  EXPECT_EQ(split_error(1921, 1080, StereoLayout::sbs),
            "layout sbs does not fit a 1921x1080 frame: side-by-side needs an even width");
  EXPECT_NE(split_error(1921, 1080, StereoLayout::sbs_half).find("even width"), std::string::npos);
  EXPECT_NE(split_error(1920, 1081, StereoLayout::tab).find("even height"), std::string::npos);
  EXPECT_NE(split_error(1920, 1081, StereoLayout::tab_half).find("even height"), std::string::npos);
  EXPECT_NE(split_error(1280, 1440, StereoLayout::fp).find("1280x1470"), std::string::npos);
  EXPECT_NE(split_error(1920, 2160, StereoLayout::fp).find("does not fit a 1920x2160"), std::string::npos);
  EXPECT_NE(split_error(1280, 720, StereoLayout::alt).find("needs a video"), std::string::npos);
  EXPECT_NE(split_error(1280, 720, StereoLayout::pair).find("--right"), std::string::npos);
  EXPECT_NE(split_error(0, 0, StereoLayout::mono).find("empty"), std::string::npos);
  EXPECT_EQ(split_error(1920, 1080, StereoLayout::sbs), "");
}

struct FilenameCase {
  const char* name;
  std::optional<StereoLayout> layout;
  bool swap;
};

TEST(StereoLayout, FilenameTokensOfReleaseNames) {
  using L = StereoLayout;
  const FilenameCase cases[] = {
      {"Avatar.2009.1080p.3D.HSBS.BluRay.x264.mkv", L::sbs_half, false},
      {"Avatar.2009.1080p.3D.Half-SBS.BluRay.mkv", L::sbs_half, false},
      {"movie.h-sbs.mkv", L::sbs_half, false},
      {"Movie (2012) [3D] [H.SBS].mp4", L::sbs_half, false},
      {"movie_half_sbs.mkv", L::sbs_half, false},
      {"Gravity.2013.3D.1080p.BluRay.Full-SBS.mkv", L::sbs, false},
      {"gravity.fsbs.mkv", L::sbs, false},
      {"photo-SBS.png", L::sbs, false},
      {"Hugo.2011.3D.HOU.1080p.mkv", L::tab_half, false},
      {"hugo.h-ou.mkv", L::tab_half, false},
      {"hugo.Half-OU.mkv", L::tab_half, false},
      {"hugo.htab.mkv", L::tab_half, false},
      {"hugo.H-TAB.mkv", L::tab_half, false},
      {"Hugo.2011.3D.OU.mkv", L::tab, false},
      {"hugo.FOU.mkv", L::tab, false},
      {"hugo.ftab.mkv", L::tab, false},
      {"hugo.TAB.mkv", L::tab, false},
      {"DSC0042_LR.jpg", L::sbs, false},
      {"crosseyed-RL.png", L::sbs, true},
      {"Some.Movie.3D.1080p.mkv", L::sbs_half, false},
      {"some movie 3d.mp4", L::sbs_half, false},
      {"Avatar3D.mkv", std::nullopt, false},  // not delimited
      {"tabletop.png", std::nullopt, false},  // "tab" inside a word
      {"holiday.png", std::nullopt, false},
      {"output.mkv", std::nullopt, false},
      {"world.png", std::nullopt, false},
  };
  for (const auto& c : cases) {
    const auto result = layout_from_filename(c.name);
    if (!c.layout) {
      EXPECT_FALSE(result) << c.name << " -> " << to_string(result->layout);
      continue;
    }
    ASSERT_TRUE(result) << c.name;
    EXPECT_EQ(to_string(result->layout), to_string(*c.layout)) << c.name;
    EXPECT_EQ(result->swap_eyes, c.swap) << c.name;
  }
}

TEST(StereoLayout, FilenameLooksOnlyAtTheLastComponent) {
  EXPECT_FALSE(layout_from_filename("/media/3D/SBS/holiday.png"));
  EXPECT_TRUE(layout_from_filename("/media/holiday.sbs.png"));
}

TEST(StereoLayout, DetectionOrder) {
  // An explicit flag beats everything.
  auto d = detect_stereo_layout(
      {StereoLayout::mono, StereoMetadata{StereoPacking::side_by_side, true}, 1280, 1470, "x.hsbs.png"});
  EXPECT_EQ(d.layout, StereoLayout::mono);
  EXPECT_EQ(to_string(d.rule), "flag");
  EXPECT_FALSE(d.swap_eyes);

  // Metadata beats frame size and filename; half or full from the aspect; invert means swap.
  d = detect_stereo_layout({std::nullopt, StereoMetadata{StereoPacking::side_by_side, true}, 1920, 1080, "x.ou.mkv"});
  EXPECT_EQ(d.layout, StereoLayout::sbs_half);
  EXPECT_TRUE(d.swap_eyes);
  EXPECT_EQ(to_string(d.rule), "metadata");
  d = detect_stereo_layout({std::nullopt, StereoMetadata{StereoPacking::side_by_side, false}, 3840, 1080, "x.mkv"});
  EXPECT_EQ(d.layout, StereoLayout::sbs);
  d = detect_stereo_layout({std::nullopt, StereoMetadata{StereoPacking::top_bottom, false}, 1920, 2160, "x.mkv"});
  EXPECT_EQ(d.layout, StereoLayout::tab);
  d = detect_stereo_layout({std::nullopt, StereoMetadata{StereoPacking::top_bottom, false}, 1920, 1080, "x.mkv"});
  EXPECT_EQ(d.layout, StereoLayout::tab_half);
  d = detect_stereo_layout({std::nullopt, StereoMetadata{StereoPacking::frame_sequence, false}, 1920, 1080, "x.mkv"});
  EXPECT_EQ(d.layout, StereoLayout::alt);

  // The HDMI frame-packed sizes beat filename tokens.
  d = detect_stereo_layout({std::nullopt, std::nullopt, 1280, 1470, "x.hsbs.png"});
  EXPECT_EQ(d.layout, StereoLayout::fp);
  EXPECT_EQ(to_string(d.rule), "frame-size");
  d = detect_stereo_layout({std::nullopt, std::nullopt, 1920, 2205, "x.png"});
  EXPECT_EQ(d.layout, StereoLayout::fp);

  // Filename beats aspect.
  d = detect_stereo_layout({std::nullopt, std::nullopt, 3840, 1080, "x.hou.png"});
  EXPECT_EQ(d.layout, StereoLayout::tab_half);
  EXPECT_EQ(to_string(d.rule), "filename");

  // Aspect: >= 3 full SBS, <= 1 full TAB.
  d = detect_stereo_layout({std::nullopt, std::nullopt, 3840, 1080, "x.png"});
  EXPECT_EQ(d.layout, StereoLayout::sbs);
  EXPECT_EQ(to_string(d.rule), "aspect");
  d = detect_stereo_layout({std::nullopt, std::nullopt, 3000, 1000, "x.png"});
  EXPECT_EQ(d.layout, StereoLayout::sbs);
  d = detect_stereo_layout({std::nullopt, std::nullopt, 1920, 2160, "x.png"});
  EXPECT_EQ(d.layout, StereoLayout::tab);
  d = detect_stereo_layout({std::nullopt, std::nullopt, 1000, 1000, "x.png"});
  EXPECT_EQ(d.layout, StereoLayout::tab);

  // Nothing: mono, with a warning naming the file.
  d = detect_stereo_layout({std::nullopt, std::nullopt, 2999, 1000, "holiday.png"});
  EXPECT_EQ(d.layout, StereoLayout::mono);
  EXPECT_EQ(to_string(d.rule), "default");
  EXPECT_NE(d.warning.find("holiday.png"), std::string::npos);
  EXPECT_NE(d.warning.find("--layout"), std::string::npos);
  d = detect_stereo_layout({std::nullopt, std::nullopt, 1001, 1000, "x.png"});
  EXPECT_EQ(d.layout, StereoLayout::mono);
}

TEST(StereoLayout, JpsIsRightLeftSideBySide) {
  auto d = detect_stereo_layout({std::nullopt, std::nullopt, 2048, 768, "photo.JPS"});
  EXPECT_EQ(d.layout, StereoLayout::sbs);
  EXPECT_TRUE(d.swap_eyes);
  EXPECT_EQ(to_string(d.rule), "filename");
  // The convention is a property of the format: an explicit layout keeps it.
  d = detect_stereo_layout({StereoLayout::sbs_half, std::nullopt, 2048, 768, "photo.jps"});
  EXPECT_EQ(d.layout, StereoLayout::sbs_half);
  EXPECT_TRUE(d.swap_eyes);
  EXPECT_FALSE(detect_stereo_layout({std::nullopt, std::nullopt, 2048, 768, "photo.jpg"}).swap_eyes);
}

// Merged from the video side's chain (formerly tests/unit/test_layout_chain.cpp, since moved).
LayoutEvidence plain(int width, int height, std::string path = "movie.mkv") {
  LayoutEvidence e;
  e.width = width;
  e.height = height;
  e.display_aspect = static_cast<double>(width) / height;
  e.filename = std::move(path);
  return e;
}

TEST(LayoutChain, FlagWinsOverEverything) {
  LayoutEvidence e = plain(1280, 1470, "film.hsbs.mkv");
  e.metadata = StereoMetadata{StereoPacking::top_bottom, true};
  e.flag = StereoLayout::sbs;
  const LayoutDecision d = detect_stereo_layout(e);
  EXPECT_EQ(d.layout, StereoLayout::sbs);
  EXPECT_EQ(d.rule, DetectionRule::flag);
  EXPECT_FALSE(d.swap_eyes) << "with an explicit layout only --swap-eyes swaps";
  e.swap_eyes = true;
  EXPECT_TRUE(detect_stereo_layout(e).swap_eyes);
}

TEST(LayoutChain, MetadataWinsOverFrameSizeAndName) {
  LayoutEvidence e = plain(1920, 2205, "film.hsbs.mkv");
  e.metadata = StereoMetadata{StereoPacking::top_bottom, true};
  const LayoutDecision d = detect_stereo_layout(e);
  EXPECT_EQ(d.layout, StereoLayout::tab);  // 1920x2205 is taller than wide: full top-bottom
  EXPECT_TRUE(d.swap_eyes);
  EXPECT_EQ(d.rule, DetectionRule::metadata);
  e.swap_eyes = true;  // --swap-eyes swaps what was detected
  EXPECT_FALSE(detect_stereo_layout(e).swap_eyes);
}

TEST(LayoutChain, MetadataHalfOrFullUsesTheDisplayAspect) {
  // Two 4:3 views side by side (2.67) are full; the aspect rule alone (>= 3) would not say so.
  LayoutEvidence e = plain(1440, 540);
  e.metadata = StereoMetadata{StereoPacking::side_by_side, false};
  EXPECT_EQ(detect_stereo_layout(e).layout, StereoLayout::sbs);
  // Anamorphic pixels: a 1440x1080 frame with 4:3 SAR is displayed at 1.78, so half.
  e = plain(1440, 1080);
  e.display_aspect = 16.0 / 9.0;
  e.metadata = StereoMetadata{StereoPacking::side_by_side, false};
  EXPECT_EQ(detect_stereo_layout(e).layout, StereoLayout::sbs_half);
  // Two 2.39 scope views stacked (1.20) are full top-bottom.
  e = plain(1920, 1606);
  e.metadata = StereoMetadata{StereoPacking::top_bottom, false};
  EXPECT_EQ(detect_stereo_layout(e).layout, StereoLayout::tab);
  e.metadata = StereoMetadata{StereoPacking::mono, false};
  EXPECT_EQ(detect_stereo_layout(e).layout, StereoLayout::mono);
  EXPECT_EQ(detect_stereo_layout(e).rule, DetectionRule::metadata);
}

TEST(LayoutChain, HdmiFramePackedSizesAreFramePacked) {
  for (auto [w, h] : {std::pair{1280, 1470}, std::pair{1920, 2205}}) {
    const LayoutDecision d = detect_stereo_layout(plain(w, h, "film.sbs.mkv"));
    EXPECT_EQ(d.layout, StereoLayout::fp);
    EXPECT_EQ(d.rule, DetectionRule::frame_size);
  }
  EXPECT_NE(detect_stereo_layout(plain(1280, 1472)).rule, DetectionRule::frame_size);
}

TEST(LayoutChain, FilenameThenAspectThenMono) {
  const LayoutDecision by_name = detect_stereo_layout(plain(1920, 1080, "/films/Some.Movie.2011.H-SBS.1080p.mkv"));
  EXPECT_EQ(by_name.layout, StereoLayout::sbs_half);
  EXPECT_EQ(by_name.rule, DetectionRule::filename);

  const LayoutDecision by_aspect = detect_stereo_layout(plain(3840, 1080));
  EXPECT_EQ(by_aspect.layout, StereoLayout::sbs);
  EXPECT_EQ(by_aspect.rule, DetectionRule::aspect);

  const LayoutDecision fallback = detect_stereo_layout(plain(1920, 1080));
  EXPECT_EQ(fallback.layout, StereoLayout::mono);
  EXPECT_EQ(fallback.rule, DetectionRule::fallback);
  EXPECT_EQ(to_string(fallback.rule), "default");
  EXPECT_FALSE(fallback.warning.empty());
}

TEST(LayoutChain, UnsupportedMetadataIsAnErrorUnlessOverridden) {
  LayoutEvidence e = plain(1920, 1080);
  e.metadata = StereoMetadata{StereoPacking::checkerboard, false};
  EXPECT_THROW(detect_stereo_layout(e), UnsupportedStereoMetadata);
  e.flag = StereoLayout::sbs_half;
  EXPECT_EQ(detect_stereo_layout(e).layout, StereoLayout::sbs_half);
}

TEST(LayoutHints, FilenameTokens) {
  const double hd = 16.0 / 9.0;
  EXPECT_EQ(layout_from_filename("a.HSBS.mkv", hd)->layout, StereoLayout::sbs_half);
  EXPECT_EQ(layout_from_filename("a.half-ou.mkv", hd)->layout, StereoLayout::tab_half);
  EXPECT_EQ(layout_from_filename("a_h-tab.mkv", hd)->layout, StereoLayout::tab_half);
  EXPECT_EQ(layout_from_filename("a.full-sbs.mkv", hd)->layout, StereoLayout::sbs);
  EXPECT_EQ(layout_from_filename("a.full-ou.mkv", hd)->layout, StereoLayout::tab);
  EXPECT_EQ(layout_from_filename("a.full-tab.mkv", hd)->layout, StereoLayout::tab);
  EXPECT_EQ(layout_from_filename("a.half-tab.mkv", hd)->layout, StereoLayout::tab_half);
  EXPECT_EQ(layout_from_filename("a.FOU.mkv", hd)->layout, StereoLayout::tab);
  EXPECT_EQ(layout_from_filename("a 3D.mkv", hd)->layout, StereoLayout::sbs_half);
  const auto rl = layout_from_filename("holiday.rl.mp4", 2 * hd);
  ASSERT_TRUE(rl.has_value());
  EXPECT_EQ(rl->layout, StereoLayout::sbs);
  EXPECT_TRUE(rl->swap_eyes);
  EXPECT_FALSE(layout_from_filename("/sbs/plain-movie.mkv", hd).has_value()) << "only the file's own name";
  EXPECT_FALSE(layout_from_filename("subsonic.mkv", hd).has_value()) << "tokens, not substrings";
}

TEST(LayoutHints, LeftRightTokensAreHalfOrFullByTheAspect) {
  // `lr`/`rl` say side-by-side only: at a single view's aspect the views are half width.
  const auto rl = layout_from_filename("holiday.rl.mp4", 16.0 / 9.0);
  ASSERT_TRUE(rl.has_value());
  EXPECT_EQ(rl->layout, StereoLayout::sbs_half);
  EXPECT_TRUE(rl->swap_eyes);
  EXPECT_EQ(layout_from_filename("holiday.lr.mp4", 16.0 / 9.0)->layout, StereoLayout::sbs_half);
  // Without an aspect they mean full side-by-side (the common stills convention).
  EXPECT_EQ(layout_from_filename("holiday.lr.jpg")->layout, StereoLayout::sbs);
  const LayoutDecision d = detect_stereo_layout({std::nullopt, std::nullopt, 1920, 1080, "clip_RL.mkv"});
  EXPECT_EQ(d.layout, StereoLayout::sbs_half);
  EXPECT_TRUE(d.swap_eyes);
  EXPECT_EQ(d.rule, DetectionRule::filename);
}

// Release names x frame sizes through the whole chain: a bare SBS/OU/TAB (or 3D) names only the
// arrangement and the frame's aspect decides half or full, as for metadata; the explicit half and
// full spellings decide whatever the frame.
struct ReleaseCase {
  const char* name;
  int width, height;
  StereoLayout layout;
};

TEST(LayoutChain, ReleaseNamesHalfOrFullByTheFrame) {
  using L = StereoLayout;
  const ReleaseCase cases[] = {
      // Bare tokens: the aspect decides.
      {"Movie.1080p.3D.SBS.mkv", 1920, 1080, L::sbs_half},
      {"Movie.1080p.3D.SBS.mkv", 3840, 1080, L::sbs},
      {"Movie.720p.3D.SBS.x264.mkv", 1280, 720, L::sbs_half},
      {"Movie.2160p.3D.SBS.mkv", 3840, 2160, L::sbs_half},
      {"Scope.Movie.3D.SBS.mkv", 1920, 800, L::sbs_half},  // 2.4:1 is one scope view
      {"Scope.Movie.3D.SBS.mkv", 3840, 800, L::sbs},
      {"movie [3D] [SBS].mp4", 1920, 1080, L::sbs_half},
      {"movie_sbs.mp4", 2560, 720, L::sbs},
      {"Movie.1080p.3D.OU.mkv", 1920, 1080, L::tab_half},
      {"Movie.1080p.3D.OU.mkv", 1920, 2160, L::tab},
      {"Movie.3D.TAB.mkv", 1920, 1080, L::tab_half},
      {"Movie.3D.TAB.mkv", 1280, 1440, L::tab},
      {"Movie.3D.TAB.mkv", 1920, 1600, L::tab},  // two scope views stacked: 1.2
      {"Movie.3D.1080p.mkv", 1920, 1080, L::sbs_half},
      {"Movie.3D.1080p.mkv", 3840, 1080, L::sbs},
      {"clip.LR.mp4", 1920, 1080, L::sbs_half},
      {"clip.LR.mp4", 3840, 1080, L::sbs},
      // Explicit full: full whatever the frame.
      {"Movie.1080p.3D.FSBS.mkv", 1920, 1080, L::sbs},
      {"Movie.1080p.3D.Full-SBS.mkv", 1920, 1080, L::sbs},
      {"Movie.1080p.3D.FullSBS.mkv", 1920, 1080, L::sbs},
      {"Movie.1080p.3D.Full.SBS.mkv", 1920, 1080, L::sbs},
      {"Movie.1080p.3D.F-SBS.mkv", 1920, 1080, L::sbs},
      {"Movie.1080p.3D.FOU.mkv", 1920, 1080, L::tab},
      {"Movie.1080p.3D.Full-OU.mkv", 1920, 1080, L::tab},
      {"Movie.1080p.3D.FullOU.mkv", 1920, 1080, L::tab},
      {"Movie.1080p.3D.FTAB.mkv", 1920, 1080, L::tab},
      {"Movie.1080p.3D.Full-TAB.mkv", 1920, 1080, L::tab},
      {"Movie.1080p.3D.FullTAB.mkv", 1920, 1080, L::tab},
      // Explicit half: half whatever the frame.
      {"Movie.1080p.3D.HSBS.mkv", 3840, 1080, L::sbs_half},
      {"Movie.1080p.3D.Half-SBS.mkv", 3840, 1080, L::sbs_half},
      {"Movie.1080p.3D.H-SBS.mkv", 3840, 1080, L::sbs_half},
      {"Movie.1080p.3D.HalfSBS.mkv", 3840, 1080, L::sbs_half},
      {"Movie.1080p.3D.HOU.mkv", 1920, 2160, L::tab_half},
      {"Movie.1080p.3D.H-OU.mkv", 1920, 2160, L::tab_half},
      {"Movie.1080p.3D.Half-OU.mkv", 1920, 2160, L::tab_half},
      {"Movie.1080p.3D.HTAB.mkv", 1920, 2160, L::tab_half},
      {"Movie.1080p.3D.H-TAB.mkv", 1920, 2160, L::tab_half},
      {"Movie.1080p.3D.HalfTAB.mkv", 1920, 2160, L::tab_half},
  };
  for (const auto& c : cases) {
    const LayoutDecision d = detect_stereo_layout(plain(c.width, c.height, c.name));
    EXPECT_EQ(to_string(d.layout), to_string(c.layout)) << c.name << " at " << c.width << "x" << c.height;
    EXPECT_EQ(d.rule, DetectionRule::filename) << c.name;
    EXPECT_FALSE(d.swap_eyes) << c.name;
  }
}

TEST(LayoutChain, ReleaseNameAspectIncludesTheSampleAspect) {
  // An anamorphic 1440x1080 frame with 4:3 pixels is displayed 16:9: one view, so half.
  LayoutEvidence e = plain(1440, 1080, "Movie.3D.SBS.mkv");
  e.display_aspect = 1440.0 * 4 / 3 / 1080;
  EXPECT_EQ(detect_stereo_layout(e).layout, StereoLayout::sbs_half);
  e.display_aspect = 2 * e.display_aspect;
  EXPECT_EQ(detect_stereo_layout(e).layout, StereoLayout::sbs);
}

TEST(LayoutChain, SwapEyesFlagComesOnTopOfJps) {
  LayoutEvidence e{std::nullopt, std::nullopt, 2048, 768, "photo.jps"};
  e.swap_eyes = true;
  EXPECT_FALSE(detect_stereo_layout(e).swap_eyes) << "--swap-eyes undoes the JPS convention";
}

}  // namespace
}  // namespace nelf
