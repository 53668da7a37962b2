// The shader contract (compositor/gl/shader_interface.hpp) against the programs GL links: the
// mapping block's std140 offsets as the C++ mirror has them, and each texture unit and uniform
// location where the C++ side sets it. The names appear here only, to ask GL.
#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "compositor/gl/shader_interface.hpp"
#include "compositor/gl/shader_programs.hpp"
#include "core/gl/objects.hpp"
#include "support/gl_test_support.hpp"

namespace nelf {
namespace {

using shaders::MappingBlock;
using shaders::ProgramKind;

gl::Program link(ProgramKind kind, int subsamples = 1) {
  test::shared_gl_context()->make_current();
  const shaders::ProgramSource source = shaders::program_source(kind, subsamples);
  return gl::make_program(source.vertex, source.fragment, source.defines);
}

GLint resource(GLuint program, GLenum interface, const char* name, GLenum property) {
  const GLuint index = glGetProgramResourceIndex(program, interface, name);
  if (index == GL_INVALID_INDEX) return -1;
  GLint value = -1;
  glGetProgramResourceiv(program, interface, index, 1, &property, 1, nullptr, &value);
  return value;
}

GLint sampler_unit(GLuint program, const char* name) {
  GLint unit = -1;
  glGetUniformiv(program, glGetUniformLocation(program, name), &unit);
  return unit;
}

const std::vector<std::pair<const char*, std::size_t>>& mapping_members() {
  static const std::vector<std::pair<const char*, std::size_t>> members = {
      {"u_texture_scale", offsetof(MappingBlock, texture_scale)},
      {"u_texture_offset", offsetof(MappingBlock, texture_offset)},
      {"u_region_origin", offsetof(MappingBlock, region_origin)},
      {"u_panel", offsetof(MappingBlock, panel)},
      {"u_pixel_pitch", offsetof(MappingBlock, pixel_pitch)},
      {"u_shift", offsetof(MappingBlock, shift)},
      {"u_rotation", offsetof(MappingBlock, rotation)},
      {"u_lattice_offset", offsetof(MappingBlock, lattice_offset)},
      {"u_screen_centre", offsetof(MappingBlock, screen_centre)},
      {"u_screen_size", offsetof(MappingBlock, screen_size)},
      {"u_view_size", offsetof(MappingBlock, view_size)},
      {"u_first_lens", offsetof(MappingBlock, first_lens)},
      {"u_lenses", offsetof(MappingBlock, lenses)},
      {"u_to_lens_plane", offsetof(MappingBlock, to_lens_plane)},
      {"u_lens_pitch", offsetof(MappingBlock, lens_pitch)},
      {"u_chief_ray_scale", offsetof(MappingBlock, chief_ray_scale)},
      {"u_cut_outside", offsetof(MappingBlock, cut_outside)},
      {"u_has_lens_array", offsetof(MappingBlock, has_lens_array)},
  };
  return members;
}

TEST(ShaderInterface, EveryMappingProgramHasTheBlockAsTheMirrorLaysItOut) {
  for (ProgramKind kind : {ProgramKind::elemental, ProgramKind::border, ProgramKind::map, ProgramKind::record,
                           ProgramKind::depth, ProgramKind::depth_border, ProgramKind::depth_record}) {
    for (int subsamples : shaders::subsample_counts) {
      SCOPED_TRACE(testing::Message() << "program " << static_cast<int>(kind) << ", " << subsamples << " sub-samples");
      const gl::Program p = link(kind, subsamples);
      const GLuint block = glGetProgramResourceIndex(p.id(), GL_UNIFORM_BLOCK, "Mapping");
      ASSERT_NE(block, GL_INVALID_INDEX);
      GLint binding = -1, size = -1;
      glGetActiveUniformBlockiv(p.id(), block, GL_UNIFORM_BLOCK_BINDING, &binding);
      glGetActiveUniformBlockiv(p.id(), block, GL_UNIFORM_BLOCK_DATA_SIZE, &size);
      EXPECT_EQ(binding, static_cast<GLint>(shaders::mapping_block_binding));
      EXPECT_LE(size, static_cast<GLint>(sizeof(MappingBlock)));
      GLint members = -1;
      glGetActiveUniformBlockiv(p.id(), block, GL_UNIFORM_BLOCK_ACTIVE_UNIFORMS, &members);
      EXPECT_EQ(members, static_cast<GLint>(mapping_members().size())) << "a member without a C++ mirror";
      for (const auto& [name, offset] : mapping_members())
        EXPECT_EQ(resource(p.id(), GL_UNIFORM, name, GL_OFFSET), static_cast<GLint>(offset)) << name;
    }
  }
}

TEST(ShaderInterface, UniformLocationsAndTextureUnitsAreTheDeclaredOnes) {
  namespace at = shaders::location;
  const gl::Program record = link(ProgramKind::record);
  EXPECT_EQ(glGetUniformLocation(record.id(), "u_part"), at::record_part);
  EXPECT_EQ(glGetUniformLocation(record.id(), "u_view"), -1) << "the recording pass takes no tap";

  const gl::Program elemental = link(ProgramKind::elemental, 2);
  EXPECT_EQ(sampler_unit(elemental.id(), "u_view"), static_cast<GLint>(shaders::view_unit));

  const gl::Program lookup = link(ProgramKind::lookup);
  EXPECT_EQ(glGetUniformLocation(lookup.id(), "u_region_origin"), at::lookup_region_origin);
  EXPECT_EQ(sampler_unit(lookup.id(), "u_view"), static_cast<GLint>(shaders::view_unit));
  EXPECT_EQ(sampler_unit(lookup.id(), "u_map"), static_cast<GLint>(shaders::second_unit));

  const gl::Program reduce = link(ProgramKind::reduce);
  EXPECT_EQ(glGetUniformLocation(reduce.id(), "u_block"), at::reduce_block);
  EXPECT_EQ(sampler_unit(reduce.id(), "u_view"), static_cast<GLint>(shaders::view_unit));

  const gl::Program box = link(ProgramKind::box);
  EXPECT_EQ(glGetUniformLocation(box.id(), "u_axis"), at::box::axis);
  EXPECT_EQ(glGetUniformLocation(box.id(), "u_cell_size"), at::box::cell_size);
  EXPECT_EQ(glGetUniformLocation(box.id(), "u_out_spacing"), at::box::out_spacing);
  EXPECT_EQ(glGetUniformLocation(box.id(), "u_box_width"), at::box::box_width);
  EXPECT_EQ(glGetUniformLocation(box.id(), "u_out_origin"), at::box::out_origin);
  EXPECT_EQ(glGetUniformLocation(box.id(), "u_view_extent"), at::box::view_extent);
  EXPECT_EQ(sampler_unit(box.id(), "u_input"), static_cast<GLint>(shaders::view_unit));

  for (ProgramKind kind : {ProgramKind::depth, ProgramKind::depth_border}) {
    const gl::Program depth = link(kind, 2);
    EXPECT_EQ(glGetUniformLocation(depth.id(), "u_parallax_gain"), at::depth::parallax_gain);
    EXPECT_EQ(glGetUniformLocation(depth.id(), "u_disparity_range"), at::depth::disparity_range);
    EXPECT_EQ(glGetUniformLocation(depth.id(), "u_pupil_per_lens"), at::depth::pupil_per_lens);
    EXPECT_EQ(sampler_unit(depth.id(), "u_view"), static_cast<GLint>(shaders::view_unit));
    EXPECT_EQ(sampler_unit(depth.id(), "u_disparity"), static_cast<GLint>(shaders::disparity_unit));
    EXPECT_EQ(sampler_unit(depth.id(), "u_front_bound"), static_cast<GLint>(shaders::front_bound_unit));
  }
  const gl::Program lookup_depth = link(ProgramKind::depth_lookup);
  EXPECT_EQ(sampler_unit(lookup_depth.id(), "u_front_bound"), static_cast<GLint>(shaders::front_bound_unit));
  EXPECT_EQ(sampler_unit(lookup_depth.id(), "u_map"), static_cast<GLint>(shaders::second_unit));
  EXPECT_EQ(sampler_unit(lookup_depth.id(), "u_hits"), static_cast<GLint>(shaders::hits_image_unit));
  const gl::Program strips_from_hits = link(ProgramKind::depth_border_hits);
  EXPECT_EQ(glGetUniformLocation(strips_from_hits.id(), "u_parallax_gain"), at::depth::parallax_gain);
  EXPECT_EQ(glGetUniformLocation(strips_from_hits.id(), "u_pupil_per_lens"), at::depth::pupil_per_lens);
  EXPECT_EQ(sampler_unit(strips_from_hits.id(), "u_hits"), static_cast<GLint>(shaders::hits_unit));
  const gl::Program depth_record = link(ProgramKind::depth_record);
  EXPECT_EQ(glGetUniformLocation(depth_record.id(), "u_part"), at::record_part);
  EXPECT_EQ(glGetUniformLocation(depth_record.id(), "u_pupil_per_lens"), at::depth::pupil_per_lens);
  EXPECT_EQ(glGetUniformLocation(depth_record.id(), "u_view"), -1) << "the recording pass takes no tap";
  EXPECT_EQ(glGetUniformLocation(depth_record.id(), "u_hits"), -1) << "it records which crossing, not the crossing";

  const gl::Program text = link(ProgramKind::text_overlay);
  EXPECT_EQ(glGetUniformLocation(text.id(), "u_box_origin"), at::text_box_origin);
  EXPECT_EQ(glGetUniformLocation(text.id(), "u_box_size"), at::text_box_size);
  EXPECT_EQ(sampler_unit(text.id(), "u_view"), static_cast<GLint>(shaders::view_unit));
  EXPECT_EQ(sampler_unit(text.id(), "u_label"), static_cast<GLint>(shaders::second_unit));
  gl::check_error("querying the shader interface");
}

}  // namespace
}  // namespace nelf
