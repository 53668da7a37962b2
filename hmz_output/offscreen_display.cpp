// `--output offscreen`: the live player with no display server (DESIGN.md §7). The packed frame is
// rendered into a framebuffer object on a headless EGL context (the GPU --gpu or NELF_GPU picks,
// else the first hardware device, else Mesa's llvmpipe) and shown to no one; the player paces it by the
// clock at the signal's refresh rate, as it paces a window without vsync. It is what the player's
// tests run on, and a way to time the whole play loop on a machine without a monitor — as mpv's
// `--vo=null` and Monado's null compositor are. Keys come from stdin when it is a pipe or a file,
// one per refresh and none before the first frame is presented, so that a session scripted as the
// bytes a terminal sends is deterministic: however long the input takes to open (a resumed movie
// seeking on a loaded machine), `hq` shows the first frame before it quits.
#include <fmt/format.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <deque>
#include <memory>
#include <stdexcept>

#include "core/gl/egl_context.hpp"
#include "core/gl/objects.hpp"
#include "hmz_output/display.hpp"
#include "hmz_output/terminal_keys.hpp"

namespace nelf {
namespace {

class OffscreenDisplay final : public Display {
 public:
  explicit OffscreenDisplay(const DisplayOptions& options) : options_(options) {
    if (options.packed[0] <= 0 || options.packed[1] <= 0)
      throw std::invalid_argument(
          fmt::format("offscreen display: empty packed frame {}x{}", options.packed[0], options.packed[1]));
    try {
      context_ = std::make_shared<gl::EglContext>(gl::ContextOptions{options.gpu});
    } catch (const gl::GlError& e) {
      throw std::runtime_error(fmt::format("offscreen output: {}", e.what()));
    }
    // As a window's: BGRA, so that the CPU path's upload is a copy.
    packed_texture_ = gl::make_bgra8_texture_2d(options.packed[0], options.packed[1]);
    packed_fbo_ = gl::make_framebuffer(packed_texture_);
    const GLfloat black[4] = {0.f, 0.f, 0.f, 1.f};
    glClearNamedFramebufferfv(packed_fbo_.id(), GL_COLOR, 0, black);
    refresh_hz_ = options.signal.timing ? options.signal.timing->refresh_hz() : 60.0;
    gl::check_error("opening the offscreen display");
    struct stat st {};
    // Not a terminal: raw mode would take it from the user's shell; a window or kms is for typing.
    reading_keys_ =
        options.keys_from_stdin && ::fstat(STDIN_FILENO, &st) == 0 && (S_ISFIFO(st.st_mode) || S_ISREG(st.st_mode));
  }

  ~OffscreenDisplay() override {
    // The GL objects die while their context is current.
    try {
      context_->make_current();
    } catch (...) {
    }
    packed_fbo_.reset();
    packed_texture_.reset();
  }
  OffscreenDisplay(const OffscreenDisplay&) = delete;
  OffscreenDisplay& operator=(const OffscreenDisplay&) = delete;

  std::shared_ptr<gl::Context> context() const override { return context_; }
  GLuint packed_framebuffer() const override { return packed_fbo_.id(); }
  GLuint packed_texture() const override { return packed_texture_.id(); }
  std::array<int, 2> packed_size() const override { return options_.packed; }

  // A window's present() ends with the frame finished on the GPU: so does this one, so that the
  // time a frame takes is the same whether anyone looks at it or not.
  void present() override {
    glFinish();
    gl::check_error("presenting the packed frame");
    presented_ = true;
  }
  double refresh_hz() const override { return refresh_hz_; }
  bool vsync() const override { return false; }
  std::vector<KeyPress> poll_events() override {
    if (!presented_) return {};
    if (keys_.empty()) read_keys();
    if (keys_.empty()) return {};
    std::vector<KeyPress> one{keys_.front()};
    keys_.pop_front();
    return one;
  }
  bool close_requested() const override { return false; }

  std::string description() const override {
    return fmt::format("offscreen {}x{} ({}, paced at {:g} Hz)", options_.packed[0], options_.packed[1],
                       context_->renderer(), refresh_hz_);
  }

 private:
  DisplayOptions options_;
  std::shared_ptr<gl::EglContext> context_;
  gl::Texture packed_texture_;
  gl::Framebuffer packed_fbo_;
  double refresh_hz_ = 60.0;
  bool reading_keys_ = false;
  bool presented_ = false;  // the scripted keys wait for the first frame
  TerminalKeyParser parser_;
  std::deque<KeyPress> keys_;

  // What stdin holds now, never waiting; at its end, no more keys.
  void read_keys() {
    if (!reading_keys_) return;
    pollfd fd{STDIN_FILENO, POLLIN, 0};
    if (::poll(&fd, 1, 0) <= 0 || !(fd.revents & (POLLIN | POLLHUP))) return;
    char bytes[64];
    const ssize_t n = ::read(STDIN_FILENO, bytes, sizeof bytes);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) return;
    if (n <= 0) {
      reading_keys_ = false;
      return;
    }
    for (const KeyPress& key : parser_.feed(std::string_view(bytes, static_cast<std::size_t>(n)))) keys_.push_back(key);
  }
};

}  // namespace

std::unique_ptr<Display> open_offscreen_display(const DisplayOptions& options) {
  return std::make_unique<OffscreenDisplay>(options);
}

}  // namespace nelf
