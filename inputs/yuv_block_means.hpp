#pragma once
// Block means of 8-bit 4:2:0 video straight to RGBA8, the views the prefilter starts from
// (VideoSource::reduce_regions). Averaging is linear and so is the YUV→RGB matrix, so averaging
// Y, U and V over a block and converting the mean once gives the mean of the converted pixels
// (up to clipping of single pixels), at a fraction of the cost: swscale's area scaler with full
// chroma interpolation took ~2.9 ms an eye for a 960×1080 view on the reference machine, as much
// as compositing it.
#include <cstddef>
#include <cstdint>

namespace nelf {

// R, G, B in 0..255 from (Y, U − 128, V − 128) in code values: rgb = m · (Y − y_offset, U', V').
struct YuvToRgb {
  float y_offset = 16.f;
  float m[3][3] = {};
};
// The matrix swscale uses for the SWS_CS_* table entry `coefficients` (sws_getCoefficients: crv,
// cbu, cgu, cgv in 16.16 fixed point, for limited-range chroma), for limited or full range input.
YuvToRgb yuv_to_rgb_from_sws(const int coefficients[4], bool full_range);

struct Yuv420Planes {
  const std::uint8_t* y = nullptr;
  const std::uint8_t* u = nullptr;
  const std::uint8_t* v = nullptr;
  std::ptrdiff_t y_stride = 0, u_stride = 0, v_stride = 0;  // bytes a row
};

// Whether yuv420_block_means can take blocks of block_x × block_y pixels: both even (whole chroma
// samples per block) and at most 128 a side (16-bit sums).
bool yuv420_block_means_supported(int block_x, int block_y);

// The mean of every block_x × block_y block of the width × height region at `planes` (its top-left
// pixel; x and y of the region even), as RGBA8 (alpha 255) into `out`, (width / block_x) ×
// (height / block_y) pixels, `out_stride` bytes a row.
void yuv420_block_means(const Yuv420Planes& planes, int width, int height, int block_x, int block_y,
                        const YuvToRgb& matrix, std::uint8_t* out, std::size_t out_stride);

// 4:2:0 planes of `bits` (9 to 16) a sample, as FFmpeg's native-endian yuv420p10 and the like
// hold them.
struct Yuv420Planes16 {
  const std::uint16_t* y = nullptr;
  const std::uint16_t* u = nullptr;
  const std::uint16_t* v = nullptr;
  std::ptrdiff_t y_stride = 0, u_stride = 0, v_stride = 0;  // samples a row
  int bits = 10;
};

// yuv420_block_means of deeper samples, still to RGBA8 (an 8-bit output): the means are converted
// at their full precision and rounded with a 4×4 ordered dither, so that what the bits below 8
// held survives as a pattern the compositing's averaging smooths, instead of as banding.
void yuv420_block_means(const Yuv420Planes16& planes, int width, int height, int block_x, int block_y,
                        const YuvToRgb& matrix, std::uint8_t* out, std::size_t out_stride);

}  // namespace nelf
