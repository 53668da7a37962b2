#pragma once
// The compositor facade every command goes through (play, convert, calibrate, stills): a profile,
// the compositor options and the packed layout in; a stereo frame, its overlays and a packed target
// in, both eyes' elemental images drawn into the target at the layout's origins out. Hidden inside:
// GL or the CPU composite tables (and, for tables seen before, no GL at all), the uploads, the
// on-screen message and the calibration grid, and the worker compositing the next frames ahead.
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "compositor/compositor.hpp"
#include "compositor/cpu/composite_ahead.hpp"
#include "compositor/cpu/composite_table.hpp"
#include "compositor/cpu/composite_table_cache.hpp"
#include "core/frames.hpp"
#include "core/gl/context.hpp"
#include "core/gl/objects.hpp"
#include "core/image.hpp"
#include "core/packed_layout.hpp"
#include "core/packed_target.hpp"
#include "optics/depth.hpp"
#include "optics/profile.hpp"

namespace nelf {

class GlCompositor;
class GlDefectCompensation;
class TextOverlay;

// What is drawn over or done to a frame besides compositing it. The message and the grid go into
// the views before compositing, so that they are seen in focus through the lenses.
struct FrameOverlays {
  std::string message;            // on-screen text, "" for none
  bool calibration_grid = false;  // the grid pattern over both views (FrameCompositor::set_grid_pattern)
  bool swap_eyes = false;         // eye e shows view e ^ 1
  double bar = -1.0;              // with the message: a seek bar filled to this fraction; negative: none
};

// The views a stream's frames have as the compositor takes them (StereoVideoFrame's width, height,
// bits, aspect and block): what its textures and tables are made for.
struct FrameViews {
  int width = 0, height = 0, bits = 8;
  double aspect = 0.0;
  std::array<int, 2> block{1, 1};
  bool operator==(const FrameViews&) const = default;
};

// Which frames the CPU composite tables may composite, where prefer_composite_table says they pay
// (software GL, or NELF_COMPOSITE). Live outputs take them for block means only, as play always
// has: calibrate's whole views, whose optics change at every key, stay on GL rather than recording
// tables (~0.4 s) at each. A conversion takes them wherever they apply (whole views too, when the
// prefilter averages no block), as convert always has.
enum class TableUse { block_means, any_views };

class FrameCompositor {
 public:
  using Frame = std::shared_ptr<const StereoVideoFrame>;
  // The full-size calibration grid for both views of `width`×`height` under `profile` (the
  // compositor does not draw test patterns itself: they are an input). May throw
  // std::runtime_error (no grid for these optics).
  using GridPattern = std::function<EyeImages(const Profile& profile, int width, int height)>;

  // Frames composited ahead: three, with four packed frames (7.5 MB each at 720p frame packing) in
  // memory. With a busy process beside the player on two cores, ten 30 fps runs dropped 17 frames
  // in all with two ahead and 8 with three; on a quiet machine both drop none.
  static constexpr std::size_t ahead_depth = 3;

  // `layout`: where the eyes go (packed_layout(signal, profile's panel)); video needs eyes that fit
  // their areas (require_eyes_fit). `context`: the GL context to render with (a display's), made
  // current by the caller; none: the compositor makes its own headless one (on options.gpu) when
  // it first needs GL, so frames whose composite tables are in the cache start no GL at all.
  // Throws std::invalid_argument for a bad fsaa or a layout made for another panel, gl::GlError.
  FrameCompositor(Profile profile, CompositorOptions options, PackedLayout layout,
                  std::shared_ptr<gl::Context> context = nullptr, TableUse table_use = TableUse::block_means);
  ~FrameCompositor();
  FrameCompositor(const FrameCompositor&) = delete;
  FrameCompositor& operator=(const FrameCompositor&) = delete;

  // The block of view pixels whose means the compositor wants for `eye` of views of `width`×
  // `height` shown at `aspect` (0 = width / height): {1, 1} for whole views (prefilter_block).
  std::array<int, 2> wanted_block(Eye eye, int width, int height, double aspect) const;
  // The block both eyes take, or {1, 1} when they differ: what a stereo source is asked for.
  std::array<int, 2> wanted_block(int width, int height, double aspect) const;
  // The same as the view format a source of `view`s negotiates (Source::negotiate): views as the
  // prefilter's block means where the input allows (swscale makes them while converting from
  // YUV), far less to convert, upload and composite per frame. It follows the optics. For an
  // 8-bit output (`output_bits`: a display, an 8-bit file), 8-bit views, which the CPU composite
  // tables take.
  ViewFormat wanted_view_format(const ViewGeometry& view, int output_bits = 8) const {
    return {wanted_block(view.width, view.height, view.aspect), output_bits > 8 ? 16 : 8};
  }

  // New optics (the live keys). Throws, keeping the current profile, when `profile` is not
  // usable (or has another panel than the layout's).
  void set_profile(const Profile& profile);
  const Profile& profile() const { return profile_; }
  const PackedLayout& layout() const { return layout_; }
  const CompositorOptions& options() const { return options_; }
  void set_grid_pattern(GridPattern pattern) { grid_pattern_ = std::move(pattern); }

  // Chooses between GL and the composite tables for frames of `views` now (loading tables from
  // the cache, starting GL, recording tables) rather than at the first frame: a conversion fails
  // before it opens its output.
  void prepare_views(const FrameViews& views);
  // `frame` (with the grid when overlays.calibration_grid) made ready for render(): done by
  // render() itself, and only once per frame; separately it can be timed, and a grid that cannot
  // be made throws here (std::runtime_error) rather than there.
  void prepare(const Frame& frame, const FrameOverlays& overlays);

  // Both eyes of `frame` into `target` at the layout's origins, black elsewhere (null frame: all
  // black). A GL target takes the frame drawn by GL into its framebuffer, or made on the CPU and
  // uploaded into its texture (BGRA); a PackedFrame target is filled (the layout's size; 8 bits a
  // channel for 8-bit views, else 16; RGBA) from the tables or read back from GL. True when the
  // frame came composited ahead (GL targets only).
  bool render(const Frame& frame, const FrameOverlays& overlays, const PackedTarget& target);

  // Every refresh: `frames` (the next to be shown, in order) to be composited ahead on the worker
  // for `target` with what render() would use for them now, or nothing when it would not use the
  // tables. Only GL targets (a display's) take frames composited ahead.
  void composite_ahead(std::span<const Frame> frames, const FrameOverlays& overlays, const GlPackedTarget& target);
  // Waits (up to `timeout`) until the worker has made what it was asked for.
  void wait_for_ahead(std::chrono::milliseconds timeout) { ahead_.wait_until_idle(timeout); }

  // Whether the frame last prepared is composited with its depth (options().depth, the frame's
  // disparity, a lens-array profile): each pixel then shows the view where its ray meets the
  // content's surface, on GL or (where the tables pay) from the tables' depth-aware rays.
  bool depth_aware() const { return depth_frame_; }

  // The defect compensation eye `eye` takes for frames of the current views (or, after a still,
  // the still's), or null when there is nothing to hide: no defect map, none on that eye, or
  // options().defect_compensation off. Made when first needed.
  std::shared_ptr<const EyeDefectPlan> defect_plan(Eye eye) const {
    return defect_plans_.rgba[static_cast<std::size_t>(eye)];
  }

  // A still: float views composited by GL (no composite tables: they replay 8-bit block means,
  // and stills keep 16-bit and float precision) and placed by the layout, cropped to the eye areas
  // as pack_eyes does. The views' own size and aspect; frames are not involved.
  // With depth (options().depth, a lens-array profile), `disparity` is the still's: each pixel shows
  // the view where its ray meets that surface; null, the flat screen (said once).
  Image render_still(const StereoPair& views, std::shared_ptr<const StereoDisparity> disparity = nullptr);

 private:
  void start_gl();
  void rebuild_gl();
  TextOverlay& text_overlay();
  void open_views(const FrameViews& views);
  bool reduced() const { return views_.block[0] > 1 || views_.block[1] > 1; }
  int texture_w() const { return views_.width / views_.block[0]; }
  int texture_h() const { return views_.height / views_.block[1]; }
  std::array<int, 2> current_wanted_block(Eye eye) const { return wanted_blocks_[static_cast<int>(eye)]; }
  void update_wanted_blocks();
  const Image& calibration_grid(int view);
  bool table_path_open() const;
  bool use_tables();
  void forget_tables();
  std::shared_ptr<const CompositeSetup> ahead_setup(const FrameOverlays& overlays, std::array<int, 2> packed);
  std::shared_ptr<const Image> message_cover(const std::string& text, double bar);
  std::array<const std::uint8_t*, 2> covered_views(const FrameOverlays& overlays);
  void render_tables(const FrameOverlays& overlays, const GlPackedTarget& target);
  void render_tables(const FrameOverlays& overlays, PackedFrame& out);
  void fill_outside_eyes(std::uint8_t* rgba) const;
  std::array<const DisparitySurface*, 2> depth_surfaces() const;
  void render_gl(const FrameOverlays& overlays, unsigned int framebuffer);
  void upload_views();
  void upload_packed(const GlPackedTarget& target, const std::uint8_t* bgra);
  void update_depth(const StereoVideoFrame& frame);
  void depth_notice(const std::string& why);
  double content_aspect() const;
  const EyeDefectPlans& defect_plans(std::array<double, 2> aspects, bool bgra);

  Profile profile_;
  CompositorOptions options_;
  PackedLayout layout_;
  std::shared_ptr<gl::Context> context_;
  std::unique_ptr<GlCompositor> compositor_;  // none until GL is needed
  std::unique_ptr<TextOverlay> overlay_;      // with GL
  const TableUse table_use_;
  bool prefer_tables_ = false;  // prefer_composite_table of context_
  GridPattern grid_pattern_;
  int profile_generation_ = 0;  // what the grid was made for changes with it

  // The views of the frames (FrameViews), the blocks the prefilter wants for them, and their
  // textures (GL), filled from the last prepared frame when the GL path first needs them.
  FrameViews views_;
  std::array<std::array<int, 2>, 2> wanted_blocks_{};
  std::array<gl::Texture, 2> view_textures_;
  bool textures_current_ = false;
  // The calibration cover per view and what it was made for, and the views with it drawn over.
  std::shared_ptr<const std::array<Image, 2>> grid_;
  int grid_generation_ = -1;
  FrameViews grid_views_made_for_;
  std::array<std::vector<std::uint8_t>, 2> grid_views_;
  // The message as a cover for the views' bytes (CPU path), what it was made for, and the views
  // with it drawn over them.
  std::shared_ptr<const Image> message_;
  std::string message_text_;
  double message_bar_ = -1.0;
  double message_aspect_ = 0.0;
  std::array<std::vector<std::uint8_t>, 2> message_views_;
  // The CPU path: the tables for the current views and optics (tried when first used).
  std::array<std::optional<CompositeTable>, 2> tables_;
  bool tables_tried_ = false;
  const CompositeTableCache table_cache_;
  PackedFrameBytes packed_;  // a GL target's frame made on the CPU
  // A PackedFrame target on the GL path: the packed frame GL renders into, then reads back.
  gl::Texture packed_texture_;
  gl::Framebuffer packed_fbo_;
  int packed_bits_ = 0;
  // Compositing ahead: the frame last prepared and whether with the grid, the worker's copy of the
  // tables and the setup last handed to it, and the worker (last: it stops first).
  Frame frame_;
  bool calibration_ = false;
  // The depth of the frame last prepared: per view, its surface (made once per disparity), and
  // whether it is used; the one line said when it cannot be.
  std::shared_ptr<const StereoDisparity> surfaces_from_;
  std::array<std::shared_ptr<const DisparitySurface>, 2> surfaces_;
  const std::shared_ptr<FrameSurfaces> frame_surfaces_ = std::make_shared<FrameSurfaces>();  // shared with the worker
  bool depth_frame_ = false;
  bool depth_notice_given_ = false;
  // The dead and stuck pixels of the profile's defect map hidden after compositing: per eye, the
  // plan for RGBA bytes (and floats, and GL) and the same for BGRA bytes (the tables' packed frames),
  // made for the profile generation and the content aspect per eye they were made for; the one
  // line said when they are first made.
  struct DefectPlans {
    int generation = -1;
    std::array<double, 2> aspects{0.0, 0.0};
    EyeDefectPlans rgba, bgra;
  };
  DefectPlans defect_plans_;
  bool defect_notice_given_ = false;
  std::unique_ptr<GlDefectCompensation> defect_gl_;  // with GL, when a GL target takes a plan
  std::shared_ptr<std::array<std::optional<CompositeTable>, 2>> worker_tables_;
  std::shared_ptr<const CompositeSetup> setup_;
  CompositeAhead ahead_{ahead_depth};
};

}  // namespace nelf
