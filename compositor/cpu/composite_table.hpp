#pragma once
// The fsaa-1 composite of one eye as a fixed table, replayed on the CPU.
//
// At fsaa 1 an eye image is a fixed linear function of the view's block means: the prefilter's
// separable box pass, then per pixel one bilinear tap of the prefiltered view through the
// coordinate map, and along the elemental-image borders up to four area-weighted taps. Only the
// view changes from frame to frame. On a software rasteriser (llvmpipe) every GL pass pays a large
// per-pixel overhead (~20 ns per pixel for a one-tap pass on the 2-core reference machine), so the
// same work done from a table on the CPU is several times cheaper. The table is recorded by the
// GL compositor's own shaders (GlCompositor::make_composite_table: the coordinate map, and the
// border strips writing down their taps instead of taking them), so the geometry has one source;
// this class only replays the box pass and the taps, with the arithmetic of GL's RGBA8 path
// (8-bit intermediates, 8-bit bilinear weights). It agrees with the GL path to within a code value
// or two (tests/compositor/gl/test_composite_table.cpp).
//
// With depth on, a table also holds what of each ray of the depth-aware composite does not change
// from frame to frame (recorded the same way, by GL's depth coordinate map and depth strips); per
// frame it searches each ray against the frame's surface and taps there, so frames with depth take
// the CPU path too.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace nelf {

class DisparitySurface;  // optics/depth.hpp

// The byte order of a table's output pixels. The block means are always RGBA8; BGRA is what X11
// and DRM framebuffers hold, so a packed frame made in it goes to the screen by plain copies (on
// llvmpipe a 1:1 blit between the same formats is a memcpy, a swizzling one a shader pass).
enum class ChannelOrder { rgba, bgra };

// One axis of the prefilter's separable box pass (shaders/prefilter_box.frag): for each output
// sample, the input cells it overlaps and their weights (overlap / box width).
struct BoxAxis {
  std::vector<int> first;      // first input cell, per output sample
  std::vector<int> begin;      // index into `weights` per output sample, plus one past the end
  std::vector<float> weights;  // per overlapped cell, in order from `first`
};

// prefilter_box.frag's weights for `outputs` samples spaced `spacing` view texels apart, the first
// sample's edge at `origin` (≤ 0), a box of `box` texels, input cells of `cell` texels, `cells` of
// them, a view `extent` texels long (black beyond it).
BoxAxis make_box_axis(int outputs, double origin, double spacing, double box, double cell, int cells, double extent);

class CompositeTable {
 public:
  struct BorderPart {
    float x = 0.f, y = 0.f, weight = 0.f;
  };
  // What GlCompositor::make_composite_table recorded for one eye.
  struct Recording {
    std::array<int, 2> panel{0, 0};        // eye image size
    std::array<int, 2> reduced{0, 0};      // size of the block-mean image render() takes
    std::array<int, 2> prefiltered{0, 0};  // size of the box pass's output (margins included)
    BoxAxis horizontal, vertical;          // the box pass, per axis
    std::vector<float> coordinates;        // panel[0]·panel[1]·2: pass 1's texture coordinate, < 0 black
    // The pixels the border strips redraw (y · panel[0] + x; none without a lens array), and for
    // each its four parts: texture coordinate and weight (0: absent, or a black lens).
    std::vector<std::int32_t> border_pixels;
    std::vector<std::array<BorderPart, 4>> border_parts;
    // The depth-aware composite's rays (recorded with CompositorOptions::depth on, lens arrays
    // only), for frames that carry their depth: what of each ray does not change from frame to
    // frame, as GL's depth coordinate map and its border strips (elemental.frag, NELF_DEPTH_MAP and
    // NELF_DEPTH_HITS) hold it.
    struct DepthPart {
      float u = 0.f, v = 0.f;                    // where the part's ray meets the flat screen (uv)
      float crossing_x = 0.f, crossing_y = 0.f;  // where it crosses the pupil plane (mm)
      float weight = 0.f;                        // 0: absent, or a black lens
      std::int32_t hit_pixel = 0;                // the pixel whose crossing it takes (y · panel[0] + x)
    };
    struct DepthRecording {
      std::vector<float> rays;  // panel[0]·panel[1]·4: flat-screen uv, pupil crossing (mm); u < -1e8 black
      std::vector<std::array<DepthPart, 4>> border_parts;  // per border pixel, as border_parts
      std::array<float, 2> parallax_gain{0.f, 0.f};        // uv shift per mm of crossing per unit of δ / W
      std::array<float, 2> texture_scale{1.f, 1.f}, texture_offset{0.f, 0.f};  // uv → prefiltered texture
    };
    std::optional<DepthRecording> depth;
  };

  // One bilinear tap of the prefiltered image: its top-left texel (y · prefiltered[0] + x; the
  // black texel is prefiltered[0] · prefiltered[1], the first of the spare rows below the image)
  // and the weights (out of 256) of it, its right neighbour and the two below them. The weights sum
  // to 256; all four 0 stands for 256 on the top-left texel (the only way a weight reaches 256:
  // make_tap moves such a tap onto that texel), so a tap is 8 bytes, not 12.
  struct Tap {
    std::int32_t texel = 0;
    std::array<std::uint8_t, 4> weights{};
  };
  struct BorderPixel {
    std::int32_t x = 0, y = 0;  // in the panel
    std::array<Tap, 4> taps;
    std::array<float, 4> weights{};  // per part; ≤ 0: no part
  };
  // A ray of the depth-aware composite: where it meets the flat screen (uv; u < -1e8: a black
  // pixel) and its uv shift per unit of δ / W (the pupil crossing times the parallax gain).
  struct DepthRay {
    float u = 0.f, v = 0.f, gain_u = 0.f, gain_v = 0.f;
  };
  struct DepthBorderPixel {
    std::int32_t x = 0, y = 0;  // in the panel
    std::array<DepthRay, 4> rays;
    std::array<float, 4> weights{};            // per part; ≤ 0: no part
    std::array<std::int32_t, 4> hit_pixels{};  // per part, the pixel whose crossing it takes
  };
  struct DepthTable {
    std::vector<DepthRay> rays;             // per pixel (pass 1)
    std::vector<DepthBorderPixel> borders;  // pass 2
    std::array<float, 2> texture_scale{1.f, 1.f}, texture_offset{0.f, 0.f};
  };
  // What render() replays, built from a Recording (what a CompositeTableCache keeps: a table loaded
  // from it needs no make_tap per pixel).
  struct Built {
    std::array<int, 2> panel{0, 0}, reduced{0, 0}, prefiltered{0, 0};  // as in Recording
    BoxAxis horizontal, vertical;
    std::vector<Tap> taps;             // per pixel, y · panel[0] + x (pass 1)
    std::vector<BorderPixel> borders;  // pass 2, in row order
    std::optional<DepthTable> depth;   // the depth-aware composite's rays, when recorded
  };

  explicit CompositeTable(const Recording& recording);
  // Everything that indexes memory is checked (a Built may come from a cache file); throws
  // std::invalid_argument when it does not hold together.
  explicit CompositeTable(Built built);

  std::array<int, 2> panel() const { return built_.panel; }
  // The block-mean image render() takes (GlReducedView's texture size).
  std::array<int, 2> reduced_size() const { return built_.reduced; }
  const Built& built() const { return built_; }

  // Whether the table holds the depth-aware composite's rays (render() with a surface).
  bool has_depth() const { return built_.depth.has_value(); }

  // Renders the eye from `reduced` (RGBA8 block means, row 0 the top row, `reduced_stride` bytes
  // per row) into `out` (the panel-sized eye image, 8 bits a channel in `order`, row 0 the top row,
  // `out_stride` bytes per row; alpha 255). With a `surface` (the view's depth; the table must
  // have_depth()), each pixel shows the view where its ray meets that surface, as GL's depth-aware
  // pass does (the search in the shader's float arithmetic, DisparitySurface::crossing); without,
  // the flat screen. Not thread-safe on one table (scratch buffers); use one per thread.
  void render(const std::uint8_t* reduced, std::size_t reduced_stride, std::uint8_t* out, std::size_t out_stride,
              ChannelOrder order = ChannelOrder::rgba, const DisparitySurface* surface = nullptr);

 private:
  // The box pass in fixed point: per output sample of an axis, pairs of input cells with their
  // weights in 1/32768 (see box_pass).
  struct FixedAxis {
    int pairs = 0;                      // most pairs any output sample needs (horizontal: all have this many)
    std::vector<std::int32_t> first;    // first input cell of each output's pairs
    std::vector<std::int32_t> begin;    // vertical: index into `weights` per output, plus one past the end
    std::vector<std::int16_t> weights;  // per pair: the two cells' weights, repeated ×4 (one SSE2 register)
  };

  static Built build(const Recording& recording);
  static Tap make_tap(float x, float y, std::array<int, 2> prefiltered);
  static void replay_taps(const Tap* taps, int count, const std::uint8_t* image, std::size_t image_row,
                          std::uint8_t* out);
  void box_pass(const std::uint8_t* reduced, std::size_t reduced_stride, ChannelOrder order);
  void render_depth(const DisparitySurface& surface, std::uint8_t* out, std::size_t out_stride);

  Built built_;
  FixedAxis horizontal_, vertical_;
  std::vector<std::uint8_t> input_;   // one row of the block means, zero-padded for the last pairs
  std::vector<std::uint8_t> across_;  // after the horizontal pass: across_row_ bytes × reduced[1] rows
  std::size_t across_row_ = 0;
  std::vector<std::uint8_t> image_;  // the prefiltered image: prefiltered[0] × prefiltered[1], RGBA8, spare rows
  std::vector<float> hits_;          // with depth: each pixel's crossing, δ / W (the border parts take them)
  std::vector<Tap> row_taps_;        // with depth: one row's taps, made per frame
};

// Opaque black RGBA8 (0, 0, 0, 255) over `rgba` (a whole number of pixels): what surrounds the
// panels in a packed frame.
void fill_opaque_black(std::span<std::uint8_t> rgba);

// Both eyes of a stereo frame into a packed frame (8 bits a channel in `order`, row 0 the top row,
// `stride` bytes a row), the two in parallel (each table has its own scratch buffers, so the frame
// is ready sooner): eye e, when it has a table and an origin, renders views[e] (block means,
// `view_stride` bytes a row) with its panel's top-left corner at origins[e] (x, y). Pixels outside
// the panels are left as they are.
// `surfaces`: per eye, the depth its view shows (render()'s surface), or null for the flat screen.
void render_packed_eyes(std::array<std::optional<CompositeTable>, 2>& tables,
                        const std::array<const std::uint8_t*, 2>& views, std::size_t view_stride,
                        const std::array<std::optional<std::pair<int, int>>, 2>& origins, std::uint8_t* packed,
                        std::size_t stride, ChannelOrder order = ChannelOrder::rgba,
                        const std::array<const DisparitySurface*, 2>& surfaces = {});

}  // namespace nelf
