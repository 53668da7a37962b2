#include "compositor/frame_compositor.hpp"

#include <fmt/format.h>

#include <stdexcept>
#include <utility>

#include "compositor/gl/gl_compositor.hpp"
#include "compositor/gl/gl_defect_compensation.hpp"
#include "compositor/overlays/calibration_overlay.hpp"
#include "compositor/overlays/text_overlay.hpp"
#include "core/gl/egl_context.hpp"
#include "optics/defect_compensation.hpp"
#include "optics/defect_map.hpp"
#include "optics/mapping.hpp"

namespace nelf {

FrameCompositor::FrameCompositor(Profile profile, CompositorOptions options, PackedLayout layout,
                                 std::shared_ptr<gl::Context> context, TableUse table_use)
    : profile_(std::move(profile)),
      options_(options),
      layout_(layout),
      context_(std::move(context)),
      table_use_(table_use) {
  validate_fsaa(options_.fsaa);
  if (layout_.eye != profile_.display.resolution)
    throw std::invalid_argument(fmt::format("a packed layout for {}x{} eyes given a {}x{} panel", layout_.eye[0],
                                            layout_.eye[1], profile_.display.resolution[0],
                                            profile_.display.resolution[1]));
  // A display's context: GL is there anyway, and its errors belong to the start; so is the
  // message's blending pass, compiled now rather than as a hitch at the first key.
  if (context_) {
    start_gl();
    overlay_ = std::make_unique<TextOverlay>();
  }
}

FrameCompositor::~FrameCompositor() = default;

std::array<int, 2> FrameCompositor::wanted_block(Eye eye, int width, int height, double aspect) const {
  return prefilter_block(profile_, options_, eye, width, height, aspect);
}

std::array<int, 2> FrameCompositor::wanted_block(int width, int height, double aspect) const {
  return stereo_prefilter_block(profile_, options_, width, height, aspect);
}

void FrameCompositor::start_gl() {
  if (compositor_) return;
  if (!context_) context_ = std::make_shared<gl::EglContext>(gl::ContextOptions{options_.gpu});
  compositor_ = std::make_unique<GlCompositor>(profile_, options_, context_);
  prefer_tables_ = prefer_composite_table(*context_);
}

void FrameCompositor::rebuild_gl() {
  compositor_.reset();
  compositor_ = std::make_unique<GlCompositor>(profile_, options_, context_);
}

TextOverlay& FrameCompositor::text_overlay() {
  start_gl();
  if (!overlay_) overlay_ = std::make_unique<TextOverlay>();
  return *overlay_;
}

void FrameCompositor::set_profile(const Profile& profile) {
  if (profile.display.resolution != layout_.eye)
    throw std::invalid_argument(fmt::format("the {}x{} panel of profile {} is not the {}x{} of the packed layout",
                                            profile.display.resolution[0], profile.display.resolution[1], profile.name,
                                            layout_.eye[0], layout_.eye[1]));
  const Profile previous = profile_;
  profile_ = profile;
  try {
    if (compositor_) rebuild_gl();
    update_wanted_blocks();  // the optics for the current views (throws for a mapping that cannot be)
  } catch (...) {
    profile_ = previous;
    if (compositor_) rebuild_gl();
    update_wanted_blocks();
    throw;
  }
  ++profile_generation_;
  forget_tables();
}

void FrameCompositor::update_wanted_blocks() {
  for (Eye eye : {Eye::left, Eye::right})
    wanted_blocks_[static_cast<int>(eye)] =
        views_.width > 0 ? wanted_block(eye, views_.width, views_.height, views_.aspect) : std::array<int, 2>{1, 1};
}

void FrameCompositor::prepare_views(const FrameViews& views) {
  open_views(views);
  if (!use_tables()) start_gl();
}

void FrameCompositor::open_views(const FrameViews& views) {
  if (views == views_) return;
  views_ = views;
  view_textures_ = {};
  textures_current_ = false;
  update_wanted_blocks();
  forget_tables();
}

// The grid for view `i` at the views' size and the current optics, as cover for the views' bytes
// (cover_grid: block means of it on reduced views). Made when first needed.
const Image& FrameCompositor::calibration_grid(int i) {
  if (!grid_ || grid_generation_ != profile_generation_ || !(grid_views_made_for_ == views_)) {
    if (!grid_pattern_) throw std::logic_error("a calibration grid asked of a compositor given no grid pattern");
    const EyeImages pattern = grid_pattern_(profile_, views_.width, views_.height);
    // A new object, never changed: a CompositeSetup holding the old one stays as it was made.
    grid_ = std::make_shared<const std::array<Image, 2>>(
        std::array<Image, 2>{cover_grid(pattern[0], views_.block), cover_grid(pattern[1], views_.block)});
    grid_generation_ = profile_generation_;
    grid_views_made_for_ = views_;
  }
  return (*grid_)[static_cast<std::size_t>(i)];
}

void FrameCompositor::prepare(const Frame& frame, const FrameOverlays& overlays) {
  if (!frame) return;
  if (frame == frame_ && overlays.calibration_grid == calibration_) return;
  open_views({frame->width, frame->height, frame->bits, frame->aspect, frame->block});
  if (overlays.calibration_grid) {
    // Both covers first: a grid that cannot be made leaves the views as they were.
    calibration_grid(0);
    for (int i = 0; i < 2; ++i) {
      const auto& source = i == 0 ? frame->left : frame->right;
      grid_views_[i].assign(source.begin(), source.end());
      draw_over(grid_views_[i], calibration_grid(i), views_.bits);
    }
  }
  frame_ = frame;
  calibration_ = overlays.calibration_grid;
  textures_current_ = false;
  update_depth(*frame);
  // The GL path's uploads now (the player times them apart from the render); the CPU path's frames
  // need none, and a key that hands a frame to GL uploads it then.
  if (!use_tables() && compositor_) upload_views();
}

// The CPU path (compositor/cpu/composite_table.hpp) replays the fsaa-1 composite of 8-bit block
// means several times cheaper than llvmpipe runs the GL passes; prefer_composite_table says where
// it pays (software GL, or NELF_COMPOSITE). Not with block means made for optics a key has changed
// since (the GL path's smaller view covers the frames until the new block arrives).
bool FrameCompositor::table_path_open() const {
  if (views_.width == 0 || views_.bits != 8 || (table_use_ == TableUse::block_means && !reduced())) return false;
  for (Eye eye : {Eye::left, Eye::right})
    if (layout_.origins[static_cast<int>(eye)] && views_.block != current_wanted_block(eye)) return false;
  return true;
}

// Whether this render goes the CPU path. Records the tables on first use for the current views and
// optics: from the cache when these optics and views were seen before (recording takes ~0.4 s,
// e.g. after +/− back to a distance already used). Without GL yet, the cache alone decides where
// it may: never on a machine that may have a GPU (a render node), unless NELF_COMPOSITE=table.
bool FrameCompositor::use_tables() {
  if (!table_path_open()) return false;
  if (!tables_tried_) {
    tables_tried_ = true;
    const auto load = [&](GlCompositor* recorder) {
      for (Eye eye : {Eye::left, Eye::right}) {
        const int e = static_cast<int>(eye);
        if (!layout_.origins[e]) continue;
        tables_[e] = load_or_record_composite_table(table_cache_, recorder, profile_, options_, eye, views_.width,
                                                    views_.height, views_.aspect, views_.block);
        // No table for these options (fsaa other than 1, no prefilter): GL for both eyes.
        if (!tables_[e]) {
          tables_ = {};
          return false;
        }
      }
      return tables_[0] || tables_[1];
    };
    bool loaded = false;
    if (!compositor_) {
      const CompositeChoice choice = composite_choice();
      if (choice == CompositeChoice::table || (choice == CompositeChoice::automatic && !has_render_node())) {
        // GL would have refused a --gpu (or NELF_GPU) that names no device: so does a cache hit.
        gl::check_requested_gpu(gl::ContextOptions{options_.gpu});
        loaded = load(nullptr);
      }
      if (!loaded) start_gl();
    }
    if (!loaded && prefer_tables_) load(compositor_.get());
  }
  // A frame with depth needs the depth-aware rays (recorded with them when depth is on).
  if (depth_frame_)
    for (const auto& table : tables_)
      if (table && !table->has_depth()) return false;
  return tables_[0] || tables_[1];
}

void FrameCompositor::forget_tables() {
  tables_ = {};
  tables_tried_ = false;
  worker_tables_.reset();
  setup_.reset();
}

// What the worker composites the next frames with: exactly what render_tables() would use for them
// now (tables, eye positions, swap, calibration grid, views). Null while render() would not take
// the table path, and until the tables are made (that needs GL, this thread). A new setup for
// every change, so that frames made with the old one are never shown.
std::shared_ptr<const CompositeSetup> FrameCompositor::ahead_setup(const FrameOverlays& overlays,
                                                                   std::array<int, 2> packed) {
  if (!table_path_open() || !tables_tried_ || !(tables_[0] || tables_[1])) return nullptr;
  // With depth on, the tables of a lens-array profile hold the depth-aware rays (recorded with
  // them); frames with depth that tables without them cannot composite go to GL on this thread.
  // A stock profile shows every frame flat.
  const bool depth = options_.depth != DepthMode::off && profile_.lens_array.has_value();
  for (const auto& table : tables_)
    if (depth && table && !table->has_depth()) return nullptr;
  std::shared_ptr<const std::array<Image, 2>> grid;
  std::shared_ptr<const Image> message;
  EyeDefectPlans defects;
  try {
    if (overlays.calibration_grid) {
      calibration_grid(0);  // as prepare() would make it for the next frame (the optics may have changed)
      grid = grid_;
    }
    message = message_cover(overlays.message, overlays.bar);
    defects = defect_plans({content_aspect(), content_aspect()}, true);
  } catch (const std::runtime_error&) {
    return nullptr;  // no grid for these optics, or no font, or no mapping: render() says so
  }
  if (!setup_ || setup_->swap_eyes != overlays.swap_eyes || setup_->grid != grid || setup_->message != message ||
      setup_->packed != packed || setup_->defects != defects) {
    // The worker's own copy (once per tables): a table's render() uses its scratch buffers.
    if (!worker_tables_) worker_tables_ = std::make_shared<std::array<std::optional<CompositeTable>, 2>>(tables_);
    setup_ = std::make_shared<const CompositeSetup>(
        CompositeSetup{worker_tables_, layout_.origins, packed, overlays.swap_eyes, grid, views_.width, views_.height,
                       views_.block, views_.aspect, message, defects, depth, frame_surfaces_});
  }
  return setup_;
}

// The message as a cover for the views' bytes (what TextOverlay::apply() draws into the view
// textures on the GL path), or null for none. Made when the text or the views change.
std::shared_ptr<const Image> FrameCompositor::message_cover(const std::string& text, double bar) {
  if (text.empty()) return nullptr;
  const double aspect = views_.aspect > 0.0 ? views_.aspect : static_cast<double>(views_.width) / views_.height;
  if (!message_ || message_text_ != text || message_bar_ != bar || message_->width() != texture_w() ||
      message_->height() != texture_h() || message_aspect_ != aspect) {
    TextOverlay& overlay = text_overlay();
    overlay.set_text(text);
    overlay.set_bar(bar);
    message_ = std::make_shared<const Image>(overlay.cover(texture_w(), texture_h(), aspect));
    message_text_ = text;
    message_bar_ = bar;
    message_aspect_ = aspect;
  }
  return message_;
}

// The views' bytes the tables composite: the frame's own, or the copies with the grid drawn over
// them, and the message over those.
std::array<const std::uint8_t*, 2> FrameCompositor::covered_views(const FrameOverlays& overlays) {
  std::array<const std::uint8_t*, 2> views =
      calibration_ ? std::array<const std::uint8_t*, 2>{grid_views_[0].data(), grid_views_[1].data()}
                   : std::array<const std::uint8_t*, 2>{frame_->left.data(), frame_->right.data()};
  const auto message = message_cover(overlays.message, overlays.bar);
  const std::size_t view_bytes = static_cast<std::size_t>(texture_w()) * texture_h() * 4;
  for (std::size_t i = 0; i < 2; ++i)
    views[i] = covered_view({views[i], view_bytes}, nullptr, message.get(), message_views_[i]);
  return views;
}

bool FrameCompositor::render(const Frame& frame, const FrameOverlays& overlays, const PackedTarget& target) {
  prepare(frame, overlays);
  const bool shown = frame != nullptr;
  if (const auto* gl_target = std::get_if<GlPackedTarget>(&target.where)) {
    if (shown && use_tables()) {
      // Only a packed frame made for this frame with exactly the current setup; else as before.
      if (const auto setup = ahead_setup(overlays, gl_target->size)) {
        if (const auto packed = ahead_.take(*frame_, *setup)) {
          upload_packed(*gl_target, packed->data());
          return true;
        }
      }
      render_tables(overlays, *gl_target);
      return false;
    }
    start_gl();
    const float black[4] = {0.f, 0.f, 0.f, 1.f};
    glClearNamedFramebufferfv(gl_target->framebuffer, GL_COLOR, 0, black);
    if (shown) {
      render_gl(overlays, gl_target->framebuffer);
      // The corrections on the GPU, from the frame as drawn: no read-back.
      const EyeDefectPlans& plans = defect_plans({content_aspect(), content_aspect()}, false);
      if (plans[0] || plans[1]) {
        if (!defect_gl_) defect_gl_ = std::make_unique<GlDefectCompensation>();
        defect_gl_->apply(plans, layout_.origins, *gl_target);
      }
    }
    return false;
  }
  PackedFrame& out = *std::get<PackedFrame*>(target.where);
  out.width = layout_.packed[0];
  out.height = layout_.packed[1];
  out.pts_seconds = shown ? frame->pts_s : 0.0;
  if (shown && use_tables()) {
    render_tables(overlays, out);
    return false;
  }
  // GL into a packed frame of its own, read back.
  start_gl();
  const int bits = shown && views_.bits > 8 ? 16 : 8;
  if (!packed_texture_ || packed_bits_ != bits) {
    packed_texture_ = gl::make_texture_2d(bits > 8 ? GL_RGBA16 : GL_RGBA8, out.width, out.height);
    packed_fbo_ = gl::make_framebuffer(packed_texture_);
    packed_bits_ = bits;
  }
  const float black[4] = {0.f, 0.f, 0.f, 1.f};
  glClearNamedFramebufferfv(packed_fbo_.id(), GL_COLOR, 0, black);
  if (shown) render_gl(overlays, packed_fbo_.id());
  out.bits = bits;
  out.rgba.resize(static_cast<std::size_t>(out.width) * out.height * bytes_per_pixel(bits));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, packed_fbo_.id());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, out.width, out.height, GL_RGBA, bits > 8 ? GL_UNSIGNED_SHORT : GL_UNSIGNED_BYTE, out.rgba.data());
  gl::check_error("reading back the packed frame");
  // The frame is read back whole anyway: its corrections on the CPU.
  if (shown)
    compensate_packed_eyes(defect_plans({content_aspect(), content_aspect()}, false), layout_.origins, out.rgba.data(),
                           static_cast<std::size_t>(out.width) * bytes_per_pixel(bits), bits);
  return false;
}

// Both eyes into a CPU copy of the packed frame, then that into the target's texture: one upload
// of the whole frame, since the eyes' panels are nearly all of it.
void FrameCompositor::render_tables(const FrameOverlays& overlays, const GlPackedTarget& target) {
  const auto views = covered_views(overlays);
  render_packed_frame(tables_, views, static_cast<std::size_t>(texture_w()) * 4, overlays.swap_eyes, layout_.origins,
                      target.size, packed_, depth_surfaces());
  compensate_packed_eyes(defect_plans({content_aspect(), content_aspect()}, true), layout_.origins,
                         packed_.pixels.data(), static_cast<std::size_t>(target.size[0]) * 4, 8);
  upload_packed(target, packed_.pixels.data());
}

// Both eyes from their tables straight into the packed frame's bytes (RGBA), black around them.
void FrameCompositor::render_tables(const FrameOverlays& overlays, PackedFrame& out) {
  auto views = covered_views(overlays);
  auto surfaces = depth_surfaces();
  if (overlays.swap_eyes) std::swap(views[0], views[1]), std::swap(surfaces[0], surfaces[1]);
  out.bits = 8;
  out.rgba.resize(static_cast<std::size_t>(out.width) * out.height * 4);
  fill_outside_eyes(out.rgba.data());
  // While x264 fills its look-ahead the compositing is what a conversion waits for: the eyes
  // render in parallel.
  render_packed_eyes(tables_, views, static_cast<std::size_t>(texture_w()) * 4, layout_.origins, out.rgba.data(),
                     static_cast<std::size_t>(out.width) * 4, ChannelOrder::rgba, surfaces);
  compensate_packed_eyes(defect_plans({content_aspect(), content_aspect()}, false), layout_.origins, out.rgba.data(),
                         static_cast<std::size_t>(out.width) * 4, 8);
}

// Per view, the surface the frame last prepared shows on the CPU path, or null (the flat screen).
std::array<const DisparitySurface*, 2> FrameCompositor::depth_surfaces() const {
  if (!depth_frame_) return {};
  return {surfaces_[0].get(), surfaces_[1].get()};
}

// Opaque black wherever the eyes do not draw (the gap, and borders when a panel is smaller than its
// eye area); the eyes overwrite all of their own pixels. A pooled buffer holds the last frame.
void FrameCompositor::fill_outside_eyes(std::uint8_t* rgba) const {
  const auto panel = layout_.eye;
  const int width = layout_.packed[0], height = layout_.packed[1];
  const auto fill = [&](int y, int from, int to) {
    if (from < to)
      fill_opaque_black(
          {rgba + (static_cast<std::size_t>(y) * width + from) * 4, static_cast<std::size_t>(to - from) * 4});
  };
  for (int y = 0; y < height; ++y) {
    int from = 0;
    for (const auto& origin : layout_.origins) {
      if (!origin || y < origin->second || y >= origin->second + panel[1]) continue;
      fill(y, from, origin->first);
      from = origin->first + panel[0];
    }
    fill(y, from, width);
  }
}

// The views into their textures (whole views, or the block means the prefilter starts from:
// 1/block² of the texels to upload and composite), once per frame and only when GL draws it.
void FrameCompositor::upload_views() {
  if (textures_current_) return;
  if (!view_textures_[0])
    for (auto& t : view_textures_)
      t = gl::make_texture_2d(views_.bits > 8 ? GL_RGBA16 : GL_RGBA8, texture_w(), texture_h());
  const GLenum type = views_.bits > 8 ? GL_UNSIGNED_SHORT : GL_UNSIGNED_BYTE;
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  for (int i = 0; i < 2; ++i) {
    const std::uint8_t* pixels = calibration_ ? grid_views_[i].data() : (i == 0 ? frame_->left : frame_->right).data();
    glTextureSubImage2D(view_textures_[i].id(), 0, 0, 0, texture_w(), texture_h(), GL_RGBA, type, pixels);
  }
  gl::check_error("uploading the views");
  textures_current_ = true;
}

void FrameCompositor::render_gl(const FrameOverlays& overlays, unsigned int framebuffer) {
  upload_views();
  const bool message = !overlays.message.empty();
  if (message || overlay_) {
    text_overlay().set_text(overlays.message);
    overlay_->set_bar(overlays.bar);
  }
  for (Eye eye : {Eye::left, Eye::right}) {
    const auto& origin = layout_.origins[static_cast<int>(eye)];
    if (!origin) continue;
    const int view = static_cast<int>(eye) ^ (overlays.swap_eyes ? 1 : 0);
    // The text goes onto the texture as it is (block means: at their size, where it is as sharp as
    // the prefilter would leave full-size text, and its cap height still 1/20 of the view).
    const GlTextureView texture{view_textures_[view].id(), texture_w(), texture_h(),
                                views_.aspect > 0.0 ? views_.aspect : double(views_.width) / views_.height};
    const GlTextureView shown = message ? overlay_->apply(eye, texture) : texture;
    const GlTarget target{framebuffer, origin->first, origin->second};
    compositor_->set_depth(eye, depth_frame_ ? surfaces_[view] : nullptr);
    if (reduced() && views_.block == current_wanted_block(eye))
      compositor_->render_eye_reduced(
          eye, GlReducedView{{shown.texture, views_.width, views_.height, views_.aspect}, views_.block}, target);
    else  // whole views, or block means made for optics changed since (a key): a smaller view
      compositor_->render_eye(eye, shown, target);
  }
}

// Whether `frame` is composited with its depth, and its surfaces when it is. A depth that cannot
// be used gives the flat screen, said once.
void FrameCompositor::update_depth(const StereoVideoFrame& frame) {
  depth_frame_ = false;
  if (options_.depth == DepthMode::off) return;
  if (!profile_.lens_array) {
    depth_notice(
        fmt::format("profile {} has no lens array: its picture cannot follow the content's depth; showing "
                    "the flat view",
                    profile_.name));
    return;
  }
  if (!frame.disparity) {
    depth_notice(
        "a frame without depth (its two views cannot be matched: too little texture, or one view for both); such "
        "frames show the flat screen");
    return;
  }
  if (frame.disparity != surfaces_from_) {
    try {
      surfaces_ = frame_surfaces_->get(frame.disparity);
      surfaces_from_ = frame.disparity;
    } catch (const std::invalid_argument& e) {
      surfaces_ = {};
      surfaces_from_.reset();
      depth_notice(fmt::format("the frame's depth is unusable ({}); showing the flat screen", e.what()));
      return;
    }
  }
  depth_frame_ = true;
}

void FrameCompositor::depth_notice(const std::string& why) {
  if (depth_notice_given_) return;
  depth_notice_given_ = true;
  fmt::print(stderr, "nelf: --depth {}: {}\n", depth_mode_name(options_.depth), why);
}

// A BGRA packed frame into the target's (BGRA) texture: a copy.
void FrameCompositor::upload_packed(const GlPackedTarget& target, const std::uint8_t* bgra) {
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(target.texture, 0, 0, 0, target.size[0], target.size[1], GL_BGRA, GL_UNSIGNED_BYTE, bgra);
  gl::check_error("uploading the packed frame");
}

void FrameCompositor::composite_ahead(std::span<const Frame> frames, const FrameOverlays& overlays,
                                      const GlPackedTarget& target) {
  ahead_.want(ahead_setup(overlays, target.size), frames);
}

Image FrameCompositor::render_still(const StereoPair& views, std::shared_ptr<const StereoDisparity> disparity) {
  start_gl();
  StereoVideoFrame still;
  still.disparity = std::move(disparity);
  update_depth(still);
  for (Eye eye : {Eye::left, Eye::right})
    compositor_->set_depth(eye, depth_frame_ ? surfaces_[static_cast<int>(eye)] : nullptr);
  EyeImages eyes = compositor_->compose(views);
  for (Eye eye : {Eye::left, Eye::right}) compositor_->set_depth(eye, nullptr);
  const EyeDefectPlans& plans = defect_plans({views.left.aspect(), views.right.aspect()}, false);
  for (std::size_t e = 0; e < 2; ++e)
    if (plans[e]) compensate_defects(*plans[e], eyes[e]);
  return place_eyes(layout_, eyes);
}

double FrameCompositor::content_aspect() const {
  return views_.aspect > 0.0 ? views_.aspect : static_cast<double>(views_.width) / views_.height;
}

// The plans for the current profile and `aspects` (per eye), made when either changes: planning
// solves a small problem per defect, once per profile, not per frame. `bgra`: the plans for BGRA
// bytes (what the tables' packed frames are), whose stuck colours are in that order.
const EyeDefectPlans& FrameCompositor::defect_plans(std::array<double, 2> aspects, bool bgra) {
  if (defect_plans_.generation != profile_generation_ || defect_plans_.aspects != aspects) {
    DefectPlans made;
    made.generation = profile_generation_;
    made.aspects = aspects;
    const auto& map = profile_.correction.defects;
    if (options_.defect_compensation && map && !map->empty()) {
      int hidden = 0, outside = 0, uncompensable = 0;
      for (Eye eye : {Eye::left, Eye::right}) {
        const auto e = static_cast<std::size_t>(eye);
        if (!layout_.origins[e]) continue;  // the signal does not carry this eye
        EyeDefectPlan plan = plan_defect_compensation(make_eye_mapping(profile_, eye, aspects[e]), *map);
        for (const auto& correction : plan.corrections) hidden += correction.shares.empty() ? 0 : 1;
        outside += plan.outside_lit;
        uncompensable += plan.uncompensable;
        if (plan.empty()) continue;
        EyeDefectPlan swapped = plan;
        for (auto& correction : swapped.corrections)
          std::swap(correction.defect.stuck_rgb[0], correction.defect.stuck_rgb[2]);
        made.rgba[e] = std::make_shared<const EyeDefectPlan>(std::move(plan));
        made.bgra[e] = std::make_shared<const EyeDefectPlan>(std::move(swapped));
      }
      if (!defect_notice_given_) {
        defect_notice_given_ = true;
        fmt::print(stderr,
                   "nelf: hiding {} defects of the profile's defect map ({} outside the lit area need nothing, {} "
                   "could not be)\n",
                   hidden, outside, uncompensable);
      }
    }
    defect_plans_ = std::move(made);
  }
  return bgra ? defect_plans_.bgra : defect_plans_.rgba;
}

}  // namespace nelf
