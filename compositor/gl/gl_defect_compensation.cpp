#include "compositor/gl/gl_defect_compensation.hpp"

#include <algorithm>
#include <tuple>
#include <vector>

#include "compositor/gl/shader_programs.hpp"

namespace nelf {

namespace {

gl::Program make_defect_program(shaders::ProgramKind kind) {
  const auto source = shaders::program_source(kind, 1);
  return gl::make_program(source.vertex, source.fragment, source.defines);
}

// An immutable shader storage buffer holding `data` (at least one element: GL refuses size 0).
template <class T>
gl::Buffer make_storage_buffer(const std::vector<T>& data) {
  GLuint id = 0;
  glCreateBuffers(1, &id);
  gl::Buffer buffer(id);
  const T none{};
  glNamedBufferStorage(id, static_cast<GLsizeiptr>(std::max<std::size_t>(data.size(), 1) * sizeof(T)),
                       data.empty() ? &none : data.data(), 0);
  gl::check_error("creating a defect compensation buffer");
  return buffer;
}

// The shaders' std430 layouts (shaders/defect_gather.vert, defect_apply.vert).
struct GpuDefect {
  std::array<std::int32_t, 4> pixel;
  std::array<float, 4> shown;
};
struct GpuShare {
  std::int32_t defect;
  float weight;
};
static_assert(sizeof(GpuDefect) == 32 && sizeof(GpuShare) == 8);

constexpr int max_slots_width = 4096;

}  // namespace

GlDefectCompensation::GlDefectCompensation()
    : gather_(make_defect_program(shaders::ProgramKind::defect_gather)),
      apply_(make_defect_program(shaders::ProgramKind::defect_apply)),
      vertex_array_(gl::make_vertex_array()) {}

void GlDefectCompensation::prepare(EyeBuffers& eye, const std::shared_ptr<const EyeDefectPlan>& plan) {
  if (eye.made_for == plan) return;
  eye.adding_only = eye.subtracting_only = 0;
  const auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < plan->panel[0] && y < plan->panel[1]; };
  std::vector<GpuDefect> defects;
  // Per defect, whether its difference (what it is sent, less what it shows) can be above zero in
  // some channel (not where it shows full white), and below (not where it shows black): a dead
  // pixel's only ever adds light, a white one's only takes it away.
  std::vector<std::array<bool, 2>> can_be;
  // (row, column, defect slot, weight): sorted, each pixel's shares lie together.
  std::vector<std::tuple<int, int, std::int32_t, float>> shares;
  for (const auto& correction : plan->corrections) {
    const PixelDefect& d = correction.defect;
    if (correction.shares.empty() || !inside(d.x, d.y)) continue;
    const auto rgb = d.shown_rgb();
    const auto slot = static_cast<std::int32_t>(defects.size());
    defects.push_back({{d.x, d.y, 0, 0}, {rgb[0] / 255.f, rgb[1] / 255.f, rgb[2] / 255.f, 0.f}});
    can_be.push_back({std::any_of(rgb.begin(), rgb.end(), [](std::uint8_t v) { return v < 255; }),
                      std::any_of(rgb.begin(), rgb.end(), [](std::uint8_t v) { return v > 0; })});
    for (const auto& share : correction.shares)
      if (inside(share.x, share.y) && share.weight != 0.f) shares.emplace_back(share.y, share.x, slot, share.weight);
  }
  std::sort(shares.begin(), shares.end());
  // Each pixel with its shares, and whether its sum can be positive or negative: only those that
  // can take the adding draw, only those that can the subtracting one (on llvmpipe each point
  // costs; most pixels need one of the two).
  struct Pixel {
    std::array<std::int32_t, 4> at;  // x, y, first share, shares
    bool positive = false, negative = false;
  };
  std::vector<Pixel> listed;
  std::vector<GpuShare> flat;
  for (std::size_t i = 0; i < shares.size(); ++i) {
    const auto [y, x, slot, weight] = shares[i];
    if (listed.empty() || listed.back().at[0] != x || listed.back().at[1] != y)
      listed.push_back({{x, y, static_cast<std::int32_t>(flat.size()), 0}});
    Pixel& pixel = listed.back();
    ++pixel.at[3];
    const auto [up, down] = can_be[static_cast<std::size_t>(slot)];
    pixel.positive |= weight > 0.f ? up : down;
    pixel.negative |= weight > 0.f ? down : up;
    flat.push_back({slot, weight});
  }
  // Adding only, then both, then subtracting only: the adding draw takes the first two groups,
  // the subtracting one the last two.
  std::vector<std::array<std::int32_t, 4>> pixels;
  for (int group = 0; group < 3; ++group)
    for (const Pixel& pixel : listed) {
      const int in = pixel.positive && pixel.negative ? 1 : pixel.positive ? 0 : pixel.negative ? 2 : -1;
      if (in != group) continue;
      if (group == 0) ++eye.adding_only;
      if (group == 2) ++eye.subtracting_only;
      pixels.push_back(pixel.at);
    }
  eye.defects = make_storage_buffer(defects);
  eye.pixels = make_storage_buffer(pixels);
  eye.shares = make_storage_buffer(flat);
  eye.defect_count = static_cast<int>(defects.size());
  eye.pixel_count = static_cast<int>(pixels.size());
  const int width = std::clamp(eye.defect_count, 1, max_slots_width);
  const std::array<int, 2> slots{width, std::max(1, (eye.defect_count + width - 1) / width)};
  if (slots != eye.slots) {
    eye.differences = gl::make_texture_2d(GL_RGBA32F, slots[0], slots[1]);
    eye.differences_fbo = gl::make_framebuffer(eye.differences);
    eye.slots = slots;
  }
  eye.made_for = plan;
}

void GlDefectCompensation::apply(const EyeDefectPlans& plans,
                                 const std::array<std::optional<std::pair<int, int>>, 2>& origins,
                                 const GlPackedTarget& target) {
  glBindVertexArray(vertex_array_.id());
  glDisable(GL_SCISSOR_TEST);
  for (std::size_t e = 0; e < 2; ++e) {
    if (!plans[e] || !origins[e]) continue;
    EyeBuffers& eye = eyes_[e];
    prepare(eye, plans[e]);
    if (eye.pixel_count == 0) continue;
    const auto [ox, oy] = *origins[e];

    // Pass 1: the defects' differences, read off the frame as drawn.
    glDisable(GL_BLEND);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, eye.differences_fbo.id());
    glViewport(0, 0, eye.slots[0], eye.slots[1]);
    glUseProgram(gather_.id());
    glProgramUniform2i(gather_.id(), 0, ox, oy);
    glProgramUniform2i(gather_.id(), 1, eye.slots[0], eye.slots[1]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, eye.defects.id());
    glBindTextureUnit(0, target.texture);
    glDrawArrays(GL_POINTS, 0, eye.defect_count);
    glBindTextureUnit(0, 0);  // the frame is drawn into next: not bound for reading as well

    // Pass 2: each pixel's sum of shares, its positive part added, its negative part subtracted.
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target.framebuffer);
    glViewport(0, 0, target.size[0], target.size[1]);
    glUseProgram(apply_.id());
    glProgramUniform2i(apply_.id(), 0, ox, oy);
    glProgramUniform2i(apply_.id(), 1, eye.slots[0], eye.slots[1]);
    glProgramUniform2i(apply_.id(), 2, target.size[0], target.size[1]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, eye.pixels.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, eye.shares.id());
    glBindTextureUnit(1, eye.differences.id());
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glBlendEquation(GL_FUNC_ADD);
    glProgramUniform1f(apply_.id(), 3, 1.f);
    glDrawArrays(GL_POINTS, 0, eye.pixel_count - eye.subtracting_only);
    glBlendEquation(GL_FUNC_REVERSE_SUBTRACT);
    glProgramUniform1f(apply_.id(), 3, -1.f);
    glDrawArrays(GL_POINTS, eye.adding_only, eye.pixel_count - eye.adding_only);
    glBlendEquation(GL_FUNC_ADD);
    glDisable(GL_BLEND);
    glBindTextureUnit(1, 0);
  }
  gl::check_error("hiding the defects");
}

}  // namespace nelf
