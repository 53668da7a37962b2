#include "compositor/gl/gl_compositor.hpp"

#include "compositor/gl/shader_interface.hpp"

#include <cstdlib>
#include <cstring>
#include <string_view>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nelf {

namespace {

// Prefiltered samples per (sub-)sample footprint. The box pass is band-limited to ~1/F, so 3
// samples per F keep the final bilinear tap's extra blur small (its variance is compensated below)
// while the prefiltered texture stays tiny (~430×240 for a 1920×1080 view on hmz-t1).
constexpr double samples_per_footprint = 3.0;

int subsamples_per_axis(int fsaa) { return fsaa == 16 ? 4 : fsaa == 4 ? 2 : 1; }

float f(double x) { return static_cast<float>(x); }

bool texture_has_format(const gl::Texture& texture, GLenum format) {
  GLint current = 0;
  glGetTextureLevelParameteriv(texture.id(), 0, GL_TEXTURE_INTERNAL_FORMAT, &current);
  return static_cast<GLenum>(current) == format;
}

}  // namespace

PrefilterPlan plan_prefilter(const EyeMapping& mapping, int width, int height, int subsamples) {
  PrefilterPlan plan;
  const Vec2 footprint_uv = pixel_footprint_uv(mapping);
  const int size[2] = {width, height};
  plan.footprint = {footprint_uv.x * width / subsamples, footprint_uv.y * height / subsamples};
  plan.enabled = plan.footprint[0] > 1.0 || plan.footprint[1] > 1.0;
  if (!plan.enabled) return plan;
  for (int axis = 0; axis < 2; ++axis) {
    const double footprint = plan.footprint[axis];
    const int count =
        std::max(1, static_cast<int>(std::lround(size[axis] / std::max(1.0, footprint / samples_per_footprint))));
    plan.output[axis] = std::min(count, size[axis]);
    const double spacing = static_cast<double>(size[axis]) / plan.output[axis];
    plan.spacing[axis] = spacing;
    plan.block[axis] = spacing >= 4.0 ? 4 : spacing >= 2.0 ? 2 : 1;
    plan.reduced[axis] = (size[axis] + plan.block[axis] - 1) / plan.block[axis];
    // The reference is a box of F over the bilinear view (variance F²/12 + 1/6). Here the block
    // mean (R²/12), the box (B²/12) and the final bilinear tap on the prefiltered grid (g²/6) add
    // up; B is chosen so the total variance matches.
    const double box_squared =
        footprint * footprint + 2.0 - plan.block[axis] * plan.block[axis] - 2.0 * spacing * spacing;
    plan.box[axis] = std::sqrt(std::max(box_squared, 1.0));
    // The screen is black around the view: extend the grid until the box lies wholly outside, so
    // the outermost samples are black and the clamped texture stays black beyond them.
    plan.margin[axis] = static_cast<int>(std::ceil((0.5 * plan.box[axis] + plan.block[axis]) / spacing)) + 1;
    plan.output[axis] += 2 * plan.margin[axis];
  }
  return plan;
}

std::array<int, 2> stereo_prefilter_block(const Profile& profile, const CompositorOptions& options, int width,
                                          int height, double aspect) {
  const auto block = prefilter_block(profile, options, Eye::left, width, height, aspect);
  if (block != prefilter_block(profile, options, Eye::right, width, height, aspect)) return {1, 1};
  return block;
}

std::array<int, 2> prefilter_block(const Profile& profile, const CompositorOptions& options, Eye eye, int width,
                                   int height, double aspect) {
  if (options.fsaa == 0) return {1, 1};
  if (aspect <= 0.0) aspect = static_cast<double>(width) / height;
  const PrefilterPlan plan =
      plan_prefilter(make_eye_mapping(profile, eye, aspect), width, height, subsamples_per_axis(options.fsaa));
  return plan.enabled ? plan.block : std::array<int, 2>{1, 1};
}

GlCompositor::GlCompositor(Profile profile, CompositorOptions options, std::shared_ptr<gl::Context> context)
    : context_(context ? std::move(context) : std::make_shared<gl::EglContext>()),
      profile_(std::move(profile)),
      options_(options) {
  validate_fsaa(options_.fsaa);
  context_->make_current();
  empty_vertex_array_ = gl::make_vertex_array();
  sampler_ = gl::make_linear_clamp_sampler();
  mapping_block_ = gl::make_uniform_buffer(sizeof(shaders::MappingBlock));
  gl::check_error("creating the compositor");
}

// Programs are compiled on first use: llvmpipe takes tens of milliseconds a program, and a run
// needs only some (the CPU composite table two of the seven).
GLuint GlCompositor::program(shaders::ProgramKind kind) {
  gl::Program& p = programs_[static_cast<std::size_t>(kind)];
  if (p) return p.id();
  const shaders::ProgramSource source = shaders::program_source(kind, subsamples_per_axis(options_.fsaa));
  p = gl::make_program(source.vertex, source.fragment, source.defines);
  gl::check_error("creating the compositor's programs");
  return p.id();
}

GlCompositor::~GlCompositor() {
  // The GL objects are deleted by their owners; the context they belong to must be current.
  try {
    context_->make_current();
  } catch (const gl::GlError&) {
  }
}

GLuint GlCompositor::prefilter(const PrefilterPlan& plan, GLuint view_texture, int view_width, int view_height,
                               bool reduced, PrefilterTargets& t) {
  // Intermediates keep the view's precision: 8-bit views (decoded 8-bit video) get RGBA8, which
  // llvmpipe filters on its fast fixed-point path; anything deeper gets RGBA16F.
  GLint view_format = 0;
  glGetTextureLevelParameteriv(view_texture, 0, GL_TEXTURE_INTERNAL_FORMAT, &view_format);
  const GLenum format = view_format == GL_RGBA8 || view_format == GL_SRGB8_ALPHA8 ? GL_RGBA8 : GL_RGBA16F;
  const auto ensure = [format](std::array<int, 2>& size, std::array<int, 2> wanted, gl::Texture& texture,
                               gl::Framebuffer& fbo) {
    if (size == wanted && texture && texture_has_format(texture, format)) return;
    fbo.reset();
    texture = gl::make_texture_2d(format, wanted[0], wanted[1]);
    fbo = gl::make_framebuffer(texture);
    size = wanted;
  };
  const bool reduce = !reduced && (plan.block[0] > 1 || plan.block[1] > 1);
  if (reduce) ensure(t.reduced, plan.reduced, t.reduced_texture, t.reduced_fbo);
  ensure(t.horizontal, {plan.output[0], plan.reduced[1]}, t.horizontal_texture, t.horizontal_fbo);
  ensure(t.output, plan.output, t.output_texture, t.output_fbo);

  glBindVertexArray(empty_vertex_array_.id());
  glBindSampler(shaders::view_unit, sampler_.id());
  GLuint input = view_texture;
  if (reduce) {
    glBindFramebuffer(GL_FRAMEBUFFER, t.reduced_fbo.id());
    glViewport(0, 0, plan.reduced[0], plan.reduced[1]);
    glUseProgram(program(shaders::ProgramKind::reduce));
    glProgramUniform2i(program(shaders::ProgramKind::reduce), shaders::location::reduce_block, plan.block[0],
                       plan.block[1]);
    glBindTextureUnit(shaders::view_unit, input);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    input = t.reduced_texture.id();
  }
  const GLuint box = program(shaders::ProgramKind::box);
  glUseProgram(box);
  const int view_size[2] = {view_width, view_height};
  const auto box_pass = [&](int axis, GLuint fbo, std::array<int, 2> size, double cell) {
    namespace at = shaders::location::box;
    glProgramUniform1f(box, at::out_origin, f(-plan.margin[axis] * plan.spacing[axis]));
    glProgramUniform1f(box, at::view_extent, f(view_size[axis]));
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, size[0], size[1]);
    glProgramUniform1i(box, at::axis, axis);
    glProgramUniform1f(box, at::cell_size, f(cell));
    glProgramUniform1f(box, at::out_spacing, f(plan.spacing[axis]));
    glProgramUniform1f(box, at::box_width, f(plan.box[axis]));
    glBindTextureUnit(shaders::view_unit, input);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  };
  box_pass(0, t.horizontal_fbo.id(), t.horizontal, plan.block[0]);
  input = t.horizontal_texture.id();
  box_pass(1, t.output_fbo.id(), t.output, plan.block[1]);
  return t.output_texture.id();
}

// Where u_view's texels are for uv ∈ [0, 1] (the screen): the view itself (cut to black outside
// the screen), or the prefiltered texture, whose margins already fade to black.
GlCompositor::TextureTransform GlCompositor::prefiltered_transform(const PrefilterPlan& plan) {
  TextureTransform t;
  for (int axis = 0; axis < 2; ++axis) {
    // uv ∈ [0, 1] covers the samples between the margins.
    t.scale[axis] = f(static_cast<double>(plan.output[axis] - 2 * plan.margin[axis]) / plan.output[axis]);
    t.offset[axis] = f(static_cast<double>(plan.margin[axis]) / plan.output[axis]);
  }
  t.cut_outside = false;
  return t;
}

// The uniform block of elemental.frag and border_strips.vert (shaders/mapping.glsl): the eye's
// mapping (DESIGN.md §3), where u_view's texels are, and the region's origin in the target.
// Rewritten before each draw that reads it (GL orders the update after the draws before).
void GlCompositor::upload_mapping(const EyeMapping& m, const TextureTransform& texture, int x, int y) {
  shaders::MappingBlock b;
  b.texture_scale = {texture.scale[0], texture.scale[1]};
  b.texture_offset = {texture.offset[0], texture.offset[1]};
  b.cut_outside = texture.cut_outside ? 1 : 0;
  b.region_origin = {f(x), f(y)};
  b.panel = {f(m.panel[0]), f(m.panel[1])};
  b.pixel_pitch = {f(m.pixel_pitch_mm.x), f(m.pixel_pitch_mm.y)};
  b.shift = {f(m.shift_px.x), f(m.shift_px.y)};
  b.rotation = {f(m.rotation_cos), f(m.rotation_sin)};
  b.has_lens_array = m.has_lens_array ? 1 : 0;
  if (m.has_lens_array) {
    b.to_lens_plane = f(m.eye_relief_mm / (m.eye_relief_mm + m.gap_mm));
    b.lattice_offset = {f(m.lattice_offset_mm.x), f(m.lattice_offset_mm.y)};
    b.lens_pitch = f(m.lens_pitch_mm);
    b.first_lens = {m.first_lens[0], m.first_lens[1]};
    b.lenses = {m.lenses[0], m.lenses[1]};
    b.chief_ray_scale = f((m.render_distance_mm - m.eye_relief_mm) / m.gap_mm);
    b.screen_centre = {f(m.screen_centre_mm.x), f(m.screen_centre_mm.y)};
    b.screen_size = {f(m.screen_size_mm.x), f(m.screen_size_mm.y)};
  } else {
    b.view_size = {f(m.view_size_mm.x), f(m.view_size_mm.y)};
  }
  glNamedBufferSubData(mapping_block_.id(), 0, sizeof b, &b);
  glBindBufferBase(GL_UNIFORM_BUFFER, shaders::mapping_block_binding, mapping_block_.id());
}

// Renders the coordinate map (elemental.frag's mapping, pass 1's tap positions) of `m` into `map`.
void GlCompositor::draw_coordinate_map(const EyeMapping& m, const TextureTransform& texture, CoordinateMap& map) {
  map.fbo.reset();
  map.texture = gl::make_texture_2d(GL_RG32F, m.panel[0], m.panel[1]);
  map.fbo = gl::make_framebuffer(map.texture);
  upload_mapping(m, texture, 0, 0);
  glBindVertexArray(empty_vertex_array_.id());
  glBindFramebuffer(GL_FRAMEBUFFER, map.fbo.id());
  glViewport(0, 0, m.panel[0], m.panel[1]);
  glUseProgram(program(shaders::ProgramKind::map));
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

void GlCompositor::draw_depth_map(const EyeMapping& m, CoordinateMap& map) {
  map.fbo.reset();
  map.texture = gl::make_texture_2d(GL_RGBA32F, m.panel[0], m.panel[1]);
  map.fbo = gl::make_framebuffer(map.texture);
  map.hits = gl::make_texture_2d(GL_R32F, m.panel[0], m.panel[1]);
  upload_mapping(m, TextureTransform{}, 0, 0);
  glProgramUniform1f(program(shaders::ProgramKind::depth_map), shaders::location::depth::pupil_per_lens,
                     f(m.eye_relief_mm / m.gap_mm));
  glBindVertexArray(empty_vertex_array_.id());
  glBindFramebuffer(GL_FRAMEBUFFER, map.fbo.id());
  glViewport(0, 0, m.panel[0], m.panel[1]);
  glUseProgram(program(shaders::ProgramKind::depth_map));
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

void GlCompositor::render_eye(Eye eye, const GlTextureView& view, const GlTarget& target) {
  render(eye, view, {1, 1}, target);
}

void GlCompositor::render_eye_reduced(Eye eye, const GlReducedView& view, const GlTarget& target) {
  render(eye, view.view, view.block, target);
}

void GlCompositor::render(Eye eye, const GlTextureView& view, std::array<int, 2> block, const GlTarget& target) {
  if (view.texture == 0 || view.width <= 0 || view.height <= 0)
    throw std::invalid_argument("GlCompositor::render_eye: no view texture");
  if (target.framebuffer == 0) throw std::invalid_argument("GlCompositor::render_eye: target framebuffer 0");
  const EyeMapping m = make_eye_mapping(profile_, eye, view.aspect());
  const int subsamples = subsamples_per_axis(options_.fsaa);

  GLuint source = view.texture;
  TextureTransform texture;  // the view itself until prefiltered
  const PrefilterPlan plan =
      options_.fsaa != 0 ? plan_prefilter(m, view.width, view.height, subsamples) : PrefilterPlan{};
  // block 1×1: the view itself (the prefilter averages it); else it must be the plan's block.
  const bool reduced = block[0] > 1 || block[1] > 1;
  const std::array<int, 2> wanted_block = plan.enabled ? plan.block : std::array<int, 2>{1, 1};
  if (reduced && block != wanted_block)
    throw std::invalid_argument(
        fmt::format("GlCompositor::render_eye_reduced: the view is averaged in {}x{} blocks, the prefilter wants {}x{}",
                    block[0], block[1], wanted_block[0], wanted_block[1]));
  if (plan.enabled) {
    source = prefilter(plan, view.texture, view.width, view.height, reduced, prefilter_targets_[static_cast<int>(eye)]);
    texture = prefiltered_transform(plan);
  }

  // Pass 1 (every pixel): point samples. Pass 2 (fsaa >= 1, lens arrays): strips along the
  // elemental-image borders redo the pixels there with the per-lens area split.
  // One tap per pixel from the prefiltered view (fsaa 1): the pixel's coordinate comes from a map
  // made once per eye and view geometry, so pass 1 only taps.
  const int e = static_cast<int>(eye);
  const bool depth = depth_[e].surface && m.has_lens_array;
  const bool use_map = plan.enabled && subsamples == 1 && !depth;
  const bool new_map =
      use_map && (!coordinate_maps_[e].texture || coordinate_maps_[e].width != view.width ||
                  coordinate_maps_[e].height != view.height || coordinate_maps_[e].aspect != view.aspect());
  // The depth-aware pass 1 at fsaa 1 likewise fetches what of each pixel's ray does not change (its
  // flat-screen point and pupil crossing) from a map made once, and only searches and taps.
  const bool use_depth_map = depth && plan.enabled && subsamples == 1;
  const bool new_depth_map =
      use_depth_map && (!depth_maps_[e].texture || depth_maps_[e].width != view.width ||
                        depth_maps_[e].height != view.height || depth_maps_[e].aspect != view.aspect());
  const bool border_strips = options_.fsaa != 0 && m.has_lens_array;
  glBindVertexArray(empty_vertex_array_.id());
  CoordinateMap& map = use_depth_map ? depth_maps_[e] : coordinate_maps_[e];
  if (new_map || new_depth_map) {
    if (new_map)
      draw_coordinate_map(m, texture, map);
    else
      draw_depth_map(m, map);
    map.width = view.width;
    map.height = view.height;
    map.aspect = view.aspect();
  }
  if (!use_map || border_strips) upload_mapping(m, texture, target.x, target.y);
  if (depth) {
    const DisparitySurface& surface = *depth_[e].surface;
    const Vec2 gain = pupil_gain(depth_geometry(profile_, m), {1.0, 1.0});
    for (shaders::ProgramKind kind : {shaders::ProgramKind::depth, shaders::ProgramKind::depth_border,
                                      shaders::ProgramKind::depth_lookup, shaders::ProgramKind::depth_border_hits}) {
      namespace at = shaders::location::depth;
      glProgramUniform2f(program(kind), at::parallax_gain, f(gain.x), f(gain.y));
      glProgramUniform2f(program(kind), at::disparity_range, surface.back(), surface.front());
      glProgramUniform1f(program(kind), at::pupil_per_lens, f(m.eye_relief_mm / m.gap_mm));
    }
    glBindSampler(shaders::disparity_unit, 0);
    glBindTextureUnit(shaders::disparity_unit, depth_[e].texture.id());
    glBindSampler(shaders::front_bound_unit, 0);
    glBindTextureUnit(shaders::front_bound_unit, depth_[e].bounds.id());
  }
  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer);
  glViewport(target.x, target.y, m.panel[0], m.panel[1]);
  glBindSampler(shaders::view_unit, sampler_.id());
  glBindTextureUnit(shaders::view_unit, source);
  if (use_map) {
    glBindSampler(shaders::second_unit, 0);
    glBindTextureUnit(shaders::second_unit, map.texture.id());
    glProgramUniform2f(program(shaders::ProgramKind::lookup), shaders::location::lookup_region_origin, f(target.x),
                       f(target.y));
    glUseProgram(program(shaders::ProgramKind::lookup));
  } else if (use_depth_map) {
    glBindSampler(shaders::second_unit, 0);
    glBindTextureUnit(shaders::second_unit, map.texture.id());
    glBindImageTexture(shaders::hits_image_unit, map.hits.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glUseProgram(program(shaders::ProgramKind::depth_lookup));
  } else {
    glUseProgram(program(depth ? shaders::ProgramKind::depth : shaders::ProgramKind::elemental));
  }
  glDrawArrays(GL_TRIANGLES, 0, 3);
  if (border_strips) {
    if (use_depth_map) {  // the strips take pass 1's crossings (elemental.frag, NELF_DEPTH_HITS)
      glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
      glBindSampler(shaders::hits_unit, 0);
      glBindTextureUnit(shaders::hits_unit, map.hits.id());
      glUseProgram(program(shaders::ProgramKind::depth_border_hits));
    } else {
      glUseProgram(program(depth ? shaders::ProgramKind::depth_border : shaders::ProgramKind::border));
    }
    glDrawArrays(GL_TRIANGLES, 0, 6 * (m.lenses[0] + m.lenses[1] + 2));
  }
  gl::check_error("rendering an eye image");
}

std::optional<CompositeTable> GlCompositor::make_composite_table(Eye eye, int view_width, int view_height,
                                                                 double aspect, std::array<int, 2> block) {
  auto recording = record_composite_table(eye, view_width, view_height, aspect, block);
  if (!recording) return std::nullopt;
  return CompositeTable(*recording);
}

std::optional<CompositeTable::Recording> GlCompositor::record_composite_table(Eye eye, int view_width, int view_height,
                                                                              double aspect, std::array<int, 2> block) {
  if (options_.fsaa != 1 || view_width <= 0 || view_height <= 0) return std::nullopt;
  context_->make_current();
  const EyeMapping m = make_eye_mapping(profile_, eye, aspect > 0.0 ? aspect : double(view_width) / view_height);
  const PrefilterPlan plan = plan_prefilter(m, view_width, view_height, 1);
  if (!plan.enabled || block != plan.block) return std::nullopt;
  const TextureTransform texture = prefiltered_transform(plan);
  const int width = m.panel[0], height = m.panel[1];
  const std::size_t pixels = static_cast<std::size_t>(width) * height;

  CompositeTable::Recording r;
  r.panel = m.panel;
  r.reduced = plan.reduced;
  r.prefiltered = plan.output;
  const int view_size[2] = {view_width, view_height};
  for (int axis = 0; axis < 2; ++axis)
    (axis == 0 ? r.horizontal : r.vertical) =
        make_box_axis(plan.output[axis], -plan.margin[axis] * plan.spacing[axis], plan.spacing[axis], plan.box[axis],
                      plan.block[axis], plan.reduced[axis], view_size[axis]);

  CoordinateMap map;
  draw_coordinate_map(m, texture, map);
  r.coordinates.resize(2 * pixels);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glGetTextureImage(map.texture.id(), 0, GL_RG, GL_FLOAT, static_cast<GLsizei>(r.coordinates.size() * sizeof(float)),
                    r.coordinates.data());

  if (m.has_lens_array) {
    // The border strips write down each part's tap instead of taking it, a part per pass.
    const gl::Texture part_texture = gl::make_texture_2d(GL_RGBA32F, width, height);
    const gl::Framebuffer fbo = gl::make_framebuffer(part_texture);
    upload_mapping(m, texture, 0, 0);
    glBindVertexArray(empty_vertex_array_.id());
    glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
    glViewport(0, 0, width, height);
    glUseProgram(program(shaders::ProgramKind::record));
    std::vector<float> part(4 * pixels);
    for (int k = 0; k < 4; ++k) {
      const GLfloat zero[4] = {0.f, 0.f, 0.f, 0.f};
      glClearNamedFramebufferfv(fbo.id(), GL_COLOR, 0, zero);
      glProgramUniform1i(program(shaders::ProgramKind::record), shaders::location::record_part, k);
      glDrawArrays(GL_TRIANGLES, 0, 6 * (m.lenses[0] + m.lenses[1] + 2));
      glGetTextureImage(part_texture.id(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(part.size() * sizeof(float)),
                        part.data());
      if (k == 0) {  // the covered pixels (alpha 1), the same in every pass
        for (std::size_t i = 0; i < pixels; ++i)
          if (part[4 * i + 3] != 0.f) r.border_pixels.push_back(static_cast<std::int32_t>(i));
        r.border_parts.resize(r.border_pixels.size());
      }
      for (std::size_t b = 0; b < r.border_pixels.size(); ++b) {
        const float* p = &part[4 * static_cast<std::size_t>(r.border_pixels[b])];
        r.border_parts[b][k] = {p[0], p[1], p[2]};
      }
    }
    // The depth-aware composite's rays, for frames that carry their depth: the depth coordinate map
    // (pass 1's flat points and pupil crossings) and, from the depth strips, each border part's ray
    // and the pixel whose crossing it takes (two passes a part: 0–3, then 4–7).
    if (options_.depth != DepthMode::off) {
      CompositeTable::Recording::DepthRecording d;
      const Vec2 gain = pupil_gain(depth_geometry(profile_, m), {1.0, 1.0});
      d.parallax_gain = {f(gain.x), f(gain.y)};
      d.texture_scale = {texture.scale[0], texture.scale[1]};
      d.texture_offset = {texture.offset[0], texture.offset[1]};
      CoordinateMap rays;
      draw_depth_map(m, rays);
      d.rays.resize(4 * pixels);
      glGetTextureImage(rays.texture.id(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(d.rays.size() * sizeof(float)),
                        d.rays.data());
      const GLuint record = program(shaders::ProgramKind::depth_record);
      glProgramUniform1f(record, shaders::location::depth::pupil_per_lens, f(m.eye_relief_mm / m.gap_mm));
      upload_mapping(m, texture, 0, 0);
      glBindVertexArray(empty_vertex_array_.id());
      glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
      glViewport(0, 0, width, height);
      glUseProgram(record);
      d.border_parts.resize(r.border_pixels.size());
      for (int k = 0; k < 8; ++k) {
        const GLfloat zero[4] = {0.f, 0.f, 0.f, 0.f};
        glClearNamedFramebufferfv(fbo.id(), GL_COLOR, 0, zero);
        glProgramUniform1i(record, shaders::location::record_part, k);
        glDrawArrays(GL_TRIANGLES, 0, 6 * (m.lenses[0] + m.lenses[1] + 2));
        glGetTextureImage(part_texture.id(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(part.size() * sizeof(float)),
                          part.data());
        for (std::size_t b = 0; b < r.border_pixels.size(); ++b) {
          const float* p = &part[4 * static_cast<std::size_t>(r.border_pixels[b])];
          CompositeTable::Recording::DepthPart& to = d.border_parts[b][k & 3];
          if (k < 4) {
            to.u = p[0], to.v = p[1], to.crossing_x = p[2], to.crossing_y = p[3];
          } else {
            to.weight = p[0];
            to.hit_pixel = static_cast<std::int32_t>(p[2]) * width + static_cast<std::int32_t>(p[1]);
          }
        }
      }
      r.depth = std::move(d);
    }
  }
  gl::check_error("recording the composite table");
  return r;
}

void GlCompositor::set_depth(Eye eye, std::shared_ptr<const DisparitySurface> surface) {
  DepthSurface& d = depth_[static_cast<int>(eye)];
  if (surface == d.surface) return;
  d.surface = std::move(surface);
  if (!d.surface) return;
  context_->make_current();
  if (!d.texture || d.width != d.surface->width() || d.height != d.surface->height()) {
    d.texture = gl::make_texture_2d(GL_R32F, d.surface->width(), d.surface->height());
    d.bounds = gl::make_texture_2d(GL_R32F, d.surface->bound_width(), d.surface->bound_height());
    d.width = d.surface->width();
    d.height = d.surface->height();
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(d.texture.id(), 0, 0, 0, d.width, d.height, GL_RED, GL_FLOAT, d.surface->values().data());
  glTextureSubImage2D(d.bounds.id(), 0, 0, 0, d.surface->bound_width(), d.surface->bound_height(), GL_RED, GL_FLOAT,
                      d.surface->front_bounds().data());
  gl::check_error("uploading the disparity");
}

CompositeChoice composite_choice() {
  const char* choice = std::getenv("NELF_COMPOSITE");
  if (choice && std::string_view(choice) == "gl") return CompositeChoice::gl;
  if (choice && std::string_view(choice) == "table") return CompositeChoice::table;
  return CompositeChoice::automatic;
}

bool prefer_composite_table(const gl::Context& context) {
  const CompositeChoice choice = composite_choice();
  return choice == CompositeChoice::table || (choice == CompositeChoice::automatic && context.is_software());
}

EyeImages GlCompositor::compose(const StereoPair& views) {
  context_->make_current();
  EyeImages eyes;
  for (Eye eye : {Eye::left, Eye::right}) {
    const int e = static_cast<int>(eye);
    const View& v = eye == Eye::left ? views.left : views.right;
    if (v.image.empty()) throw std::invalid_argument("GlCompositor::compose: empty view");
    UploadedView& up = uploads_[e];
    if (!up.texture || up.width != v.image.width() || up.height != v.image.height()) {
      up.texture = upload_texture(v.image);
      up.width = v.image.width();
      up.height = v.image.height();
    } else {
      update_texture(up.texture, v.image);
    }
    EyeTarget& target = eye_targets_[e];
    if (!target.texture) {
      target.texture = gl::make_texture_2d(GL_RGBA16F, panel()[0], panel()[1]);
      target.fbo = gl::make_framebuffer(target.texture);
    }
    render_eye(eye, {up.texture.id(), up.width, up.height, v.display_aspect}, {target.fbo.id(), 0, 0});
    eyes[e] = read_back(target.fbo.id(), 0, 0, panel()[0], panel()[1]);
  }
  return eyes;
}

gl::Texture upload_texture(const Image& image, GLenum internal_format) {
  gl::Texture texture = gl::make_texture_2d(internal_format, image.width(), image.height());
  update_texture(texture, image);
  return texture;
}

void update_texture(const gl::Texture& texture, const Image& image) {
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(texture.id(), 0, 0, 0, image.width(), image.height(), GL_RGBA, GL_FLOAT, image.data());
  gl::check_error("uploading a view");
}

Image read_back(GLuint framebuffer, int x, int y, int width, int height) {
  Image image(width, height);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glNamedFramebufferReadBuffer(framebuffer, GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(x, y, width, height, GL_RGBA, GL_FLOAT, image.data());
  gl::check_error("reading an image back");
  return image;
}

}  // namespace nelf
