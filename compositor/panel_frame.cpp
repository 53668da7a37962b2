#include "compositor/panel_frame.hpp"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "core/gl/objects.hpp"

namespace nelf {

namespace {

std::uint8_t to_byte(float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.f, 1.f) * 255.f)); }

// The placed frame as 8-bit bytes, in RGBA or (for a GL texture's upload, a copy there) BGRA order.
std::vector<std::uint8_t> packed_bytes(const Image& packed, bool bgra) {
  std::vector<std::uint8_t> bytes(packed.pixels().size() * 4);
  std::size_t i = 0;
  for (const Rgba& p : packed.pixels()) {
    bytes[i + 0] = to_byte(bgra ? p.b : p.r);
    bytes[i + 1] = to_byte(p.g);
    bytes[i + 2] = to_byte(bgra ? p.r : p.b);
    bytes[i + 3] = to_byte(p.a);
    i += 4;
  }
  return bytes;
}

}  // namespace

void render_panel_frame(const PackedLayout& layout, const EyeImages& panels, const PackedTarget& target) {
  const Image packed = place_eyes(layout, panels);  // std::invalid_argument for a panel of another size
  if (const auto* gl_target = std::get_if<GlPackedTarget>(&target.where)) {
    if (gl_target->size != layout.packed)
      throw std::invalid_argument(fmt::format("a {}x{} packed target for a layout of {}x{}", gl_target->size[0],
                                              gl_target->size[1], layout.packed[0], layout.packed[1]));
    const std::vector<std::uint8_t> bgra = packed_bytes(packed, true);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(gl_target->texture, 0, 0, 0, gl_target->size[0], gl_target->size[1], GL_BGRA, GL_UNSIGNED_BYTE,
                        bgra.data());
    gl::check_error("uploading the panel frame");
    return;
  }
  PackedFrame& out = *std::get<PackedFrame*>(target.where);
  out.width = layout.packed[0];
  out.height = layout.packed[1];
  out.bits = 8;
  out.pts_seconds = 0.0;
  out.rgba = packed_bytes(packed, false);
}

}  // namespace nelf
