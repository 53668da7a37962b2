#pragma once
// A plain RGBA image in floating point (0..1, the source's own transfer curve), row 0 at the top.
// This is the currency between the stages for stills and tests; video frames use GPU textures.
#include <array>
#include <cstddef>
#include <stdexcept>
#include <vector>

namespace nelf {

struct Rgba {
  float r = 0.f, g = 0.f, b = 0.f, a = 1.f;
};

class Image {
 public:
  Image() = default;
  Image(int width, int height) : width_(width), height_(height) {
    if (width < 0 || height < 0) throw std::invalid_argument("Image: negative size");
    pixels_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), Rgba{0, 0, 0, 1});
  }

  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return pixels_.empty(); }

  Rgba& at(int x, int y) { return pixels_[index(x, y)]; }
  const Rgba& at(int x, int y) const { return pixels_[index(x, y)]; }

  float* data() { return &pixels_.data()->r; }
  const float* data() const { return &pixels_.data()->r; }
  std::vector<Rgba>& pixels() { return pixels_; }
  const std::vector<Rgba>& pixels() const { return pixels_; }

 private:
  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
  }
  int width_ = 0;
  int height_ = 0;
  std::vector<Rgba> pixels_;
};

static_assert(sizeof(Rgba) == 4 * sizeof(float), "Rgba must be tightly packed for GL uploads");

// One view of a stereo pair plus the aspect ratio it must be displayed at (width/height after
// undoing anamorphic squeeze, e.g. 16/9 for a half side-by-side 960x1080 view).
struct View {
  Image image;
  double display_aspect = 0.0;  // 0 = image width / height
  double aspect() const {
    return display_aspect > 0.0 ? display_aspect
                                : static_cast<double>(image.width()) / static_cast<double>(image.height());
  }
};

struct StereoPair {
  View left;
  View right;
};

// The two eyes' images, indexed by Eye (optics/profile.hpp).
using EyeImages = std::array<Image, 2>;

}  // namespace nelf
