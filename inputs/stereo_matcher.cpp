#include "inputs/stereo_matcher.hpp"

#include "inputs/view_bytes.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

namespace nelf {
namespace {

constexpr float unknown = std::numeric_limits<float>::quiet_NaN();
// The range probe matches at this width (or the view's, when smaller): a wide search is cheap there.
constexpr int probe_width = 192;
// Views smaller than this a side have nothing to match.
constexpr int smallest_view = 32;

int round_up_16(int n) { return (n + 15) / 16 * 16; }

// BT.709 luma of one RGBA pixel, 8 bits a channel scaled by 256.
inline std::uint32_t luma_256(std::uint32_t r, std::uint32_t g, std::uint32_t b) { return 54 * r + 183 * g + 19 * b; }

// The luma of `view` (pw × ph RGBA pixels of `bits`) averaged over k × k blocks, as 8-bit gray:
// the colour conversion and the first reduction in one pass over the frame's bytes.
cv::Mat luma_block_means(const std::vector<std::uint8_t>& view, int bits, int pw, int ph, int k) {
  const int ow = pw / k, oh = ph / k;
  cv::Mat out(oh, ow, CV_8UC1);
  const std::size_t row_bytes = static_cast<std::size_t>(pw) * bytes_per_pixel(bits);
  const float to_gray = 1.f / (static_cast<float>(k * k) * 256.f);
  cv::parallel_for_(cv::Range(0, oh), [&](const cv::Range& rows) {
    std::vector<std::uint32_t> sums(static_cast<std::size_t>(ow));
    for (int oy = rows.start; oy < rows.end; ++oy) {
      auto* dst = out.ptr<std::uint8_t>(oy);
      const std::uint8_t* top = view.data() + static_cast<std::size_t>(oy * k) * row_bytes;
      if (bits <= 8 && k == 2) {  // the common case (a 1080p view to the guide), kept vectorisable
        const std::uint8_t* bottom = top + row_bytes;
        for (int ox = 0; ox < ow; ++ox) {
          const std::uint8_t* a = top + static_cast<std::size_t>(ox) * 8;
          const std::uint8_t* b = bottom + static_cast<std::size_t>(ox) * 8;
          const std::uint32_t r = std::uint32_t{a[0]} + a[4] + b[0] + b[4];
          const std::uint32_t g = std::uint32_t{a[1]} + a[5] + b[1] + b[5];
          const std::uint32_t bl = std::uint32_t{a[2]} + a[6] + b[2] + b[6];
          dst[ox] = static_cast<std::uint8_t>((luma_256(r, g, bl) + 512) >> 10);
        }
        continue;
      }
      std::fill(sums.begin(), sums.end(), 0u);
      for (int dy = 0; dy < k; ++dy) {
        const std::uint8_t* row = top + static_cast<std::size_t>(dy) * row_bytes;
        if (bits > 8) {
          for (int ox = 0; ox < ow; ++ox) {
            std::uint32_t s = 0;
            for (int dx = 0; dx < k; ++dx) {
              std::uint16_t p[4];
              std::memcpy(p, row + static_cast<std::size_t>(ox * k + dx) * 8, sizeof p);
              s += luma_256(p[0], p[1], p[2]) >> 8;
            }
            sums[static_cast<std::size_t>(ox)] += s;
          }
        } else {
          for (int ox = 0; ox < ow; ++ox) {
            const std::uint8_t* p = row + static_cast<std::size_t>(ox * k) * 4;
            std::uint32_t s = 0;
            for (int dx = 0; dx < k; ++dx, p += 4) s += luma_256(p[0], p[1], p[2]);
            sums[static_cast<std::size_t>(ox)] += s;
          }
        }
      }
      for (int ox = 0; ox < ow; ++ox)
        dst[ox] = static_cast<std::uint8_t>(static_cast<float>(sums[static_cast<std::size_t>(ox)]) * to_gray);
    }
  });
  return out;
}

cv::Mat area_resize(const cv::Mat& gray, int width, int height) {
  if (gray.cols == width && gray.rows == height) return gray;
  cv::Mat out;
  cv::resize(gray, out, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  return out;
}

// Block matching of `left` against `right` (8-bit gray, same size) over disparities
// [min_d, min_d + num_d): d for a left pixel x means the match at x − d in the right image, the
// convention of ViewDisparity. NaN where the matcher found no unique, textured match. The images
// are padded first so that the candidates reaching outside the image do not cost the border its
// estimate (StereoBM leaves every column whose candidates leave the image unmatched).
cv::Mat block_match(cv::StereoBM& bm, const cv::Mat& left, const cv::Mat& right, int min_d, int num_d) {
  const int left_pad = std::max(0, min_d + num_d - 1), right_pad = std::max(0, -min_d);
  cv::Mat l, r, raw;
  cv::copyMakeBorder(left, l, 0, 0, left_pad, right_pad, cv::BORDER_REPLICATE);
  cv::copyMakeBorder(right, r, 0, 0, left_pad, right_pad, cv::BORDER_REPLICATE);
  bm.setMinDisparity(min_d);
  bm.setNumDisparities(num_d);
  bm.compute(l, r, raw);  // CV_16S, 1/16 pixel; below min_d: no match
  cv::Mat d(left.size(), CV_32F);
  const int invalid_below = min_d * 16;
  for (int y = 0; y < d.rows; ++y) {
    const auto* src = raw.ptr<std::int16_t>(y) + left_pad;
    auto* dst = d.ptr<float>(y);
    for (int x = 0; x < d.cols; ++x) dst[x] = src[x] < invalid_below ? unknown : static_cast<float>(src[x]) / 16.f;
  }
  return d;
}

// The right view's disparity: the same matcher on the mirrored pair (the mirrored right view as
// the reference), mirrored back; mirroring keeps the sign of the convention.
cv::Mat block_match_right(cv::StereoBM& bm, const cv::Mat& left, const cv::Mat& right, int min_d, int num_d) {
  cv::Mat fl, fr, d;
  cv::flip(left, fl, 1);
  cv::flip(right, fr, 1);
  cv::flip(block_match(bm, fr, fl, min_d, num_d), d, 1);
  return d;
}

// Left-right consistency: a left pixel keeps its disparity only if the right pixel it lands on
// points back to it (within `tolerance`), and the other way round; what fails is occluded or
// mismatched and becomes unknown. Rows are independent: each is checked, then changed.
void cross_check(cv::Mat& left, cv::Mat& right, float tolerance) {
  const int w = left.cols;
  // Where x − d lands, rounded: offset by the width so that truncation rounds down (|d| < width).
  const auto landing = [w](int x, float d) {
    return static_cast<int>(static_cast<float>(x) - d + 0.5f + static_cast<float>(w)) - w;
  };
  cv::parallel_for_(cv::Range(0, left.rows), [&](const cv::Range& rows) {
    std::vector<std::uint8_t> drop_left(static_cast<std::size_t>(w)), drop_right(static_cast<std::size_t>(w));
    for (int y = rows.start; y < rows.end; ++y) {
      auto* lr = left.ptr<float>(y);
      auto* rr = right.ptr<float>(y);
      for (int x = 0; x < w; ++x) {
        bool drop = false;
        if (const float d = lr[x]; !std::isnan(d)) {
          const int xr = landing(x, d);
          drop = xr < 0 || xr >= w || !(std::abs(rr[xr] - d) <= tolerance);  // NaN fails too
        }
        drop_left[static_cast<std::size_t>(x)] = drop;
        drop = false;
        if (const float d = rr[x]; !std::isnan(d)) {
          const int xl = landing(x, -d);
          drop = xl < 0 || xl >= w || !(std::abs(lr[xl] - d) <= tolerance);
        }
        drop_right[static_cast<std::size_t>(x)] = drop;
      }
      for (int x = 0; x < w; ++x) {
        if (drop_left[static_cast<std::size_t>(x)]) lr[x] = unknown;
        if (drop_right[static_cast<std::size_t>(x)]) rr[x] = unknown;
      }
    }
  });
}

double matched_share(const cv::Mat& d) {
  std::size_t matched = 0;
  for (int y = 0; y < d.rows; ++y) {
    const auto* row = d.ptr<float>(y);
    for (int x = 0; x < d.cols; ++x) matched += std::isnan(row[x]) ? 0 : 1;
  }
  return static_cast<double>(matched) / static_cast<double>(d.total());
}

// Where the view did not change since the previous frame, the estimate keeps `weight` of the
// previous one (and the previous one where this frame found none): the map stops flickering on
// still content and follows moving content at once.
void temper(cv::Mat& d, const cv::Mat& gray, const cv::Mat& previous_d, const cv::Mat& previous_gray, float weight) {
  constexpr int unchanged = 6;  // levels of 255: noise, compression
  for (int y = 0; y < d.rows; ++y) {
    auto* dr = d.ptr<float>(y);
    const auto* pr = previous_d.ptr<float>(y);
    const auto* g = gray.ptr<std::uint8_t>(y);
    const auto* pg = previous_gray.ptr<std::uint8_t>(y);
    for (int x = 0; x < d.cols; ++x) {
      if (std::abs(int{g[x]} - int{pg[x]}) > unchanged || std::isnan(pr[x])) continue;
      dr[x] = std::isnan(dr[x]) ? pr[x] : (1.f - weight) * dr[x] + weight * pr[x];
    }
  }
}

// Joint bilateral upsampling of `d` (at `low`'s size) to `guide`'s size: each output pixel
// interpolates the four nearest matched samples, each weighted by how close its gray level in
// `low` is to the pixel's in `guide`, so that depth edges follow the view's edges. Disparities are
// rescaled to the output's pixels.
// Into `out`, whose storage is reused when it has the size already.
void upsample(const cv::Mat& d, const cv::Mat& low, const cv::Mat& guide, ViewDisparity& out) {
  out.width = guide.cols;
  out.height = guide.rows;
  out.d.resize(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height));
  const float scale = static_cast<float>(guide.cols) / static_cast<float>(d.cols);
  // Where each output column and row falls between the samples of `d`.
  struct Tap {
    int i0, i1;
    float w;
  };
  const auto taps = [](int out_size, int in_size) {
    std::vector<Tap> t(static_cast<std::size_t>(out_size));
    const float step = static_cast<float>(in_size) / static_cast<float>(out_size);
    for (int o = 0; o < out_size; ++o) {
      const float f = std::clamp((static_cast<float>(o) + .5f) * step - .5f, 0.f, static_cast<float>(in_size - 1));
      const int i0 = static_cast<int>(f);
      t[static_cast<std::size_t>(o)] = {i0, std::min(i0 + 1, in_size - 1), f - static_cast<float>(i0)};
    }
    return t;
  };
  const std::vector<Tap> columns = taps(guide.cols, d.cols), rows_at = taps(guide.rows, d.rows);
  std::array<float, 256> similarity{};
  constexpr float sigma = 10.f;
  for (int i = 0; i < 256; ++i)
    similarity[static_cast<std::size_t>(i)] = std::exp(-static_cast<float>(i * i) / (2 * sigma * sigma)) + 1e-4f;
  cv::parallel_for_(cv::Range(0, guide.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const Tap ty = rows_at[static_cast<std::size_t>(y)];
      const float* d0 = d.ptr<float>(ty.i0);
      const float* d1 = d.ptr<float>(ty.i1);
      const std::uint8_t* l0 = low.ptr<std::uint8_t>(ty.i0);
      const std::uint8_t* l1 = low.ptr<std::uint8_t>(ty.i1);
      const std::uint8_t* g = guide.ptr<std::uint8_t>(y);
      float* dst = out.d.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width);
      for (int x = 0; x < guide.cols; ++x) {
        const Tap tx = columns[static_cast<std::size_t>(x)];
        const int level = g[x];
        const auto weight = [&](float v, std::uint8_t sample_level, float spatial) {
          return std::isnan(v) ? 0.f
                               : spatial * similarity[static_cast<std::size_t>(std::abs(level - int{sample_level}))];
        };
        const float v00 = d0[tx.i0], v01 = d0[tx.i1], v10 = d1[tx.i0], v11 = d1[tx.i1];
        const float w00 = weight(v00, l0[tx.i0], (1 - ty.w) * (1 - tx.w));
        const float w01 = weight(v01, l0[tx.i1], (1 - ty.w) * tx.w);
        const float w10 = weight(v10, l1[tx.i0], ty.w * (1 - tx.w));
        const float w11 = weight(v11, l1[tx.i1], ty.w * tx.w);
        const float weights = w00 + w01 + w10 + w11;
        const float sum = (w00 > 0 ? w00 * v00 : 0.f) + (w01 > 0 ? w01 * v01 : 0.f) + (w10 > 0 ? w10 * v10 : 0.f) +
                          (w11 > 0 ? w11 * v11 : 0.f);
        dst[x] = weights > 0 ? sum / weights * scale : unknown;
      }
    }
  });
}

struct Range {
  int min_d = 0, num_d = 16;
};

// A disparity range as shares of the width: low (behind the screen, negative) to high.
struct DisparityShares {
  double low = 0, high = 0;
};

// The range probe runs again after this many frames of one shot, so that what comes into the
// picture beyond the tracked range is found within half a second.
constexpr int reprobe_frames = 12;

// The 1st and 99th percentiles of the matched disparities of `d` (of every `step`-th pixel of every
// `step`-th row), as shares of `width`; nothing when fewer than `min_share` of them matched.
std::optional<DisparityShares> percentiles(const cv::Mat& d, int width, double min_share, int step = 1) {
  std::vector<float> found;
  std::size_t seen = 0;
  found.reserve(d.total() / static_cast<std::size_t>(step * step) + 1);
  for (int y = 0; y < d.rows; y += step) {
    const auto* row = d.ptr<float>(y);
    for (int x = 0; x < d.cols; x += step, ++seen)
      if (!std::isnan(row[x])) found.push_back(row[x]);
  }
  if (found.empty() || static_cast<double>(found.size()) < min_share * static_cast<double>(seen)) return std::nullopt;
  const auto quantile = [&](double q) {
    auto at = found.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(found.size() - 1));
    std::nth_element(found.begin(), at, found.end());
    return static_cast<double>(*at) / width;
  };
  return DisparityShares{quantile(0.01), quantile(0.99)};
}

// Whether the matched disparities of `d` keep off the ends of the search `range`: at most 1 % of
// them within a pixel of either end.
bool within_range(const cv::Mat& d, const Range& range) {
  const float low = static_cast<float>(range.min_d) + 1.f, high = static_cast<float>(range.min_d + range.num_d) - 2.f;
  std::size_t matched = 0, at_ends = 0;
  for (int y = 0; y < d.rows; ++y) {
    const auto* row = d.ptr<float>(y);
    for (int x = 0; x < d.cols; ++x)
      if (!std::isnan(row[x])) {
        ++matched;
        at_ends += row[x] <= low || row[x] >= high;
      }
  }
  return at_ends * 100 <= matched;
}

double mean_change(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat change;
  cv::absdiff(a, b, change);
  return cv::mean(change)[0];
}

}  // namespace

struct StereoMatcher::State {
  // The left view's matcher (also the range probe's) and the right view's: both run at once.
  cv::Ptr<cv::StereoBM> bm = cv::StereoBM::create(16, 9);
  cv::Ptr<cv::StereoBM> bm_right = cv::StereoBM::create(16, 9);
  // The previous frame at the working resolution: views and cross-checked, tempered maps.
  cv::Mat left_gray, right_gray, left_d, right_d;
  // The range the next frame of the shot starts from, and the frames since the last probe.
  std::optional<DisparityShares> tracked;
  int frames_since_probe = 0;
  double matched_at_probe = 0;  // the share of the view the estimate matched on the probed frame
  // The 960×540 maps handed out, written again once no frame holds them.
  ReusableDisparityMaps maps;
};

StereoMatcher::StereoMatcher(StereoMatcherSettings settings) : settings_(settings), state_(std::make_unique<State>()) {
  const int threads =
      settings_.threads > 0 ? settings_.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  cv::setNumThreads(threads);
  for (cv::StereoBM* bm : {state_->bm.get(), state_->bm_right.get()}) {
    bm->setPreFilterCap(31);
    bm->setTextureThreshold(10);
    bm->setUniquenessRatio(10);
    bm->setSpeckleRange(32);  // 1/16 pixel: 2 pixels
  }
}

StereoMatcher::~StereoMatcher() = default;

void StereoMatcher::reset() {
  auto& s = *state_;
  s.left_gray = s.right_gray = s.left_d = s.right_d = cv::Mat();
  s.tracked.reset();
}

std::shared_ptr<const StereoDisparity> StereoMatcher::estimate(const StereoVideoFrame& frame) {
  const int bx = std::max(1, frame.block[0]), by = std::max(1, frame.block[1]);
  const int pw = frame.width / bx, ph = frame.height / by;
  const std::size_t bytes = static_cast<std::size_t>(pw) * static_cast<std::size_t>(ph) * bytes_per_pixel(frame.bits);
  if (frame.left.size() != bytes || frame.right.size() != bytes)
    throw std::invalid_argument("StereoMatcher: the frame's views do not hold its pixels");
  if (pw < smallest_view || ph < smallest_view) return nullptr;
  auto& s = *state_;

  // The guide (the maps' resolution): the views' luma at up to output_scale × the largest working
  // width, reduced by whole blocks straight from the frame's bytes.
  const int k = std::max(1, pw / (settings_.output_scale * settings_.max_working_width));
  const cv::Mat left_guide = luma_block_means(frame.left, frame.bits, pw, ph, k);
  const cv::Mat right_guide = luma_block_means(frame.right, frame.bits, pw, ph, k);
  const int gw = left_guide.cols, gh = left_guide.rows;
  const auto height_at = [&](int width) {
    return std::max(1, static_cast<int>(std::lround(static_cast<double>(width) * gh / gw)));
  };

  // The disparity range, as shares of the width: the 1st and 99th percentiles of the disparities
  // found, widened by the probe's error. While a video goes on (no cut since the last frame, whose
  // estimate kept inside its range, and fewer than reprobe_frames since the last probe) it is the
  // last estimate's own, which saves the probe; otherwise a wide search at a coarse resolution
  // finds it: from 1/4 of the width behind the screen to 1/2 in front.
  const int wp = std::min(probe_width, gw), hp = height_at(wp);
  auto& bm = *s.bm;
  DisparityShares shares;
  const auto range_at = [&](int width) {
    const int margin = 2 + (3 * width + wp - 1) / wp;  // the probe's error, at this width
    Range r;
    r.min_d = static_cast<int>(std::floor(shares.low * width)) - margin;
    r.num_d = round_up_16(static_cast<int>(std::ceil(shares.high * width)) + margin - r.min_d);
    return r;
  };
  // The working views: the largest width whose search over the range fits the cost budget.
  int wk = 0, hk = 0;
  cv::Mat left_gray, right_gray;
  const auto make_working_views = [&] {
    wk = std::max(std::min(settings_.max_working_width, gw), std::min(settings_.min_working_width, gw));
    while (wk > std::min(settings_.min_working_width, gw) &&
           static_cast<double>(wk) * height_at(wk) * range_at(wk).num_d > settings_.cost_budget)
      wk -= 16;
    hk = height_at(wk);
    left_gray = area_resize(left_guide, wk, hk);
    right_gray = area_resize(right_guide, wk, hk);
  };
  // The same shot as the last frame, at the same working size: no mean change of a scene cut (12
  // levels of 255).
  const auto same_shot = [&] {
    return settings_.temporal_weight > 0 && left_gray.size() == s.left_gray.size() &&
           mean_change(left_gray, s.left_gray) < 12;
  };
  bool goes_on = false;
  if (settings_.temporal_weight > 0 && s.tracked && s.frames_since_probe < reprobe_frames) {
    shares = *s.tracked;
    make_working_views();
    goes_on = same_shot();
  }
  if (!goes_on) {
    const cv::Mat left_probe = area_resize(left_guide, wp, hp), right_probe = area_resize(right_guide, wp, hp);
    bm.setBlockSize(7);
    bm.setSpeckleWindowSize(wp * hp / 1000);
    const int probe_min = -round_up_16(wp / 4);
    const auto found = percentiles(block_match(bm, left_probe, right_probe, probe_min, round_up_16(wp / 2) - probe_min),
                                   wp, settings_.min_matched_share);
    if (!found) {
      reset();
      return nullptr;
    }
    shares = *found;
    s.frames_since_probe = 0;
    make_working_views();
    goes_on = same_shot();
  }
  ++s.frames_since_probe;
  const Range range = range_at(wk);

  // Both directions at once, each on its own matcher and core: a match's prefiltering and speckle
  // filtering run on one core, so two matches side by side take half the time of two matches each
  // spread over both cores (OpenCV runs a parallel_for_ within another on the calling thread; the
  // maps are the same to the bit).
  cv::Mat left_d, right_d;
  for (cv::StereoBM* m : {s.bm.get(), s.bm_right.get()}) {
    m->setBlockSize(wk >= 320 ? 9 : 7);
    m->setSpeckleWindowSize(wk * hk / 1000);
  }
  cv::parallel_for_(
      cv::Range(0, 2),
      [&](const cv::Range& directions) {
        for (int i = directions.start; i < directions.end; ++i) {
          if (i == 0)
            left_d = block_match(bm, left_gray, right_gray, range.min_d, range.num_d);
          else
            right_d = block_match_right(*s.bm_right, left_gray, right_gray, range.min_d, range.num_d);
        }
      },
      2);
  cross_check(left_d, right_d, 1.f);
  const double matched = matched_share(left_d);
  if (matched < settings_.min_matched_share || matched_share(right_d) < settings_.min_matched_share) {
    reset();
    return nullptr;
  }

  // The range the next frame starts from: this estimate's own, unless it pressed on the ends of the
  // search or matched markedly less of the view than the probed frame did (something may lie beyond
  // the range: the next frame probes again).
  if (s.frames_since_probe == 1) s.matched_at_probe = matched;
  s.tracked = settings_.temporal_weight > 0 && within_range(left_d, range) && matched >= 0.9 * s.matched_at_probe
                  ? percentiles(left_d, wk, settings_.min_matched_share, 4)
                  : std::nullopt;
  if (goes_on) {
    const auto w = static_cast<float>(settings_.temporal_weight);
    temper(left_d, left_gray, s.left_d, s.left_gray, w);
    temper(right_d, right_gray, s.right_d, s.right_gray, w);
  }
  s.left_gray = left_gray;
  s.right_gray = right_gray;
  s.left_d = left_d;
  s.right_d = right_d;

  std::shared_ptr<StereoDisparity> result = s.maps.next();
  result->origin = DisparityOrigin::estimated;
  upsample(left_d, left_gray, left_guide, result->left);
  upsample(right_d, right_gray, right_guide, result->right);
  return result;
}

std::shared_ptr<const StereoDisparity> estimate_still_disparity(const StereoPair& views) {
  const Image& l = views.left.image;
  const Image& r = views.right.image;
  if (l.width() != r.width() || l.height() != r.height()) return nullptr;
  StereoVideoFrame frame;
  frame.width = l.width();
  frame.height = l.height();
  frame.bits = 16;
  frame.left = view_bytes(l, 16);
  frame.right = view_bytes(r, 16);
  frame.aspect = views.left.aspect();
  // A still is matched once, at the largest working width whatever its disparity range: the cost
  // budget is what keeps a video frame within its time, and a plane close to the eye matched
  // coarser costs the retina most of a decibel on the finer displays (docs/depth.md).
  StereoMatcherSettings settings;
  settings.cost_budget = std::numeric_limits<double>::infinity();
  return StereoMatcher(settings).estimate(frame);
}

}  // namespace nelf
