#include "inputs/game_depth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace nelf {
namespace {

// Matched points a frame adds to the pool, and how many frames' worth it keeps: the relation
// belongs to the game's projection, not to the frame, so old matches stay good until it changes
// (a zoom), and pooling them keeps the fit steady from frame to frame.
constexpr std::size_t kPointsPerFrame = 96;
constexpr std::size_t kPoolSize = 8 * kPointsPerFrame;
constexpr std::size_t kFewestToFit = 24;
constexpr int kHalfPatch = 4;  // 9 × 9 pixels matched
// A match whose disparity lies farther than this from the line is another surface (an occlusion,
// a HUD, a repeated texture): pixels.
constexpr double kInlier_px = 0.75;

std::uint8_t luma(const std::uint8_t* rgba) {
  return static_cast<std::uint8_t>((77 * rgba[0] + 150 * rgba[1] + 29 * rgba[2]) >> 8);
}

// Rows y0.. of width w from column x0 of one eye as luma (8-bit), clipped to the eye by the caller.
cv::Mat luma_patch(const GameEyeColour& eye, int x0, int y0, int w, int h) {
  cv::Mat out(h, w, CV_8U);
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* row = eye.first_row + (y0 + y) * eye.row_step + static_cast<std::ptrdiff_t>(x0) * 4;
    auto* o = out.ptr<std::uint8_t>(y);
    for (int x = 0; x < w; ++x) o[x] = luma(row + 4 * x);
  }
  return out;
}

float depth_at(const GameEyeDepth& eye, int x, int y) { return eye.first_row[y * eye.row_step + x]; }

}  // namespace

void GameDepthRelation::match_points(const GameEyes& eyes, float depth_range) {
  const int w = eyes.width, h = eyes.height;
  const int max_disparity = std::max(8, w / 6);
  const float same_surface = 0.02f * depth_range;
  // Candidates on a grid shifted from frame to frame, so that the pool sees different points.
  const int step_x = std::max(2 * kHalfPatch + 1, w / 32), step_y = std::max(2 * kHalfPatch + 1, h / 18);
  const int jitter_x = static_cast<int>(frame_ * 7 % static_cast<std::uint32_t>(step_x));
  const int jitter_y = static_cast<int>(frame_ * 5 % static_cast<std::uint32_t>(step_y));
  struct Candidate {
    int x, y;
  };
  std::vector<Candidate> candidates;
  for (int y = kHalfPatch + jitter_y; y < h - kHalfPatch; y += step_y)
    for (int x = kHalfPatch + jitter_x; x < w - kHalfPatch; x += step_x) {
      // Not across a depth edge: the patch shows one surface.
      const float z = depth_at(eyes.depth[0], x, y);
      bool one_surface = true;
      for (const auto& [dx, dy] : {std::pair{-1, -1}, {1, -1}, {-1, 1}, {1, 1}})
        one_surface = one_surface &&
                      std::abs(depth_at(eyes.depth[0], x + dx * kHalfPatch, y + dy * kHalfPatch) - z) <= same_surface;
      if (!one_surface) continue;
      const cv::Mat patch =
          luma_patch(eyes.colour[0], x - kHalfPatch, y - kHalfPatch, 2 * kHalfPatch + 1, 2 * kHalfPatch + 1);
      double texture = 0;
      for (int py = 0; py < patch.rows; ++py)
        for (int px = 1; px < patch.cols; ++px)
          texture += std::abs(patch.at<std::uint8_t>(py, px) - patch.at<std::uint8_t>(py, px - 1));
      // Horizontal structure is what a match along the row needs: at least 3 levels a pixel.
      if (texture >= 3.0 * patch.rows * (patch.cols - 1)) candidates.push_back({x, y});
    }
  // A random share of them, not the most textured: a HUD or an overlay drawn over the scene without
  // depth (text, crosshairs: the sharpest patches of a frame) then has matches in proportion to its
  // area, so the scene's own outnumber them and the line goes through the scene's.
  std::shuffle(candidates.begin(), candidates.end(), random_);
  if (candidates.size() > kPointsPerFrame) candidates.resize(kPointsPerFrame);
  for (const Candidate& c : candidates) {
    // The right view's row strip where the point can be: x − d for d in ±max_disparity.
    const int x0 = std::max(0, c.x - max_disparity - kHalfPatch);
    const int x1 = std::min(w, c.x + max_disparity + kHalfPatch + 1);
    if (x1 - x0 < 2 * kHalfPatch + 3) continue;
    const cv::Mat patch =
        luma_patch(eyes.colour[0], c.x - kHalfPatch, c.y - kHalfPatch, 2 * kHalfPatch + 1, 2 * kHalfPatch + 1);
    const cv::Mat strip = luma_patch(eyes.colour[1], x0, c.y - kHalfPatch, x1 - x0, 2 * kHalfPatch + 1);
    cv::Mat cost;
    cv::matchTemplate(strip, patch, cost, cv::TM_SQDIFF);
    const auto* s = cost.ptr<float>(0);
    const int n = cost.cols;
    const int best = static_cast<int>(std::min_element(s, s + n) - s);
    // Unique: nothing else along the row nearly as good (a repeated texture is no match).
    float second = std::numeric_limits<float>::infinity();
    for (int i = 0; i < n; ++i)
      if (std::abs(i - best) > 2) second = std::min(second, s[i]);
    const float noise = 4.0f * static_cast<float>(patch.total());
    if (!(second > 1.25f * s[best] + noise)) continue;
    if (best == 0 || best == n - 1) continue;  // at the edge of the range: not a real minimum
    const double curvature = s[best - 1] - 2.0 * s[best] + s[best + 1];
    const double sub = curvature > 0 ? 0.5 * (s[best - 1] - s[best + 1]) / curvature : 0.0;
    const double right_x = x0 + kHalfPatch + best + sub;
    const int rx = static_cast<int>(std::lround(right_x));
    if (rx < 0 || rx >= w) continue;
    // The same surface in the right view: its depth there agrees (not an occluder in front).
    const float z = depth_at(eyes.depth[0], c.x, c.y);
    if (std::abs(depth_at(eyes.depth[1], rx, c.y) - z) > same_surface) continue;
    const Sample sample{z, static_cast<float>(c.x - right_x)};
    if (pool_.size() < kPoolSize)
      pool_.push_back(sample);
    else
      pool_[next_++ % kPoolSize] = sample;
  }
}

// A line through the pooled samples that most of them lie on (RANSAC over pairs), then least
// squares over those.
void GameDepthRelation::fit() {
  const std::size_t n = pool_.size();
  if (n < kFewestToFit) return;
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  std::vector<std::size_t> best_inliers, inliers;
  for (int iteration = 0; iteration < 160; ++iteration) {
    const Sample a = pool_[pick(random_)], b = pool_[pick(random_)];
    if (!(std::abs(a.depth - b.depth) > 1e-7f)) continue;
    const double slope = (static_cast<double>(b.disparity) - a.disparity) / (static_cast<double>(b.depth) - a.depth);
    const double offset = a.disparity - slope * a.depth;
    inliers.clear();
    for (std::size_t i = 0; i < n; ++i)
      if (std::abs(offset + slope * pool_[i].depth - pool_[i].disparity) <= kInlier_px) inliers.push_back(i);
    if (inliers.size() > best_inliers.size()) best_inliers.swap(inliers);
  }
  // Most of the pool on one line, and the line spanning more than one depth.
  if (best_inliers.size() < kFewestToFit || best_inliers.size() * 5 < n * 2) return;
  double mz = 0, md = 0;
  for (std::size_t i : best_inliers) mz += pool_[i].depth, md += pool_[i].disparity;
  mz /= static_cast<double>(best_inliers.size());
  md /= static_cast<double>(best_inliers.size());
  double szz = 0, szd = 0;
  for (std::size_t i : best_inliers) {
    const double dz = pool_[i].depth - mz;
    szz += dz * dz;
    szd += dz * (pool_[i].disparity - md);
  }
  if (!(szz > 0)) return;
  DepthToDisparity line;
  line.slope = szd / szz;
  line.offset = md - line.slope * mz;
  relation_ = line;
}

std::shared_ptr<const StereoDisparity> GameDepthRelation::disparity(const GameEyes& eyes, std::array<int, 2> block) {
  const int w = eyes.width, h = eyes.height;
  ++frame_;
  // Empty buffers: a game that draws without depth, or into framebuffers of its own and copies only
  // the colour to the window.
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (const GameEyeDepth& eye : eyes.depth)
    for (int y = 0; y < h; y += std::max(1, h / 64))
      for (int x = 0; x < w; x += std::max(1, w / 64)) {
        lo = std::min(lo, depth_at(eye, x, y));
        hi = std::max(hi, depth_at(eye, x, y));
      }
  if (!(hi - lo > 1e-7f)) {
    gap_ = GameDepthGap::empty_buffers;
    return nullptr;
  }
  if (w > 4 * kHalfPatch && h > 4 * kHalfPatch) match_points(eyes, hi - lo);
  fit();
  if (!relation_) {
    gap_ = GameDepthGap::too_few_matches;
    return nullptr;
  }
  gap_ = GameDepthGap::none;
  const auto [bx, by] = block;
  const int mw = w / bx, mh = h / by;
  std::shared_ptr<StereoDisparity> out = maps_.next();
  out->origin = DisparityOrigin::game;
  // A block's disparity is the mean of its pixels': the line of the mean depth value, in the map's
  // pixels (a block is bx eye pixels wide).
  const float offset = static_cast<float>(relation_->offset / bx);
  const float slope = static_cast<float>(relation_->slope / bx / (bx * by));
  for (int i = 0; i < 2; ++i) {
    ViewDisparity& map = i == 0 ? out->left : out->right;
    map.width = mw;
    map.height = mh;
    map.d.resize(static_cast<std::size_t>(mw) * mh);
    for (int my = 0; my < mh; ++my) {
      float* row = map.d.data() + static_cast<std::size_t>(my) * mw;
      if (bx == 1 && by == 1) {
        const float* depth = eyes.depth[i].first_row + my * eyes.depth[i].row_step;
        for (int mx = 0; mx < mw; ++mx) row[mx] = offset + slope * depth[mx];
        continue;
      }
      for (int mx = 0; mx < mw; ++mx) {
        float sum = 0;
        for (int y = my * by; y < (my + 1) * by; ++y)
          for (int x = mx * bx; x < (mx + 1) * bx; ++x) sum += depth_at(eyes.depth[i], x, y);
        row[mx] = offset + slope * sum;
      }
    }
  }
  return out;
}

}  // namespace nelf
