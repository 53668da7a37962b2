#pragma once
// Live sinks (DESIGN.md §7): a desktop window, fullscreen 1:1 on a monitor, quad-buffer stereo, or
// KMS scan-out. `nelf play` and `nelf calibrate` render every packed frame with the GL compositor
// into the display's packed framebuffer (GlCompositor::render_eye at the eye areas of
// hmz_output/packing), or (`nelf play` on software GL) on the CPU from composite tables into its
// texture, then call present(). Each kind of display is its own file (window_display.*,
// kms_display.*, offscreen_display.cpp) and one live row of the table in output_drivers.cpp; this
// header is the contract between them and the player.
#include <epoxy/gl.h>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/gl/context.hpp"
#include "core/keys.hpp"
#include "hmz_output/signal.hpp"
#include "hmz_output/sink.hpp"

namespace nelf {

struct DisplayOptions {
  Signal signal;                // packed frame size and (for HDMI signals) timing
  std::array<int, 2> packed{};  // the packed frame in pixels (signal.packed_width/height of the panel)
  std::string monitor;          // fullscreen: monitor name to match ("" = the one containing "HMZ")
  std::string connector;        // kms: connector name, e.g. "HDMI-A-1" ("" = the first connected one
                                // offering a 3D frame-packing mode)
  std::string title = "nelf";   // window title
  std::optional<int> gpu;       // offscreen: the EGL device (--gpu; unset: NELF_GPU, else the first hardware one)
  // offscreen: the keys typed into a pipe or a file on stdin, one per refresh (a scripted session;
  // off when the input itself is read from stdin).
  bool keys_from_stdin = false;
};

// A line of text for a desktop preview window: `width`×`height` opaque RGBA8 pixels, row 0 the top.
struct PreviewCaption {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
  bool empty() const { return rgba.empty(); }
};

class Display : public Sink {
 public:
  // The display's GL 4.5 core context, current on the thread that opened the display; give it to
  // GlCompositor so that render_eye() can draw into packed_framebuffer().
  virtual std::shared_ptr<gl::Context> context() const = 0;
  // A framebuffer object of options.packed size (row 0 = the packed frame's top row, as everywhere
  // in the compositor) holding the frame that present() shows. Never 0.
  virtual GLuint packed_framebuffer() const = 0;
  // The 8-bit RGBA colour texture of packed_framebuffer(), stored BGRA where the driver allows
  // (gl::make_bgra8_texture_2d), for renderers that make the frame on the CPU (the composite table
  // on software GL) and upload it with glTextureSubImage2D instead: BGRA bytes upload as a copy.
  virtual GLuint packed_texture() const = 0;
  virtual std::array<int, 2> packed_size() const = 0;

  // Shows the packed framebuffer's contents: scaled to fit with its aspect kept (window), 1:1
  // (fullscreen, kms), or split into the left and right back buffers (quad-buffer). Blocks until
  // the next vertical blank when vsync() is true. Throws std::runtime_error when the output is lost.
  virtual void present() = 0;
  // The refresh rate frames are paced at (the signal's, or the monitor's when it reports one).
  double refresh_hz() const override = 0;
  // True when present() waits for vblank; otherwise the caller paces frames with a timer.
  virtual bool vsync() const = 0;

  // Key presses since the last call (also handles the window system's other events).
  virtual std::vector<KeyPress> poll_events() = 0;
  // The user closed the window (or the output went away); the caller should stop.
  virtual bool close_requested() const = 0;
  // 'f': switch between window and fullscreen where that means anything; returns a line for the
  // on-screen message (e.g. "fullscreen on HMZ-T1" or "fullscreen needs a monitor named …").
  virtual std::string toggle_fullscreen() { return "fullscreen not available on this output"; }

  // The on-screen message, shown flat over a desktop preview window: there the packed frame's
  // elemental images make the copy drawn into the views (in focus through the lenses) a pattern of
  // tiny ones that no one can read. Bottom centre, scaled to 1/16 of the window's height; empty:
  // none. A display that is the HMD's signal (fullscreen, kms, quad-buffer, offscreen) shows only
  // the views' copy, so it keeps no caption.
  virtual void set_preview_caption(PreviewCaption caption) { (void)caption; }
  // Whether set_preview_caption() shows anything (a window, fullscreen or not: `f` switches).
  virtual bool takes_preview_caption() const { return false; }

  // One line for logs, e.g. "window 1280x1470 on :99 (llvmpipe, no vsync)" or
  // "KMS HDMI-A-1 1280x1470@60Hz 3D frame packing".
  std::string description() const override = 0;
};

}  // namespace nelf
