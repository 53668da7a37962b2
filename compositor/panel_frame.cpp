#include "compositor/panel_frame.hpp"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "core/gl/objects.hpp"

namespace nelf {

namespace {

// As lround(clamp(v) * 255) (v is never negative after the clamp), without the library call: ~7.5
// million of them a frame.
std::uint8_t to_byte(float v) { return static_cast<std::uint8_t>(std::clamp(v, 0.f, 1.f) * 255.f + 0.5f); }

// The packed frame as 8-bit bytes, RGBA or (for a GL texture's upload, a copy there) BGRA: the eyes
// placed and clipped as place_eyes places them, opaque black elsewhere. Written straight from the
// panels rather than through place_eyes' float frame (four times the bytes) on every key.
std::vector<std::uint8_t> packed_bytes(const PackedLayout& layout, const EyeImages& panels, bool bgra) {
  for (const Image& eye : panels)
    if (eye.width() != layout.eye[0] || eye.height() != layout.eye[1])
      throw std::invalid_argument(fmt::format("a {}x{} panel image for a layout of {}x{} panels", eye.width(),
                                              eye.height(), layout.eye[0], layout.eye[1]));
  const std::size_t width = static_cast<std::size_t>(layout.packed[0]);
  std::vector<std::uint8_t> bytes(width * static_cast<std::size_t>(layout.packed[1]) * 4, 0);
  for (std::size_t i = 3; i < bytes.size(); i += 4) bytes[i] = 255;
  for (std::size_t e = 0; e < 2; ++e) {
    if (!layout.areas[e]) continue;
    const EyeArea& area = *layout.areas[e];
    const Image& eye = panels[e];
    const int dx = layout.origins[e]->first - area.x, dy = layout.origins[e]->second - area.y;
    const int x_begin = std::max(0, dx), x_end = std::min(area.width, dx + eye.width());
    const int y_begin = std::max(0, dy), y_end = std::min(area.height, dy + eye.height());
    for (int y = y_begin; y < y_end; ++y) {
      const Rgba* src = &eye.at(x_begin - dx, y - dy);
      std::uint8_t* out = &bytes[(static_cast<std::size_t>(area.y + y) * width + area.x + x_begin) * 4];
      for (int x = x_begin; x < x_end; ++x, ++src, out += 4) {
        out[0] = to_byte(bgra ? src->b : src->r);
        out[1] = to_byte(src->g);
        out[2] = to_byte(bgra ? src->r : src->b);
        out[3] = to_byte(src->a);
      }
    }
  }
  return bytes;
}

}  // namespace

void render_panel_frame(const PackedLayout& layout, const EyeImages& panels, const PackedTarget& target) {
  if (const auto* gl_target = std::get_if<GlPackedTarget>(&target.where)) {
    if (gl_target->size != layout.packed)
      throw std::invalid_argument(fmt::format("a {}x{} packed target for a layout of {}x{}", gl_target->size[0],
                                              gl_target->size[1], layout.packed[0], layout.packed[1]));
    const std::vector<std::uint8_t> bgra = packed_bytes(layout, panels, true);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(gl_target->texture, 0, 0, 0, gl_target->size[0], gl_target->size[1], GL_BGRA, GL_UNSIGNED_BYTE,
                        bgra.data());
    gl::check_error("uploading the panel frame");
    return;
  }
  PackedFrame& out = *std::get<PackedFrame*>(target.where);
  out.rgba = packed_bytes(layout, panels, false);
  out.width = layout.packed[0];
  out.height = layout.packed[1];
  out.bits = 8;
  out.pts_seconds = 0.0;
}

}  // namespace nelf
