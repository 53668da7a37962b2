// The per-frame half of the defect compensation (optics/defect_compensation.hpp): each defect's
// shortfall or excess is read off the composited image, then its shares are added to the healthy
// pixels of its bundle. The planning half is optics/defect_compensation.cpp.
#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

#include "optics/defect_compensation.hpp"

namespace nelf {

namespace {

using Rgb = std::array<float, 3>;

// The corrections a frame adds, summed per pixel: a pixel several defects share with takes their
// shares together and is clipped once, whatever the order of the defects. An open-addressing table
// keyed by where the pixel is, sized for the plan's shares (a few thousand: far cheaper per frame
// than touching a panel-sized buffer), and kept per thread from frame to frame: only the slots a
// frame used are emptied for the next.
class ShareSums {
 public:
  // Empty, with room for `shares`.
  void reset(std::size_t shares) {
    const std::size_t slots = std::bit_ceil(std::max<std::size_t>(16, shares * 2));
    if (slots != keys_.size()) {
      mask_ = slots - 1;
      keys_.assign(slots, empty_key);
      sums_.resize(slots);
    } else {
      for (std::size_t slot : touched_) keys_[slot] = empty_key;
    }
    touched_.clear();
    touched_.reserve(shares);
  }

  void add(std::size_t pixel, float weight, const Rgb& difference) {
    std::size_t slot = ((pixel * 0x9E3779B97F4A7C15ull) >> 20) & mask_;
    while (keys_[slot] != pixel) {
      if (keys_[slot] == empty_key) {
        keys_[slot] = pixel;
        sums_[slot] = {0.f, 0.f, 0.f};
        touched_.push_back(slot);
        break;
      }
      slot = (slot + 1) & mask_;
    }
    for (int c = 0; c < 3; ++c) sums_[slot][c] += weight * difference[c];
  }

  // Each pixel that takes shares, once, with the sum of its shares.
  template <class Visit>
  void for_each(Visit&& visit) const {
    for (std::size_t slot : touched_) visit(keys_[slot], sums_[slot]);
  }

 private:
  static constexpr std::size_t empty_key = ~std::size_t{0};
  std::size_t mask_ = 0;
  std::vector<std::size_t> keys_;
  std::vector<Rgb> sums_;
  std::vector<std::size_t> touched_;
};

bool inside(const std::array<int, 2>& panel, int x, int y) { return x >= 0 && y >= 0 && x < panel[0] && y < panel[1]; }

// What the defect shows whatever it is sent, on the 0..1 scale the images use.
Rgb shown(const PixelDefect& defect) {
  const auto rgb = defect.shown_rgb();
  return {rgb[0] / 255.f, rgb[1] / 255.f, rgb[2] / 255.f};
}

// The shares of every correction, from `read(x, y)` (0..1 per channel, the image as given),
// summed per `key(x, y)` (where the pixel is: an index, or a byte offset).
template <class Read, class Key>
const ShareSums& sum_shares(const EyeDefectPlan& plan, Read&& read, Key&& key) {
  std::size_t shares = 0;
  for (const auto& correction : plan.corrections) shares += correction.shares.size();
  thread_local ShareSums sums;
  sums.reset(shares);
  for (const auto& correction : plan.corrections) {
    const PixelDefect& defect = correction.defect;
    if (correction.shares.empty() || !inside(plan.panel, defect.x, defect.y)) continue;
    const Rgb sent = read(defect.x, defect.y);
    const Rgb seen = shown(defect);
    const Rgb difference{sent[0] - seen[0], sent[1] - seen[1], sent[2] - seen[2]};
    if (difference[0] == 0.f && difference[1] == 0.f && difference[2] == 0.f) continue;
    for (const auto& share : correction.shares)
      if (inside(plan.panel, share.x, share.y)) sums.add(key(share.x, share.y), share.weight, difference);
  }
  return sums;
}

template <class Channel>
void compensate_channels(const EyeDefectPlan& plan, std::uint8_t* rgba, std::size_t row_bytes) {
  constexpr float full = static_cast<float>(std::numeric_limits<Channel>::max());
  const auto offset = [&](int x, int y) {
    return static_cast<std::size_t>(y) * row_bytes + static_cast<std::size_t>(x) * 4 * sizeof(Channel);
  };
  const auto read = [&](int x, int y) {
    Channel channels[3];
    std::memcpy(channels, rgba + offset(x, y), sizeof(channels));
    return Rgb{channels[0] / full, channels[1] / full, channels[2] / full};
  };
  const ShareSums& sums = sum_shares(plan, read, offset);
  sums.for_each([&](std::size_t at, const Rgb& sum) {
    Channel channels[3];
    std::memcpy(channels, rgba + at, sizeof(channels));
    // Clipped to 0..1 first, so + 0.5 rounds to nearest.
    for (int c = 0; c < 3; ++c)
      channels[c] = static_cast<Channel>(std::clamp(channels[c] / full + sum[c], 0.f, 1.f) * full + 0.5f);
    std::memcpy(rgba + at, channels, sizeof(channels));
  });
}

}  // namespace

void compensate_defects(const EyeDefectPlan& plan, Image& eye) {
  if (plan.empty()) return;
  if (eye.width() != plan.panel[0] || eye.height() != plan.panel[1])
    throw std::invalid_argument(fmt::format("compensate_defects: a plan for a {}x{} panel given a {}x{} image",
                                            plan.panel[0], plan.panel[1], eye.width(), eye.height()));
  const auto index = [&](int x, int y) {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(eye.width()) + static_cast<std::size_t>(x);
  };
  const ShareSums& sums = sum_shares(
      plan,
      [&](int x, int y) {
        const Rgba& p = eye.at(x, y);
        return Rgb{p.r, p.g, p.b};
      },
      index);
  auto& pixels = eye.pixels();
  sums.for_each([&](std::size_t pixel, const Rgb& sum) {
    Rgba& p = pixels[pixel];
    p.r = std::clamp(p.r + sum[0], 0.f, 1.f);
    p.g = std::clamp(p.g + sum[1], 0.f, 1.f);
    p.b = std::clamp(p.b + sum[2], 0.f, 1.f);
  });
}

void compensate_defects(const EyeDefectPlan& plan, std::uint8_t* rgba, int bits, std::size_t row_bytes) {
  if (plan.empty()) return;
  if (bits == 8)
    compensate_channels<std::uint8_t>(plan, rgba, row_bytes);
  else if (bits == 16)
    compensate_channels<std::uint16_t>(plan, rgba, row_bytes);
  else
    throw std::invalid_argument(fmt::format("compensate_defects: {} bits a channel (8 or 16)", bits));
}

void show_defects(const DefectMap& map, Eye eye, Image& eye_image) {
  const std::array<int, 2> size{eye_image.width(), eye_image.height()};
  for (const auto& defect : map.defects) {
    if (defect.eye != eye || !inside(size, defect.x, defect.y)) continue;
    const Rgb rgb = shown(defect);
    Rgba& p = eye_image.at(defect.x, defect.y);
    p.r = rgb[0];
    p.g = rgb[1];
    p.b = rgb[2];
  }
}

}  // namespace nelf
