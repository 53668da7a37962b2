#pragma once
// The quality reference of DESIGN.md §4: a CPU compositor in double precision that averages
// N×N stratified sub-samples over each display pixel's aperture (each sub-sample uses the lens that
// owns its position), each a bilinear tap on the full-resolution view. Slow by design; it is the
// oracle the GL path is tested against.
#include <array>
#include <memory>

#include "compositor/compositor.hpp"
#include "optics/depth.hpp"
#include "optics/mapping.hpp"

namespace nelf {

// Bilinear sample of `image` at texture coordinate (u, t) in [0,1] (texel centres at (i+½)/W),
// clamped to the edge.
Rgba sample_bilinear(const Image& image, double u, double t);

// One eye's image: `subsamples` per axis (16 for the reference; fewer for quick checks).
Image reference_eye_image(const EyeMapping& mapping, const Image& view, int subsamples = 16);

// The depth-aware reference: each sub-sample shows the view where its chief ray meets `surface`
// (optics/depth.hpp) under `geometry`, black off the screen. A flat surface gives reference_eye_image.
Image reference_eye_image(const EyeMapping& mapping, const Image& view, const DisparitySurface& surface,
                          const DepthGeometry& geometry, int subsamples = 16);

class ReferenceCompositor final : public Compositor {
 public:
  explicit ReferenceCompositor(Profile profile, int subsamples = 16)
      : profile_(std::move(profile)), subsamples_(subsamples) {}
  EyeImages compose(const StereoPair& views) override;
  void set_depth(Eye eye, std::shared_ptr<const DisparitySurface> surface) override {
    surfaces_[static_cast<int>(eye)] = std::move(surface);
  }

 private:
  Profile profile_;
  int subsamples_;
  std::array<std::shared_ptr<const DisparitySurface>, 2> surfaces_;
};

}  // namespace nelf
