// inputs/stereo_matcher: the estimated depth against stereo pairs of known disparity built here (a
// textured plane in front of a textured background, with the occlusions that makes), and what it
// must not do: invent depth on a flat, black or uncorrelated pair.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "inputs/stereo_matcher.hpp"

namespace nelf {
namespace {

// Smooth value noise (two octaves of bilinearly interpolated lattice values), defined at every
// integer point so that a view can be cut anywhere from it: the texture of the scene's surfaces.
float texture(int u, int v, unsigned seed) {
  const auto lattice = [seed](int i, int j) {
    std::uint32_t h = static_cast<std::uint32_t>(i) * 73856093u ^ static_cast<std::uint32_t>(j) * 19349663u ^ seed;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return static_cast<float>(h & 0xffffu) / 65535.f;
  };
  const auto octave = [&](int cell) {
    const int i = static_cast<int>(std::floor(static_cast<float>(u) / static_cast<float>(cell)));
    const int j = static_cast<int>(std::floor(static_cast<float>(v) / static_cast<float>(cell)));
    const float fx = static_cast<float>(u - i * cell) / static_cast<float>(cell);
    const float fy = static_cast<float>(v - j * cell) / static_cast<float>(cell);
    const float top = lattice(i, j) * (1 - fx) + lattice(i + 1, j) * fx;
    const float bottom = lattice(i, j + 1) * (1 - fx) + lattice(i + 1, j + 1) * fx;
    return top * (1 - fy) + bottom * fy;
  };
  return 0.6f * octave(12) + 0.4f * octave(4);
}

// A scene of known disparity: the background at `background_d` everywhere, a plane at `plane_d`
// covering [x0, x1) × [y0, y1) of the left view. `truth_*`: the disparity of each view's pixel,
// NaN where the point is hidden in the other view or outside it.
struct KnownPair {
  StereoVideoFrame frame;
  std::vector<float> truth_left, truth_right;
};

// `plane_seed`: the plane's texture (0: seed + 1).
KnownPair planes_pair(int width, int height, int background_d, int plane_d, int bits = 8, unsigned seed = 7,
                      unsigned plane_seed = 0) {
  if (plane_seed == 0) plane_seed = seed + 1;
  const int x0 = width / 3, x1 = width * 2 / 3, y0 = height / 4, y1 = height * 3 / 4;
  const auto on_plane = [&](int x, int y) { return x >= x0 && x < x1 && y >= y0 && y < y1; };
  KnownPair p;
  auto& f = p.frame;
  f.width = width;
  f.height = height;
  f.bits = bits;
  f.aspect = static_cast<double>(width) / height;
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  f.left.resize(pixels * bytes_per_pixel(bits));
  f.right.resize(pixels * bytes_per_pixel(bits));
  p.truth_left.assign(pixels, 0.f);
  p.truth_right.assign(pixels, 0.f);
  const auto put = [&](std::vector<std::uint8_t>& view, std::size_t i, float value) {
    if (bits > 8) {
      const auto v = static_cast<std::uint16_t>(std::lround(value * 65535.f));
      const std::uint16_t px[4] = {v, v, static_cast<std::uint16_t>(v / 2 + 16384), 65535};
      std::memcpy(view.data() + i * 8, px, sizeof px);
    } else {
      const auto v = static_cast<std::uint8_t>(std::lround(value * 255.f));
      const std::uint8_t px[4] = {v, v, static_cast<std::uint8_t>(v / 2 + 64), 255};
      std::memcpy(view.data() + i * 4, px, sizeof px);
    }
  };
  const float nan = std::nanf("");
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
      // Left view: the plane, or the background (seen in the right view at x − background_d,
      // unless the plane covers that spot there).
      if (on_plane(x, y)) {
        put(f.left, i, texture(x - x0, y, plane_seed));
        p.truth_left[i] = static_cast<float>(plane_d);
      } else {
        put(f.left, i, texture(x, y, seed));
        const int xr = x - background_d;
        p.truth_left[i] = xr < 0 || xr >= width || on_plane(xr + plane_d, y) ? nan : static_cast<float>(background_d);
      }
      // Right view: the plane where its left-view point x + plane_d is on it, else the background.
      if (on_plane(x + plane_d, y)) {
        put(f.right, i, texture(x + plane_d - x0, y, plane_seed));
        p.truth_right[i] = static_cast<float>(plane_d);
      } else {
        put(f.right, i, texture(x + background_d, y, seed));
        const int xl = x + background_d;
        p.truth_right[i] = xl < 0 || xl >= width || on_plane(xl, y) ? nan : static_cast<float>(background_d);
      }
    }
  return p;
}

// The estimate against the truth, in the view's pixels: over the pixels the truth says both views
// see, the median absolute error of those matched, the share of them off by more than `bad_px`,
// and the share left unknown; over the occluded pixels, the share given a value that is neither
// the background's nor unknown (garbage in the occlusions).
struct Accuracy {
  double median_error = 0, bad_share = 0, unknown_share = 0, occlusion_garbage = 0;
};

Accuracy accuracy(const ViewDisparity& map, const std::vector<float>& truth, int width, int height, float background_d,
                  float bad_px = 3.f) {
  EXPECT_GT(map.width, 0);
  EXPECT_EQ(map.d.size(), static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height));
  const float scale = static_cast<float>(width) / static_cast<float>(map.width);
  std::vector<float> errors;
  std::size_t visible = 0, unknown = 0, bad = 0, occluded = 0, garbage = 0;
  for (int my = 0; my < map.height; ++my)
    for (int mx = 0; mx < map.width; ++mx) {
      const int x = std::min(width - 1, static_cast<int>((static_cast<float>(mx) + .5f) * scale));
      const int y = std::min(height - 1, static_cast<int>((static_cast<float>(my) + .5f) * height / map.height));
      const float t =
          truth[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)];
      const float e =
          map.d[static_cast<std::size_t>(my) * static_cast<std::size_t>(map.width) + static_cast<std::size_t>(mx)] *
          scale;
      if (std::isnan(t)) {
        ++occluded;
        garbage += !std::isnan(e) && std::abs(e - background_d) > bad_px;
        continue;
      }
      ++visible;
      if (std::isnan(e)) {
        ++unknown;
        continue;
      }
      errors.push_back(std::abs(e - t));
      bad += errors.back() > bad_px;
    }
  Accuracy a;
  if (!errors.empty()) {
    std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2), errors.end());
    a.median_error = errors[errors.size() / 2];
    a.bad_share = static_cast<double>(bad) / static_cast<double>(errors.size());
  }
  a.unknown_share = static_cast<double>(unknown) / static_cast<double>(std::max<std::size_t>(visible, 1));
  a.occlusion_garbage = static_cast<double>(garbage) / static_cast<double>(std::max<std::size_t>(occluded, 1));
  return a;
}

void expect_accurate(const StereoDisparity& d, const KnownPair& p, float background_d, double max_median = 0.5,
                     double max_bad = 0.02) {
  const int w = p.frame.width, h = p.frame.height;
  const Accuracy left = accuracy(d.left, p.truth_left, w, h, background_d);
  const Accuracy right = accuracy(d.right, p.truth_right, w, h, background_d);
  for (const auto& [name, a] : {std::pair{"left", left}, std::pair{"right", right}}) {
    SCOPED_TRACE(name);
    std::printf("%s: median %.3f bad %.4f unknown %.4f occlusion garbage %.4f (map %dx%d)\n", name, a.median_error,
                a.bad_share, a.unknown_share, a.occlusion_garbage, d.left.width, d.left.height);
    EXPECT_LE(a.median_error, max_median);
    EXPECT_LE(a.bad_share, max_bad);
    EXPECT_LE(a.unknown_share, 0.12);
    EXPECT_LE(a.occlusion_garbage, 0.10);
  }
  EXPECT_EQ(d.origin, DisparityOrigin::estimated);
}

TEST(StereoMatcher, FindsAPlaneBeforeItsBackgroundIn1080p) {
  const KnownPair p = planes_pair(1920, 1080, -12, 60);
  StereoMatcher matcher;
  const auto d = matcher.estimate(p.frame);
  ASSERT_TRUE(d);
  expect_accurate(*d, p, -12.f);
  // Coarser than the view, finer than the working resolution: upsampled.
  EXPECT_LT(d->left.width, 1920);
  EXPECT_GT(d->left.width, 480);
  EXPECT_EQ(d->left.width, d->right.width);
}

TEST(StereoMatcher, FindsAPlaneCloseToTheEyeWithAWideDisparity) {
  // A third of the view's width in front of the screen (a plane a quarter of the screen distance
  // away): the range probe widens the search and the working resolution drops to pay for it.
  const KnownPair p = planes_pair(1280, 720, 0, 420);
  StereoMatcher matcher;
  const auto d = matcher.estimate(p.frame);
  ASSERT_TRUE(d);
  expect_accurate(*d, p, 0.f);
}

// A still is matched once, with no cost budget: a range as wide as this plane's is matched at the
// full working width, where a video frame drops to a coarser one to keep its time, so the still's
// map is finer.
TEST(StereoMatcher, AStillIsMatchedAtTheFullWorkingWidthWhateverItsRange) {
  const KnownPair p = planes_pair(1280, 720, 0, 420, 16);
  StereoPair views;
  for (auto [bytes, view] : {std::pair{&p.frame.left, &views.left}, std::pair{&p.frame.right, &views.right}}) {
    view->image = Image(1280, 720);
    for (std::size_t i = 0; i < std::size_t{1280} * 720 * 4; ++i) {
      std::uint16_t v = 0;
      std::memcpy(&v, bytes->data() + 2 * i, 2);
      view->image.data()[i] = static_cast<float>(v) / 65535.f;
    }
  }
  const auto still = estimate_still_disparity(views);
  ASSERT_TRUE(still);
  expect_accurate(*still, p, 0.f);
  StereoMatcher matcher;
  const auto frame = matcher.estimate(p.frame);
  ASSERT_TRUE(frame);
  const Accuracy from_still = accuracy(still->left, p.truth_left, 1280, 720, 0.f, 0.5f);
  const Accuracy from_frame = accuracy(frame->left, p.truth_left, 1280, 720, 0.f, 0.5f);
  std::printf("off by more than half a pixel: still %.4f, video frame %.4f\n", from_still.bad_share,
              from_frame.bad_share);
  EXPECT_LT(from_still.bad_share, 0.75 * from_frame.bad_share);
}

TEST(StereoMatcher, ReadsSixteenBitViewsAndBlockMeans) {
  {
    const KnownPair p = planes_pair(960, 540, -6, 30, 16);
    StereoMatcher matcher;
    const auto d = matcher.estimate(p.frame);
    ASSERT_TRUE(d);
    expect_accurate(*d, p, -6.f);
  }
  // The frame's views as 2 × 2 block means of a 1920 × 1080 view: the maps are of the same
  // scene, so in the full view's pixels they agree with the truth there.
  const KnownPair full = planes_pair(1920, 1080, -12, 60);
  StereoVideoFrame blocks = full.frame;
  blocks.block = {2, 2};
  const auto reduce = [](const std::vector<std::uint8_t>& view) {
    std::vector<std::uint8_t> out(960 * 540 * 4);
    for (int y = 0; y < 540; ++y)
      for (int x = 0; x < 960; ++x)
        for (int c = 0; c < 4; ++c) {
          int s = 0;
          for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) s += view[((2 * y + dy) * 1920 + 2 * x + dx) * 4 + c];
          out[(y * 960 + x) * 4 + c] = static_cast<std::uint8_t>(s / 4);
        }
    return out;
  };
  blocks.left = reduce(full.frame.left);
  blocks.right = reduce(full.frame.right);
  StereoMatcher matcher;
  const auto d = matcher.estimate(blocks);
  ASSERT_TRUE(d);
  expect_accurate(*d, full, -12.f);
}

StereoVideoFrame uniform_frame(int width, int height, std::uint8_t level) {
  StereoVideoFrame f;
  f.width = width;
  f.height = height;
  f.left.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4, level);
  f.right = f.left;
  return f;
}

TEST(StereoMatcher, GivesNoDepthForAFlatOrBlackPair) {
  StereoMatcher matcher;
  EXPECT_FALSE(matcher.estimate(uniform_frame(1920, 1080, 0)));
  EXPECT_FALSE(matcher.estimate(uniform_frame(1920, 1080, 128)));
  // After a textured frame too: the flat one takes nothing from it.
  const KnownPair p = planes_pair(960, 540, -6, 30);
  ASSERT_TRUE(matcher.estimate(p.frame));
  EXPECT_FALSE(matcher.estimate(uniform_frame(960, 540, 0)));
}

TEST(StereoMatcher, GivesNoDepthWhereTheViewsShowDifferentThings) {
  // Two unrelated textures: nothing matches, and what matches by chance fails the cross check.
  KnownPair a = planes_pair(960, 540, 0, 0, 8, 11);
  const KnownPair b = planes_pair(960, 540, 0, 0, 8, 977);
  a.frame.right = b.frame.right;
  StereoMatcher matcher;
  const auto d = matcher.estimate(a.frame);
  if (d) {
    std::size_t known = 0;
    for (float v : d->left.d) known += !std::isnan(v);
    EXPECT_LT(static_cast<double>(known) / static_cast<double>(d->left.d.size()), 0.10);
  }
}

TEST(StereoMatcher, TemperedOnStillVideoAndFollowsACut) {
  // The same scene with fresh sensor noise each frame: the tempered estimate changes less from
  // frame to frame than untempered ones do, and after a cut to another scene it is right at once.
  const KnownPair p = planes_pair(960, 540, -6, 30);
  const auto noisy = [&](unsigned n) {
    StereoVideoFrame f = p.frame;
    std::uint32_t state = 12345u + n;
    for (auto* view : {&f.left, &f.right})
      for (std::size_t i = 0; i < view->size(); i += 4) {
        state = state * 1664525u + 1013904223u;
        const int noise = static_cast<int>(state >> 29) - 4;
        for (std::size_t c = 0; c < 3; ++c)
          (*view)[i + c] = static_cast<std::uint8_t>(std::clamp(int{(*view)[i + c]} + noise, 0, 255));
      }
    return f;
  };
  const auto flicker = [&](double weight) {
    StereoMatcherSettings s;
    s.temporal_weight = weight;
    StereoMatcher matcher(s);
    std::shared_ptr<const StereoDisparity> previous;
    double change = 0;
    std::size_t n = 0;
    for (unsigned frame = 0; frame < 6; ++frame) {
      auto d = matcher.estimate(noisy(frame));
      EXPECT_TRUE(d);
      if (!d) return 0.0;
      if (previous && frame >= 2)
        for (std::size_t i = 0; i < d->left.d.size(); ++i)
          if (!std::isnan(d->left.d[i]) && !std::isnan(previous->left.d[i]))
            change += std::abs(d->left.d[i] - previous->left.d[i]), ++n;
      previous = d;
    }
    return change / static_cast<double>(std::max<std::size_t>(n, 1));
  };
  const double tempered = flicker(0.5), untempered = flicker(0.0);
  EXPECT_GT(untempered, 0.0);
  EXPECT_LT(tempered, 0.8 * untempered);

  StereoMatcher matcher;
  for (unsigned frame = 0; frame < 3; ++frame) ASSERT_TRUE(matcher.estimate(noisy(frame)));
  const KnownPair cut = planes_pair(960, 540, 4, 50, 8, 99);
  const auto d = matcher.estimate(cut.frame);
  ASSERT_TRUE(d);
  expect_accurate(*d, cut, 4.f);
}

TEST(StereoMatcher, TheRangeOfAShotFollowsAPlaneThatComesCloser) {
  // Within a shot the search range is the last estimate's own (the probe is saved); a plane that
  // jumps far beyond it, with no cut, leaves much of the view unmatched, and the next frame probes
  // again: the plane is found one frame late, at the latest at the probe's interval of 12 frames.
  StereoMatcher matcher;
  for (unsigned frame = 0; frame < 4; ++frame)
    ASSERT_TRUE(matcher.estimate(planes_pair(960, 540, -6, 30, 8, 7, 8 + frame).frame));
  const auto accurate = [](const StereoDisparity& d, const KnownPair& p) {
    for (const auto& [map, truth] : {std::pair{&d.left, &p.truth_left}, std::pair{&d.right, &p.truth_right}}) {
      const Accuracy a = accuracy(*map, *truth, p.frame.width, p.frame.height, -6.f);
      if (a.median_error > 0.5 || a.bad_share > 0.02 || a.unknown_share > 0.12 || a.occlusion_garbage > 0.10)
        return false;
    }
    return true;
  };
  int late = 0;
  for (; late < 12; ++late) {
    const KnownPair p = planes_pair(960, 540, -6, 150, 8, 7, 20 + static_cast<unsigned>(late));
    const auto d = matcher.estimate(p.frame);
    ASSERT_TRUE(d);
    if (accurate(*d, p)) break;
  }
  EXPECT_EQ(late, 1) << "frames before the plane at 150 px was found";
}

TEST(StereoMatcher, RefusesViewsThatDoNotHoldTheFramesPixelsAndSkipsTinyOnes) {
  StereoVideoFrame f = uniform_frame(64, 64, 10);
  f.right.resize(10);
  StereoMatcher matcher;
  EXPECT_THROW(matcher.estimate(f), std::invalid_argument);
  EXPECT_FALSE(matcher.estimate(uniform_frame(16, 16, 10)));
}

}  // namespace
}  // namespace nelf
