#pragma once
// Packed RGBA8 frames (full-range RGB) to 8-bit YUV 4:2:0, BT.709 limited range: what the video
// encoder feeds libx264 and most other codecs. swscale does the same conversion through its
// generic scaler (RGB input unpacked in C, then a 1:1 "scale") at ~9 ms per 1280×1470 frame on the
// 2-core reference machine, as much as the whole CPU compositing; this one is a few milliseconds.
// Chroma is the mean of each 2×2 block (centre-sited, as libyuv's ARGBToI420); alpha is ignored.
#include <cstddef>
#include <cstdint>

namespace nelf {

struct YuvPlanes {
  std::uint8_t* y;
  std::uint8_t* u;
  std::uint8_t* v;
  std::ptrdiff_t y_stride, u_stride, v_stride;  // bytes per row
};

// Converts width×height RGBA8 pixels (`rgba`, rows `rgba_stride` bytes apart) into `out`
// (planes of width×height and ⌈width/2⌉×⌈height/2⌉). Odd sizes repeat the last column / row for chroma.
void rgba_to_yuv420_bt709(const std::uint8_t* rgba, std::ptrdiff_t rgba_stride, int width, int height,
                          const YuvPlanes& out);

}  // namespace nelf
