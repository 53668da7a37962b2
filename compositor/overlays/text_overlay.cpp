#include "compositor/overlays/text_overlay.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "compositor/gl/shader_interface.hpp"
#include "compositor/gl/shader_programs.hpp"
#include "core/chart_style.hpp"
#include "core/gl/egl_context.hpp"
#include "core/image_library.hpp"

namespace nelf {

namespace {

// The font size in view texels, relative to the view's height: the same apparent size at any source
// resolution.
constexpr double kFontPerViewHeight = 1.0 / 16.0;
constexpr int kMinimumFontPx = 8;
constexpr double kMaximumWidthFraction = 0.9;  // of the view's width
constexpr double kBoxCentreFromTop = 0.75;     // lower third
constexpr float kBoxOpacity = 0.6f;
constexpr int kBarLengthInFonts = 12;
constexpr float kBarRestGrey = 0.35f;

// Formats the output can keep; anything else (sRGB, RGB without alpha, integer) becomes RGBA16F.
GLenum output_format(GLenum view_format) {
  switch (view_format) {
    case GL_RGBA8:
    case GL_RGBA16:
    case GL_RGBA16F:
    case GL_RGBA32F:
    case GL_RGB10_A2:
      return view_format;
    default:
      return GL_RGBA16F;
  }
}

gl::Program make_text_program() {
  const shaders::ProgramSource source = shaders::program_source(shaders::ProgramKind::text_overlay, 1);
  return gl::make_program(source.vertex, source.fragment, source.defines);
}

// Displayed width of one view texel relative to its height (1 for square pixels).
double pixel_aspect(const GlTextureView& view) { return view.aspect() * view.height / static_cast<double>(view.width); }

}  // namespace

TextOverlay::TextOverlay()
    : program_(make_text_program()),
      vertex_array_(gl::make_vertex_array()),
      sampler_(gl::make_linear_clamp_sampler()) {}

TextOverlay::~TextOverlay() = default;

void TextOverlay::set_text(std::string text) { text_ = std::move(text); }
void TextOverlay::set_bar(double fraction) { bar_ = fraction < 0.0 ? -1.0 : std::min(fraction, 1.0); }

const TextOverlay::Label& TextOverlay::cpu_label(int font_px) {
  if (!label_.rgba.empty() && label_.text == text_ && label_.bar == bar_ && label_.font_px == font_px) return label_;
  const std::string font = chart::font();
  const auto extent = image_library::text_size(text_, font_px, font);
  if (!extent)
    throw std::runtime_error(
        fmt::format("cannot render the on-screen text with font {} (install fonts-dejavu-core)", font));
  // A fixed line height from the font size, so that the box does not jump as descenders come and go.
  const int pad = std::max(2, font_px / 3);
  const int ascent = std::max(static_cast<int>(std::lround(0.95 * font_px)), -extent->y_begin);
  const int descent = std::max(static_cast<int>(std::lround(0.25 * font_px)), extent->y_end);
  // The seek bar: a line under the text, long enough to point at a place (12 font sizes), as thick as
  // a stroke of a capital letter is tall at a third of it, so that it survives the scaling down into
  // a preview window as the text does.
  const bool bar = bar_ >= 0.0;
  const int bar_width = bar ? kBarLengthInFonts * font_px : 0;
  const int bar_height = bar ? std::max(3, font_px / 3) : 0;
  const int text_height = ascent + descent;
  const int width = std::max(extent->width(), bar_width) + 2 * pad;
  const int height = text_height + 2 * pad + (bar ? bar_height + pad : 0);

  // White text on a translucent black box, drawn as float and stored as RGBA8.
  std::vector<float> image(static_cast<std::size_t>(width) * height * 4);
  for (std::size_t i = 0; i < image.size(); i += 4) image[i + 3] = kBoxOpacity;
  const float white[4] = {1.f, 1.f, 1.f, 1.f};
  try {
    image_library::render_text({.values = image.data(), .width = width, .height = height, .channels = 4},
                               (width - extent->width()) / 2 - extent->x_begin, pad + ascent, text_, font_px, font,
                               white);
  } catch (const image_library::ImageLibraryError& e) {
    throw std::runtime_error(fmt::format("cannot render the on-screen text: {}", e.what()));
  }
  if (bar) {
    // Played: white; still to come: grey; both opaque so that the place reads against any picture.
    const int x0 = (width - bar_width) / 2, y0 = pad + text_height + pad / 2;
    const int filled = static_cast<int>(std::lround(bar_ * bar_width));
    for (int y = y0; y < y0 + bar_height && y < height; ++y)
      for (int x = x0; x < x0 + bar_width; ++x) {
        float* p = &image[(static_cast<std::size_t>(y) * width + x) * 4];
        const float v = x - x0 < filled ? 1.f : kBarRestGrey;
        p[0] = p[1] = p[2] = v;
        p[3] = 1.f;
      }
  }
  label_.rgba.resize(image.size());
  for (std::size_t i = 0; i < image.size(); ++i)
    label_.rgba[i] = static_cast<std::uint8_t>(std::lround(std::clamp(image[i], 0.f, 1.f) * 255.f));
  label_.texture.reset();  // for the old text
  label_.text = text_;
  label_.bar = bar_;
  label_.font_px = font_px;
  label_.width = width;
  label_.height = height;
  return label_;
}

const TextOverlay::Label& TextOverlay::label(int font_px) {
  const Label& made = cpu_label(font_px);
  if (made.texture) return made;
  label_.texture = gl::make_texture_2d(GL_RGBA8, made.width, made.height);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(label_.texture.id(), 0, 0, 0, made.width, made.height, GL_RGBA, GL_UNSIGNED_BYTE,
                      made.rgba.data());
  gl::check_error("uploading the on-screen text");
  return label_;
}

TextOverlay::Placement TextOverlay::place(int width, int height, double aspect) {
  // Size: from the view's height; smaller when the line would not fit the width.
  int font_px = std::max(kMinimumFontPx, static_cast<int>(std::lround(height * kFontPerViewHeight)));
  const Label* text = &cpu_label(font_px);
  const double widest = kMaximumWidthFraction * width * aspect;  // in square (label) pixels
  if (text->width > widest) {
    font_px = std::max(kMinimumFontPx, static_cast<int>(std::floor(font_px * widest / text->width)));
    text = &cpu_label(font_px);
  }
  Box box;
  box.width = std::min(width, std::max(1, static_cast<int>(std::lround(text->width / aspect))));
  box.height = std::min(height, text->height);
  box.x = (width - box.width) / 2;
  box.y =
      std::clamp(static_cast<int>(std::lround(kBoxCentreFromTop * height - box.height / 2.0)), 0, height - box.height);
  return {font_px, box};
}

Image TextOverlay::cover(int width, int height, double aspect) {
  if (text_.empty() || width <= 0 || height <= 0) return Image();
  const Placement at = place(width, height, pixel_aspect(GlTextureView{0, width, height, aspect}));
  const Label& text = cpu_label(at.font_px);
  Image out(width, height);
  std::fill_n(out.data(), static_cast<std::size_t>(width) * height * 4, 0.f);  // transparent outside the box
  // text_overlay.frag's texture() of the label at each box texel's centre: bilinear, clamped to
  // the edge, from the label's 8-bit values.
  const auto texel = [&](int x, int y, int c) {
    x = std::clamp(x, 0, text.width - 1);
    y = std::clamp(y, 0, text.height - 1);
    return text.rgba[(static_cast<std::size_t>(y) * text.width + x) * 4 + c] / 255.f;
  };
  for (int y = 0; y < at.box.height; ++y)
    for (int x = 0; x < at.box.width; ++x) {
      const float u = (x + 0.5f) / at.box.width * text.width - 0.5f;
      const float v = (y + 0.5f) / at.box.height * text.height - 0.5f;
      const int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
      const float fx = u - x0, fy = v - y0;
      float value[4];
      for (int c = 0; c < 4; ++c)
        value[c] = (texel(x0, y0, c) * (1 - fx) + texel(x0 + 1, y0, c) * fx) * (1 - fy) +
                   (texel(x0, y0 + 1, c) * (1 - fx) + texel(x0 + 1, y0 + 1, c) * fx) * fy;
      out.at(at.box.x + x, at.box.y + y) = Rgba{value[0], value[1], value[2], value[3]};
    }
  return out;
}

Image TextOverlay::label_image(int font_px) {
  if (text_.empty()) return Image();
  const Label& text = cpu_label(font_px);
  Image out(text.width, text.height);
  for (std::size_t i = 0; i < text.rgba.size(); ++i) out.data()[i] = text.rgba[i] / 255.f;
  return out;
}

GlTextureView TextOverlay::apply(Eye eye, const GlTextureView& view) {
  EyeTarget& target = eyes_[static_cast<int>(eye)];
  target.box = {};
  if (text_.empty() || view.width <= 0 || view.height <= 0) return view;

  GLint view_format = 0;
  glGetTextureLevelParameteriv(view.texture, 0, GL_TEXTURE_INTERNAL_FORMAT, &view_format);
  const GLenum format = output_format(static_cast<GLenum>(view_format));
  if (!target.texture || target.width != view.width || target.height != view.height || target.format != format) {
    target.fbo.reset();
    target.texture = gl::make_texture_2d(format, view.width, view.height);
    target.fbo = gl::make_framebuffer(target.texture);
    target.width = view.width;
    target.height = view.height;
    target.format = format;
  }

  const Placement at = place(view.width, view.height, pixel_aspect(view));
  const Label* text = &label(at.font_px);
  const Box box = at.box;

  glBindFramebuffer(GL_FRAMEBUFFER, target.fbo.id());
  if (format == static_cast<GLenum>(view_format)) {
    // Same format: copy the view as it is (a memory copy, several times cheaper than a full-view
    // pass on llvmpipe) and draw only the box; the shader addresses texels by window position, so a
    // viewport on the box is all it needs.
    glCopyImageSubData(view.texture, GL_TEXTURE_2D, 0, 0, 0, 0, target.texture.id(), GL_TEXTURE_2D, 0, 0, 0, 0,
                       view.width, view.height, 1);
    glViewport(box.x, box.y, box.width, box.height);
  } else {
    glViewport(0, 0, view.width, view.height);  // converts the whole view to the output's format
  }
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_BLEND);
  glUseProgram(program_.id());
  glProgramUniform2i(program_.id(), shaders::location::text_box_origin, box.x, box.y);
  glProgramUniform2i(program_.id(), shaders::location::text_box_size, box.width, box.height);
  glBindTextureUnit(shaders::view_unit, view.texture);
  glBindTextureUnit(shaders::second_unit, text->texture.id());
  // Our sampler on both units: texelFetch of the view then works whatever the view texture's own
  // filter (a mipmapped filter on a single-level texture would make it incomplete, reading black).
  glBindSampler(shaders::view_unit, sampler_.id());
  glBindSampler(shaders::second_unit, sampler_.id());
  glBindVertexArray(vertex_array_.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindSampler(shaders::view_unit, 0);
  glBindSampler(shaders::second_unit, 0);
  glBindTextureUnit(shaders::second_unit, 0);
  gl::check_error("drawing the on-screen text");

  target.box = box;
  return GlTextureView{target.texture.id(), view.width, view.height, view.display_aspect};
}

}  // namespace nelf
