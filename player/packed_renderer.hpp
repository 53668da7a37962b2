#pragma once
// How `nelf play` turns a decoded frame into the display's packed frame: the GL compositor, or the
// CPU composite tables (with the ahead worker), the on-screen message and the calibration grid.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <vector>

#include "compositor/cpu/composite_ahead.hpp"
#include "compositor/cpu/composite_table_cache.hpp"
#include "compositor/gl/gl_compositor.hpp"
#include "compositor/overlays/calibration_overlay.hpp"
#include "compositor/overlays/text_overlay.hpp"
#include "core/gl/objects.hpp"
#include "core/image_library.hpp"
#include "core/user_error.hpp"
#include "hmz_output/display.hpp"
#include "hmz_output/packing.hpp"
#include "inputs/test_patterns.hpp"
#include "player/frame_queue.hpp"
#include "player/player.hpp"

namespace nelf::playback {

// The GL side: view textures, the compositor (rebuilt when the optics change) and the eye areas;
// on software GL also the CPU path, composite tables replayed from the views' bytes.
class PackedRenderer {
 public:
  // Frames composited ahead: three, with four packed frames (7.5 MB each at 720p frame packing) in
  // memory. With a busy process beside the player on two cores, ten 30 fps runs dropped 17 frames
  // in all with two ahead and 8 with three; on a quiet machine both drop none.
  static constexpr std::size_t ahead_depth = 3;

  PackedRenderer(Display& display, const PlayerOptions& options)
      : display_(display), options_(options), prefer_tables_(prefer_composite_table(*display.context())) {
    profile_ = options.profile;
    rebuild();
  }

  // Throws (and keeps the old compositor) when the profile is not usable.
  void set_profile(const Profile& profile) {
    const Profile previous = profile_;
    profile_ = profile;
    try {
      rebuild();
    } catch (...) {
      profile_ = previous;
      rebuild();
      throw;
    }
  }
  const Profile& profile() const { return profile_; }

  // The frame's views into the view textures: whole views, or (frame.block > 1×1) the block means
  // the compositor's prefilter starts from, 1/block² of the texels to upload and composite. The
  // frame is kept: render() may find it composited ahead.
  void upload(std::shared_ptr<const StereoVideoFrame> shared, bool calibration) {
    frame_ = std::move(shared);
    calibration_ = calibration;
    const StereoVideoFrame& frame = *frame_;
    if (frame.width != view_w_ || frame.height != view_h_ || frame.bits != bits_ || frame.block != block_ ||
        frame.aspect != aspect_) {
      view_w_ = frame.width;
      view_h_ = frame.height;
      bits_ = frame.bits;
      block_ = frame.block;
      aspect_ = frame.aspect;
      for (auto& t : views_) t = gl::make_texture_2d(bits_ > 8 ? GL_RGBA16 : GL_RGBA8, texture_w(), texture_h());
      update_wanted_blocks();
      forget_tables();
    }
    // The textures are filled even when the CPU path will composite this frame: a key changing
    // the optics hands the next renders to GL (until block means for the new optics arrive),
    // which then needs them.
    const GLenum type = bits_ > 8 ? GL_UNSIGNED_SHORT : GL_UNSIGNED_BYTE;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    for (int i = 0; i < 2; ++i) {
      const auto& source = i == 0 ? frame.left : frame.right;
      const std::uint8_t* pixels = source.data();
      if (calibration) {
        grid_views_[i].assign(source.begin(), source.end());
        draw_over(grid_views_[i], calibration_grid(i), bits_);
        pixels = grid_views_[i].data();
      }
      glTextureSubImage2D(views_[i].id(), 0, 0, 0, texture_w(), texture_h(), GL_RGBA, type, pixels);
    }
    gl::check_error("uploading the views");
  }

  // The block each eye's prefilter wants for the current views and optics ({1, 1}: whole views).
  std::array<int, 2> wanted_block(Eye eye) const { return wanted_blocks_[static_cast<int>(eye)]; }

  // The grid for view `i` at the view's size and the current optics, as cover for the view
  // texture (cover_grid: block means of it on reduced views). Made when first needed.
  const Image& calibration_grid(int i) {
    const PatternGeometry geometry = pattern_geometry(profile_, view_w_, view_h_);
    if (!grid_ || !(grid_geometry_ == geometry) || grid_block_ != block_) {
      const StereoPair pair = make_test_pattern(TestPattern::grid, geometry);
      // A new object, never changed: a CompositeSetup holding the old one stays as it was made.
      grid_ = std::make_shared<const std::array<Image, 2>>(
          std::array<Image, 2>{cover_grid(pair.left.image, block_), cover_grid(pair.right.image, block_)});
      grid_geometry_ = geometry;
      grid_block_ = block_;
    }
    return (*grid_)[static_cast<std::size_t>(i)];
  }

  // The on-screen message ("" for none), blended into both views before compositing so that it
  // is seen in focus through the lenses.
  void set_message(const std::string& text) { overlay_.set_text(text); }

  // Both eyes into the display's packed framebuffer; the gap (and any border) black. True when the
  // frame came composited ahead by the worker.
  bool render(bool swap_eyes) {
    if (use_tables()) {
      // Only a packed frame made for this frame with exactly the current setup; else as before.
      const auto setup = frame_ ? ahead_setup(swap_eyes) : nullptr;
      if (setup) {
        if (const auto packed = ahead_.take(*frame_, *setup)) {
          upload_packed(packed->data());
          return true;
        }
      }
      render_from_tables(swap_eyes);
      return false;
    }
    const GLuint fbo = display_.packed_framebuffer();
    const float black[4] = {0.f, 0.f, 0.f, 1.f};
    glClearNamedFramebufferfv(fbo, GL_COLOR, 0, black);
    if (view_w_ == 0) return false;
    for (Eye eye : {Eye::left, Eye::right}) {
      const auto& origin = origins_[static_cast<int>(eye)];
      if (!origin) continue;
      const int view = static_cast<int>(eye) ^ (swap_eyes ? 1 : 0);
      // The text goes onto the texture as it is (block means: at their size, where it is as sharp
      // as the prefilter would leave full-size text, and its cap height still 1/20 of the view).
      const GlTextureView shown =
          overlay_.apply(eye, GlTextureView{views_[view].id(), texture_w(), texture_h(),
                                            aspect_ > 0.0 ? aspect_ : double(view_w_) / view_h_});
      const GlTarget target{fbo, origin->first, origin->second};
      if (reduced() && block_ == wanted_block(eye))
        compositor_->render_eye_reduced(eye, GlReducedView{{shown.texture, view_w_, view_h_, aspect_}, block_}, target);
      else  // whole views, or block means made for optics changed since (a key): a smaller view
        compositor_->render_eye(eye, shown, target);
    }
    return false;
  }

  // Every refresh: `frames` (the next to be shown, in order) to be composited ahead on the worker
  // with the setup render() would use now, or none when it would not use the tables.
  void composite_ahead(bool swap_eyes, std::span<const CompositeAhead::Frame> frames) {
    ahead_.want(ahead_setup(swap_eyes), frames);
  }
  // Waits (up to `timeout`) until the worker has made what it was asked for.
  void wait_for_ahead(std::chrono::milliseconds timeout) { ahead_.wait_until_idle(timeout); }

 private:
  // The CPU path (compositor/cpu/composite_table.hpp) replays the fsaa-1 composite of 8-bit block
  // means several times cheaper than llvmpipe runs the GL passes; prefer_composite_table says
  // where it pays (software GL, or NELF_COMPOSITE).
  bool may_use_tables() const { return prefer_tables_ && bits_ == 8 && reduced(); }
  // Whether this render goes the CPU path: not with block means made for optics a key has changed
  // since (the GL path's smaller view covers the frames until the new block arrives). A message
  // goes into the views' bytes (message_cover). Records the tables on first use for the current
  // views and optics.
  bool table_path_open() const {
    if (view_w_ == 0 || !may_use_tables()) return false;
    for (Eye eye : {Eye::left, Eye::right})
      if (origins_[static_cast<int>(eye)] && block_ != wanted_block(eye)) return false;
    return true;
  }
  bool use_tables() {
    if (!table_path_open()) return false;
    if (!tables_tried_) {
      tables_tried_ = true;
      for (Eye eye : {Eye::left, Eye::right}) {
        const int e = static_cast<int>(eye);
        if (!origins_[e]) continue;
        // From the cache when these optics and views were seen before (recording takes ~0.4 s,
        // e.g. after +/− back to a distance already used).
        tables_[e] = load_or_record_composite_table(table_cache_, compositor_.get(), profile_, options_.compositor, eye,
                                                    view_w_, view_h_, aspect_, block_);
        // No table for these options (fsaa other than 1, no prefilter): GL for both eyes.
        if (!tables_[e]) {
          tables_ = {};
          break;
        }
      }
    }
    return tables_[0] || tables_[1];
  }
  void forget_tables() {
    tables_ = {};
    tables_tried_ = false;
    worker_tables_.reset();
    setup_.reset();
  }

  // What the worker composites the next frames with: exactly what render_from_tables() would use
  // for them now (tables, eye positions, swap, calibration grid, views). Null while render() would
  // not take the table path, and until render() has made the tables (that needs GL, this thread).
  // A new setup for every change, so that frames made with the old one are never shown.
  std::shared_ptr<const CompositeSetup> ahead_setup(bool swap_eyes) {
    if (!table_path_open() || !tables_tried_ || !(tables_[0] || tables_[1])) return nullptr;
    std::shared_ptr<const std::array<Image, 2>> grid;
    if (calibration_) {
      try {
        calibration_grid(0);  // as upload() would make it for the next frame (the optics may have changed)
      } catch (const TestPatternError&) {
        return nullptr;
      }
      grid = grid_;
    }
    std::shared_ptr<const Image> message;
    try {
      message = message_cover();
    } catch (const std::runtime_error&) {
      return nullptr;  // no font: render() says so
    }
    if (!setup_ || setup_->swap_eyes != swap_eyes || setup_->grid != grid || setup_->message != message) {
      // The worker's own copy (once per tables): a table's render() uses its scratch buffers.
      if (!worker_tables_) worker_tables_ = std::make_shared<std::array<std::optional<CompositeTable>, 2>>(tables_);
      setup_ = std::make_shared<const CompositeSetup>(CompositeSetup{worker_tables_, origins_, display_.packed_size(),
                                                                     swap_eyes, grid, view_w_, view_h_, block_, aspect_,
                                                                     message});
    }
    return setup_;
  }
  // The message as a cover for the views' bytes (what overlay_.apply() draws into the view
  // textures on the GL path), or null for none. Made when the text or the views change.
  std::shared_ptr<const Image> message_cover() {
    if (overlay_.text().empty()) return nullptr;
    const double aspect = aspect_ > 0.0 ? aspect_ : static_cast<double>(view_w_) / view_h_;
    if (!message_ || message_text_ != overlay_.text() || message_->width() != texture_w() ||
        message_->height() != texture_h() || message_aspect_ != aspect) {
      message_ = std::make_shared<const Image>(overlay_.cover(texture_w(), texture_h(), aspect));
      message_text_ = overlay_.text();
      message_aspect_ = aspect;
    }
    return message_;
  }
  // Both eyes into a CPU copy of the packed frame, then that into the display's texture: one
  // upload of the whole frame, since the eyes' panels are nearly all of it.
  void render_from_tables(bool swap_eyes) {
    // The views as uploaded: the frame's own bytes, or the copies with the grid drawn over them.
    std::array<const std::uint8_t*, 2> views =
        calibration_ ? std::array<const std::uint8_t*, 2>{grid_views_[0].data(), grid_views_[1].data()}
                     : std::array<const std::uint8_t*, 2>{frame_->left.data(), frame_->right.data()};
    // The message over them, as the GL path draws it over the textures.
    const auto message = message_cover();
    const std::size_t view_bytes = static_cast<std::size_t>(texture_w()) * texture_h() * 4;
    for (std::size_t i = 0; i < 2; ++i)
      views[i] = covered_view({views[i], view_bytes}, nullptr, message.get(), message_views_[i]);
    render_packed_frame(tables_, views, static_cast<std::size_t>(texture_w()) * 4, swap_eyes, origins_,
                        display_.packed_size(), packed_);
    upload_packed(packed_.pixels.data());
  }
  // A BGRA packed frame into the display's (BGRA) texture: a copy.
  void upload_packed(const std::uint8_t* pixels) {
    const auto packed = display_.packed_size();
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(display_.packed_texture(), 0, 0, 0, packed[0], packed[1], GL_BGRA, GL_UNSIGNED_BYTE, pixels);
    gl::check_error("uploading the packed frame");
  }

  bool reduced() const { return block_[0] > 1 || block_[1] > 1; }
  int texture_w() const { return view_w_ / block_[0]; }
  int texture_h() const { return view_h_ / block_[1]; }
  void update_wanted_blocks() {
    for (Eye eye : {Eye::left, Eye::right})
      wanted_blocks_[static_cast<int>(eye)] =
          view_w_ > 0 ? prefilter_block(profile_, options_.compositor, eye, view_w_, view_h_, aspect_)
                      : std::array<int, 2>{1, 1};
  }

  void rebuild() {
    forget_tables();
    compositor_.reset();
    compositor_ = std::make_unique<GlCompositor>(profile_, options_.compositor, display_.context());
    update_wanted_blocks();
    const auto panel = compositor_->panel();
    const auto packed = display_.packed_size();
    const PackedLayout layout = packed_layout(options_.signal, panel);
    for (int e = 0; e < 2; ++e) {
      const auto& area = layout.areas[e];
      if (!area) continue;
      if (panel[0] > area->width || panel[1] > area->height)
        throw UserError(fmt::format("the {}x{} panel of profile {} does not fit the {}x{} eye area of signal {}",
                                    panel[0], panel[1], profile_.name, area->width, area->height, options_.signal.name),
                        2);
      const auto [x, y] = *layout.origins[e];
      if (x + panel[0] > packed[0] || y + panel[1] > packed[1])
        throw UserError(fmt::format("the display's {}x{} frame is smaller than signal {} needs", packed[0], packed[1],
                                    options_.signal.name),
                        1);
    }
    origins_ = layout.origins;
  }

  Display& display_;
  const PlayerOptions& options_;
  Profile profile_;
  std::unique_ptr<GlCompositor> compositor_;
  TextOverlay overlay_;
  std::shared_ptr<const std::array<Image, 2>> grid_;
  PatternGeometry grid_geometry_;
  std::array<int, 2> grid_block_{1, 1};
  std::array<std::optional<std::pair<int, int>>, 2> origins_;
  std::array<gl::Texture, 2> views_;
  // The views with the calibration grid drawn over them, as in the textures while it is on.
  std::array<std::vector<std::uint8_t>, 2> grid_views_;
  // The message as a cover for the views' bytes (CPU path), what it was made for, and the views
  // with it drawn over them.
  std::shared_ptr<const Image> message_;
  std::string message_text_;
  double message_aspect_ = 0.0;
  std::array<std::vector<std::uint8_t>, 2> message_views_;
  // The CPU path: the tables for the current views and optics (recorded when first used), and the
  // packed frame.
  const bool prefer_tables_;
  std::array<std::optional<CompositeTable>, 2> tables_;
  bool tables_tried_ = false;
  // Compositing ahead: the frame last uploaded and whether with the grid, the worker's copy of the
  // tables and the setup last handed to it, and the worker (last: it stops first).
  std::shared_ptr<const StereoVideoFrame> frame_;
  bool calibration_ = false;
  std::shared_ptr<std::array<std::optional<CompositeTable>, 2>> worker_tables_;
  std::shared_ptr<const CompositeSetup> setup_;
  const CompositeTableCache table_cache_;
  PackedFrameBytes packed_;
  int view_w_ = 0, view_h_ = 0, bits_ = 8;
  std::array<int, 2> block_{1, 1};  // of the views in the textures
  std::array<std::array<int, 2>, 2> wanted_blocks_{};
  double aspect_ = 0.0;
  CompositeAhead ahead_{ahead_depth};
};

}  // namespace nelf::playback
