#pragma once
// The OpenGL compositor (DESIGN.md §3–4): each eye's elemental images rendered on the GPU (or
// llvmpipe) with exactly the geometry of optics/mapping.cpp, antialiased per CompositorOptions:
//   fsaa 0   one bilinear tap of the full-resolution view per pixel (comparison only);
//   fsaa 1   the view prefiltered once per frame to the pixel footprint (a block-mean pass and a
//            separable box pass into a small texture shared by all lenslets, black beyond the
//            screen's edge), one tap per pixel; pixels straddling an elemental-image border
//            (drawn again as thin strips along the borders) take one tap per lens, area-weighted;
//   fsaa 4   prefilter at the sub-sample footprint + 2×2 stratified sub-apertures per pixel;
//   fsaa 16  prefilter at the sub-sample footprint + 4×4 sub-apertures.
// Prefilter textures are RGBA8 for RGBA8 views (fast on llvmpipe), RGBA16F otherwise.
// compose() works on CPU Images; render_eye() is the lower-level entry for video: it renders from an
// existing GL texture into a region of any framebuffer (e.g. straight into the packed HDMI frame).
//
// Texture memory convention (views, intermediates and targets): row 0 is the image's top row, as in
// nelf::Image, so uploads and read-backs need no flip. A window sink flips when it presents.
#include <epoxy/gl.h>

#include <array>
#include <memory>
#include <optional>

#include "compositor/compositor.hpp"
#include "compositor/cpu/composite_table.hpp"
#include "compositor/gl/shader_programs.hpp"
#include "core/gl/context.hpp"
#include "core/gl/egl_context.hpp"
#include "core/gl/objects.hpp"
#include "optics/depth.hpp"
#include "optics/mapping.hpp"

namespace nelf {

// A view already on the GPU: any 2D colour texture (the compositor samples level 0 with its own
// bilinear, clamp-to-edge sampler, whatever the texture's own parameters are).
struct GlTextureView {
  GLuint texture = 0;
  int width = 0;
  int height = 0;
  double display_aspect = 0.0;  // 0 = width / height
  double aspect() const {
    return display_aspect > 0.0 ? display_aspect : static_cast<double>(width) / static_cast<double>(height);
  }
};

// A view whose texture already holds the prefilter's first pass: the mean of each
// block[0]×block[1] group of texels of a view.width×view.height view (view.texture is
// view.width / block[0] × view.height / block[1] texels). Video conversion gets it from swscale's
// area filter while converting the decoded YUV, so no full-resolution RGBA frame is ever made.
struct GlReducedView {
  GlTextureView view;
  std::array<int, 2> block{1, 1};
};

// Where an eye image goes: a panel-sized rectangle of `framebuffer` whose lowest-addressed corner
// (row 0 = the eye image's top row) is at (x, y). framebuffer 0 is not allowed (headless).
struct GlTarget {
  GLuint framebuffer = 0;
  int x = 0;
  int y = 0;
};

// How the footprint prefilter samples one view (per axis; public so tests and benchmarks can show it).
struct PrefilterPlan {
  bool enabled = false;               // false: the footprint is at most a texel, sample the view itself
  std::array<double, 2> footprint{};  // F: the (sub-)sample footprint in view texels
  std::array<int, 2> block{1, 1};     // R: view texels averaged per cell by the block-mean pass
  std::array<int, 2> reduced{0, 0};   // size of the block-mean texture
  std::array<int, 2> margin{0, 0};    // prefiltered samples beyond each edge of the view (black there)
  std::array<int, 2> output{0, 0};    // size of the prefiltered texture, margins included
  std::array<double, 2> spacing{};    // g: view texels between prefiltered samples
  std::array<double, 2> box{};        // B: box width (view texels) of the separable pass
};

// The plan for a view of `width`×`height` texels under `mapping`, with `subsamples` per pixel axis.
PrefilterPlan plan_prefilter(const EyeMapping& mapping, int width, int height, int subsamples);

// The block the prefilter averages first for `eye` of `profile` and a `width`×`height` view shown at
// `aspect` (0 = width / height): what a GlReducedView for it must hold. {1, 1} when the compositor
// samples the view itself (fsaa 0, or a footprint of at most a texel).
std::array<int, 2> prefilter_block(const Profile& profile, const CompositorOptions& options, Eye eye, int width,
                                   int height, double aspect);
// The block both eyes take (one reduction serves a stereo frame's two views), or {1, 1} when they
// differ: what to ask a video source for before render_eye_reduced.
std::array<int, 2> stereo_prefilter_block(const Profile& profile, const CompositorOptions& options, int width,
                                          int height, double aspect);

class GlCompositor final : public Compositor {
 public:
  // Renders with `context` (headless EGL, a window's or a KMS surface's), or with a new headless
  // context (ContextOptions{}) when it is null.
  // Throws std::invalid_argument for a bad fsaa value, gl::GlError when GL is unusable.
  GlCompositor(Profile profile, CompositorOptions options = {}, std::shared_ptr<gl::Context> context = nullptr);
  ~GlCompositor() override;
  GlCompositor(const GlCompositor&) = delete;
  GlCompositor& operator=(const GlCompositor&) = delete;

  // Uploads both views, renders each eye and reads the images back.
  EyeImages compose(const StereoPair& views) override;

  // The content's depth for `eye`'s next renders: each display pixel then shows the view where its
  // chief ray (and, in the border strips, each part's ray) meets the content's surface rather than
  // the flat screen (optics/depth.hpp). Null: the flat screen. A flat (all-zero) surface renders what
  // no surface does. Stock profiles (no lenslets) keep the flat view.
  void set_depth(Eye eye, std::shared_ptr<const DisparitySurface> surface) override;

  // Renders `eye` from `view` into `target` (panel-sized region). Prefilters the view first
  // (fsaa ≥ 1): call once per eye per frame. Leaves the target framebuffer bound.
  void render_eye(Eye eye, const GlTextureView& view, const GlTarget& target);
  // render_eye from a view already block-averaged; `view.block` must be prefilter_block() of it
  // (else std::invalid_argument).
  void render_eye_reduced(Eye eye, const GlReducedView& view, const GlTarget& target);

  // The fsaa-1 composite of `eye` for views of view_width×view_height shown at `aspect` (0 =
  // width / height), reduced by `block`, as a table for the CPU (compositor/cpu/composite_table.hpp),
  // recorded with this compositor's shaders. Nothing where no table applies: fsaa other than 1,
  // no prefilter, or `block` not prefilter_block() of the view. Replaying it on the CPU is much
  // cheaper than render_eye_reduced on a software rasteriser; on a GPU render_eye_reduced wins.
  // With options().depth on and a lens array, the table holds the depth-aware composite's rays too
  // (CompositeTable::has_depth), so that frames with depth take the CPU path as well.
  std::optional<CompositeTable> make_composite_table(Eye eye, int view_width, int view_height, double aspect,
                                                     std::array<int, 2> block);
  // What make_composite_table builds the table from.
  std::optional<CompositeTable::Recording> record_composite_table(Eye eye, int view_width, int view_height,
                                                                  double aspect, std::array<int, 2> block);

  const gl::Context& context() const { return *context_; }
  const Profile& profile() const { return profile_; }
  const CompositorOptions& options() const { return options_; }
  std::array<int, 2> panel() const { return profile_.display.resolution; }

 private:
  struct PrefilterTargets {
    std::array<int, 2> reduced{0, 0}, horizontal{0, 0}, output{0, 0};
    gl::Texture reduced_texture, horizontal_texture, output_texture;
    gl::Framebuffer reduced_fbo, horizontal_fbo, output_fbo;
  };
  struct EyeTarget {
    gl::Texture texture;
    gl::Framebuffer fbo;
  };
  // Per eye: where pass 1 taps the prefiltered view for each pixel (elemental.frag's mapping,
  // rendered once), for the view geometry it was made for.
  struct CoordinateMap {
    gl::Texture texture;
    gl::Framebuffer fbo;
    gl::Texture hits;  // depth maps: R32F, the crossing pass 1 found for each pixel
    int width = 0, height = 0;
    double aspect = 0.0;
  };
  struct UploadedView {
    gl::Texture texture;
    int width = 0, height = 0;
  };
  struct DepthSurface {
    std::shared_ptr<const DisparitySurface> surface;
    gl::Texture texture;  // R32F, the surface's values
    gl::Texture bounds;   // R32F, its front bounds (DisparitySurface::front_bounds)
    int width = 0, height = 0;
  };

  struct TextureTransform {
    float scale[2] = {1.f, 1.f}, offset[2] = {0.f, 0.f};
    bool cut_outside = true;
  };
  static TextureTransform prefiltered_transform(const PrefilterPlan& plan);
  // Fills the mapping's uniform block (shaders/mapping.glsl) for the next draw.
  void upload_mapping(const EyeMapping& m, const TextureTransform& texture, int x, int y);
  void draw_coordinate_map(const EyeMapping& m, const TextureTransform& texture, CoordinateMap& map);
  // The depth coordinate map (elemental.frag's NELF_DEPTH_MAP) of `m` into `map`.
  void draw_depth_map(const EyeMapping& m, CoordinateMap& map);
  // Runs the prefilter passes; returns the texture the elemental pass samples. `reduced`: the
  // texture already holds the block means (the first pass is skipped).
  GLuint prefilter(const PrefilterPlan& plan, GLuint view_texture, int view_width, int view_height, bool reduced,
                   PrefilterTargets& targets);
  void render(Eye eye, const GlTextureView& view, std::array<int, 2> block, const GlTarget& target);

  std::shared_ptr<gl::Context> context_;
  Profile profile_;
  CompositorOptions options_;
  gl::VertexArray empty_vertex_array_;
  gl::Sampler sampler_;
  gl::Buffer mapping_block_;  // shaders::MappingBlock, bound at shaders::mapping_block_binding
  // Compiled on first use, from shaders::program_source (compositor/gl/shader_programs.hpp).
  GLuint program(shaders::ProgramKind kind);
  std::array<gl::Program, shaders::every_program_kind.size()> programs_;
  std::array<CoordinateMap, 2> coordinate_maps_;       // per eye, fsaa 1
  std::array<CoordinateMap, 2> depth_maps_;            // per eye, fsaa 1 with depth
  std::array<PrefilterTargets, 2> prefilter_targets_;  // per eye
  std::array<UploadedView, 2> uploads_;                // per eye, for compose()
  std::array<EyeTarget, 2> eye_targets_;               // per eye, for compose()
  std::array<DepthSurface, 2> depth_;                  // per eye, set_depth
};

// Whether video paths should composite from a CompositeTable on the CPU rather than with GL: on a
// software rasteriser, unless the environment says otherwise (NELF_COMPOSITE=gl or =table, for
// comparisons and benchmarks).
bool prefer_composite_table(const gl::Context& context);
enum class CompositeChoice { automatic, gl, table };
CompositeChoice composite_choice();  // NELF_COMPOSITE

// The helpers below need a current context (e.g. GlCompositor::context().make_current()).
// A texture holding `image` in `internal_format` (GL_RGBA16F keeps 10-bit sources' precision;
// GL_RGBA8 is what 8-bit video decodes to; GL_RGBA32F is exact but samples slowly on llvmpipe).
gl::Texture upload_texture(const Image& image, GLenum internal_format = GL_RGBA16F);
// Replaces the contents of a texture of the same size.
void update_texture(const gl::Texture& texture, const Image& image);

// Reads a `width`×`height` rectangle at (x, y) of `framebuffer`'s colour attachment 0 into an Image
// (row 0 = the framebuffer's row y, see the memory convention above).
Image read_back(GLuint framebuffer, int x, int y, int width, int height);

}  // namespace nelf
