#pragma once
// The defect compensation (optics/defect_compensation.hpp) on a frame GL has drawn into a display's
// packed frame, on the GPU, so that the frame is not read back. Two passes of points per eye: one
// per defect reads what it was sent off the frame's texture, less what it shows, into a small float
// texture; one per pixel taking shares sums its shares from there and adds the sum with blending
// (the positive part added, the negative part subtracted, as a unorm framebuffer takes only 0..1),
// so that, as on the CPU, every share is worked out from the frame as drawn and a pixel several
// defects share with is clipped once.
#include <array>
#include <memory>
#include <optional>
#include <utility>

#include "compositor/cpu/composite_ahead.hpp"
#include "core/gl/objects.hpp"
#include "core/packed_target.hpp"
#include "optics/defect_compensation.hpp"

namespace nelf {

class GlDefectCompensation {
 public:
  // Compiles its programs: the context must be current (and stay so for apply and destruction).
  GlDefectCompensation();

  // Each eye's plan (RGBA) applied to its panel of `target`, whose top-left corner is origins[e].
  // The plans' buffers are made once per plan. Leaves blending off.
  void apply(const EyeDefectPlans& plans, const std::array<std::optional<std::pair<int, int>>, 2>& origins,
             const GlPackedTarget& target);

 private:
  // One plan as GL buffers: its defects, the pixels taking shares with where their shares start,
  // the shares, and the texture (and framebuffer) pass 1 writes the defects' differences into.
  struct EyeBuffers {
    std::shared_ptr<const EyeDefectPlan> made_for;
    gl::Buffer defects, pixels, shares;
    int defect_count = 0, pixel_count = 0;
    // The pixels are listed adding only, then both, then subtracting only: how many of the first
    // and the last.
    int adding_only = 0, subtracting_only = 0;
    std::array<int, 2> slots{0, 0};
    gl::Texture differences;
    gl::Framebuffer differences_fbo;
  };
  void prepare(EyeBuffers& eye, const std::shared_ptr<const EyeDefectPlan>& plan);

  gl::Program gather_, apply_;
  gl::VertexArray vertex_array_;
  std::array<EyeBuffers, 2> eyes_;
};

}  // namespace nelf
