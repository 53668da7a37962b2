#pragma once
// What the compositor's shaders declare with layout(...) qualifiers, mirrored in C++: the mapping's
// uniform block (shaders/mapping.glsl), texture units and uniform locations. No uniform is looked
// up by name; tests/compositor/gl/test_shader_interface.cpp checks this file against the linked programs.
#include <array>
#include <cstddef>
#include <cstdint>

namespace nelf::shaders {

// Binding points: `layout(binding = N)`.
inline constexpr unsigned mapping_block_binding = 0;  // uniform block Mapping
inline constexpr unsigned view_unit = 0;              // u_view (u_input in prefilter_box.frag)
inline constexpr unsigned second_unit = 1;            // u_map (elemental_lookup.frag), u_label (text_overlay.frag)
inline constexpr unsigned disparity_unit = 2;         // u_disparity (elemental.frag, NELF_DEPTH)
inline constexpr unsigned hits_unit = 3;              // u_hits (elemental.frag, NELF_DEPTH_HITS)
inline constexpr unsigned front_bound_unit = 4;       // u_front_bound (depth_search.glsl)
inline constexpr unsigned hits_image_unit = 0;        // image u_hits (elemental_depth_lookup.frag)

// Uniform locations: `layout(location = N)`, per shader.
namespace location {
inline constexpr int record_part = 0;           // elemental.frag, NELF_RECORD_TAPS: u_part
inline constexpr int lookup_region_origin = 0;  // elemental_lookup.frag: u_region_origin
inline constexpr int reduce_block = 0;          // prefilter_reduce.frag: u_block
namespace depth {                               // elemental.frag, NELF_DEPTH
inline constexpr int parallax_gain = 1, disparity_range = 2, pupil_per_lens = 3;
}
namespace box {  // prefilter_box.frag
inline constexpr int axis = 0, cell_size = 1, out_spacing = 2, box_width = 3, out_origin = 4, view_extent = 5;
}
inline constexpr int text_box_origin = 0, text_box_size = 1;  // text_overlay.frag
}  // namespace location

// The std140 block `Mapping` of shaders/mapping.glsl, field for field (vec2 → 2 floats at 8-byte
// alignment, ivec2 → 2 ints, bool as int). The offsets below are std140's for that order.
struct MappingBlock {
  std::array<float, 2> texture_scale{1.f, 1.f};
  std::array<float, 2> texture_offset{0.f, 0.f};
  std::array<float, 2> region_origin{0.f, 0.f};
  std::array<float, 2> panel{0.f, 0.f};
  std::array<float, 2> pixel_pitch{0.f, 0.f};
  std::array<float, 2> shift{0.f, 0.f};
  std::array<float, 2> rotation{1.f, 0.f};
  std::array<float, 2> lattice_offset{0.f, 0.f};
  std::array<float, 2> screen_centre{0.f, 0.f};
  std::array<float, 2> screen_size{0.f, 0.f};
  std::array<float, 2> view_size{0.f, 0.f};
  std::array<std::int32_t, 2> first_lens{0, 0};
  std::array<std::int32_t, 2> lenses{0, 0};
  float to_lens_plane = 0.f;
  float lens_pitch = 0.f;
  float chief_ray_scale = 0.f;
  std::int32_t cut_outside = 0;
  std::int32_t has_lens_array = 0;
  std::int32_t padding_ = 0;  // std140 rounds the block up to 16 bytes
};
static_assert(offsetof(MappingBlock, texture_scale) == 0);
static_assert(offsetof(MappingBlock, texture_offset) == 8);
static_assert(offsetof(MappingBlock, region_origin) == 16);
static_assert(offsetof(MappingBlock, panel) == 24);
static_assert(offsetof(MappingBlock, pixel_pitch) == 32);
static_assert(offsetof(MappingBlock, shift) == 40);
static_assert(offsetof(MappingBlock, rotation) == 48);
static_assert(offsetof(MappingBlock, lattice_offset) == 56);
static_assert(offsetof(MappingBlock, screen_centre) == 64);
static_assert(offsetof(MappingBlock, screen_size) == 72);
static_assert(offsetof(MappingBlock, view_size) == 80);
static_assert(offsetof(MappingBlock, first_lens) == 88);
static_assert(offsetof(MappingBlock, lenses) == 96);
static_assert(offsetof(MappingBlock, to_lens_plane) == 104);
static_assert(offsetof(MappingBlock, lens_pitch) == 108);
static_assert(offsetof(MappingBlock, chief_ray_scale) == 112);
static_assert(offsetof(MappingBlock, cut_outside) == 116);
static_assert(offsetof(MappingBlock, has_lens_array) == 120);
static_assert(sizeof(MappingBlock) == 128);

}  // namespace nelf::shaders
