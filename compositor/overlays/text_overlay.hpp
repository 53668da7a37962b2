#pragma once
// On-screen messages for `nelf play` and `nelf calibrate` ("paused", "distance 1.25 m", "IPD 63.5 mm").
// Through a light field display only what goes through the compositor is in focus, so the text is
// blended into each eye's view texture before GlCompositor::render_eye, never onto the packed frame.
#include <epoxy/gl.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "compositor/compositor.hpp"
#include "compositor/gl/gl_compositor.hpp"
#include "core/gl/objects.hpp"
#include "core/image.hpp"

namespace nelf {

class TextOverlay {
 public:
  // Where the text box lands in a view: a rectangle in view texels, row 0 = the view's top row.
  struct Box {
    int x = 0, y = 0, width = 0, height = 0;
  };

  // Compiles the blending pass; the GL context that will render must be current (as for every call).
  TextOverlay();
  ~TextOverlay();
  TextOverlay(const TextOverlay&) = delete;
  TextOverlay& operator=(const TextOverlay&) = delete;

  // The line to show (ASCII: OpenImageIO's render_text draws other characters wrongly); "" shows
  // nothing. The text is rasterised again only when it or the size it is drawn at changes.
  void set_text(std::string text);
  const std::string& text() const { return text_; }
  // A seek bar under the text, filled to `fraction` (0 to 1) of its length; negative: none. It is
  // drawn into the same label as the text (so the CPU path's cover has it too).
  void set_bar(double fraction);
  double bar() const { return bar_; }

  // `view` with the text in a box: light on a translucent dark box, centred horizontally in the lower
  // third, its cap height 1/20 of the view's height (so it looks the same size at any source
  // resolution; narrowed to fit the width). Returns `view` itself when the text is empty; otherwise a
  // texture of the view's size and format (RGBA8/16/16F/32F, RGB10_A2: the view copied, then only the
  // box drawn: ~2.5 ms for 1920x1080 on llvmpipe; other formats: one pass into RGBA16F), owned by the
  // overlay and valid until the next apply() for the same eye. Eyes have separate textures, so both
  // can be prepared before rendering either.
  // Throws gl::GlError when GL fails, std::runtime_error when the text cannot be rendered (no font).
  GlTextureView apply(Eye eye, const GlTextureView& view);

  // The box of the last apply() for `eye` (all zero when the text was empty).
  Box box(Eye eye) const { return eyes_[static_cast<int>(eye)].box; }

  // The same text for views whose bytes are composited on the CPU (the player's composite
  // tables): a width × height image of the label as apply() draws it into such a view (`aspect`
  // its display aspect, 0 = width / height), alpha 0 outside the box; drawn over the view's bytes
  // (draw_over, compositor/overlays/calibration_overlay) it gives what apply() gives. Empty for no text.
  // Needs no GL. Throws std::runtime_error when the text cannot be rendered (no font).
  Image cover(int width, int height, double aspect);

  // The label itself at `font_px`, at its own size: the text on its translucent dark box (alpha the
  // box's opacity), as apply() scales it into a view; empty for no text. For a caption shown flat
  // (the preview window's). Needs no GL. Throws std::runtime_error when the text cannot be rendered.
  Image label_image(int font_px);

 private:
  struct Label {
    std::string text;
    double bar = -1.0;
    int font_px = 0;
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgba;  // as in `texture` (RGBA8, row 0 the top row)
    gl::Texture texture;             // made by label(), not by cpu_label()
  };
  // Where the label goes in a view (font size narrowed to fit its width) and at which size.
  struct Placement {
    int font_px = 0;
    Box box;
  };
  Placement place(int width, int height, double pixel_aspect);
  // The label's pixels for `text_` at `font_px` (cached; no GL).
  const Label& cpu_label(int font_px);
  struct EyeTarget {
    int width = 0, height = 0;
    GLenum format = 0;
    gl::Texture texture;
    gl::Framebuffer fbo;
    Box box;
  };

  // The label for `text_` at `font_px` pixels (cached).
  const Label& label(int font_px);

  std::string text_;
  double bar_ = -1.0;
  Label label_;
  std::array<EyeTarget, 2> eyes_;
  gl::Program program_;
  gl::VertexArray vertex_array_;
  gl::Sampler sampler_;
};

}  // namespace nelf
