#pragma once
// A game's depth buffers as the content's disparity (issue #15, the `game` depth source).
//
// A depth buffer holds, per pixel, a value that a perspective projection makes affine in 1/z (z the
// distance from the camera), and a stereo pair of parallel cameras, off-axis or not, has a
// disparity that is affine in 1/z too: so disparity = offset + slope · depth-buffer value, with
// two numbers per game (per projection), whatever its near and far planes, field of view or eye
// separation. GL does not say those (a modern game keeps its projection in its shaders), so the
// two numbers are fitted from stereo matches: a few well-textured points of each frame are
// matched along their row into the other view, and a robust line through the pooled (depth value,
// disparity) pairs of the last frames gives the relation. Then every pixel's disparity is exact to
// the depth buffer's precision, where a matcher would guess at untextured and occluded pixels.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "core/view_disparity.hpp"

namespace nelf {

// One eye as the game's buffers hold it: `first_row` is the top row of the picture and `row_step`
// the distance to the next one down, in elements (negative for GL's bottom-up rows).
struct GameEyeColour {
  const std::uint8_t* first_row = nullptr;  // RGBA8
  std::ptrdiff_t row_step = 0;              // bytes
};
struct GameEyeDepth {
  const float* first_row = nullptr;  // the depth buffer's values, 0..1
  std::ptrdiff_t row_step = 0;       // floats
};
struct GameEyes {
  int width = 0, height = 0;
  GameEyeColour colour[2];  // left, right
  GameEyeDepth depth[2];
};

// disparity = offset + slope · depth value, in pixels of the eye.
struct DepthToDisparity {
  double offset = 0, slope = 0;
  double at(double depth_value) const { return offset + slope * depth_value; }
};

// Why a frame has no disparity from its depth buffers.
enum class GameDepthGap {
  none,
  empty_buffers,   // every depth value the same: the game draws without depth, or into framebuffers of its own
  too_few_matches  // not yet enough matched points (flat, dark or untextured frames) to fit
};

// One game's relation, learnt over its frames; used from one thread.
class GameDepthRelation {
 public:
  // Both eyes' disparity maps (DisparityOrigin::game) for one frame, each pixel the mean over a
  // block of `block` eye pixels (the views' ViewFormat::block), in pixels of the map; null when the
  // frame has none (gap() says why).
  std::shared_ptr<const StereoDisparity> disparity(const GameEyes& eyes, std::array<int, 2> block);

  GameDepthGap gap() const { return gap_; }
  std::optional<DepthToDisparity> relation() const { return relation_; }

 private:
  struct Sample {
    float depth, disparity;
  };
  void match_points(const GameEyes& eyes, float depth_range);
  void fit();

  ReusableDisparityMaps maps_;  // a fresh 1280×720 pair cost more in page faults than in filling it

  std::vector<Sample> pool_;  // the last frames' matches, oldest overwritten first
  std::size_t next_ = 0;
  std::optional<DepthToDisparity> relation_;
  GameDepthGap gap_ = GameDepthGap::none;
  std::uint32_t frame_ = 0;
  std::mt19937 random_{20261205};
};

}  // namespace nelf
