#pragma once
// How FFmpeg's pixel formats, colour tags and display matrix read for the decoder
// (inputs/video_source.cpp): rotation, colour matrix and range, bit depth, and the rotated copy
// of a converted frame.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

extern "C" {
#include <libavformat/avformat.h>
#include <libavutil/pixfmt.h>
}

#include "inputs/video_source.hpp"

namespace nelf::video_pixels {

// Clockwise rotation a player must apply, from the stream's display matrix, snapped to a quarter
// turn (the same reading as ffmpeg's autorotate: the matrix's angle is counter-clockwise).
int rotation_from_display_matrix(const AVStream& stream);

// The matrix an AVColorSpace tag names; `tagged` false (and BT.709) for tags nelf does not know.
ColorMatrix matrix_from_av(int space, bool& tagged);

// Untagged content: HD and up is BT.709, SD is BT.601 — what broadcast and players assume.
ColorMatrix default_matrix_for_height(int height);

// The SWS_CS_* coefficients swscale converts `matrix` with.
int sws_colorspace_for(ColorMatrix matrix);

// The deprecated "J" formats mean full-range YUV; swscale wants the plain format plus the range.
AVPixelFormat without_jpeg_range(AVPixelFormat format, bool& full_range);

// YUV or grey samples (not RGB, not a palette).
bool is_yuv_or_gray(AVPixelFormat format);

// Whether samples in `format` tagged `range` use the full code range. Untagged YUV is limited
// (video); untagged grey is full (stills, as swscale assumes); RGB and palettes are always full.
bool is_full_range(AVPixelFormat format, int range);

// Bits of the first component (8 when FFmpeg does not say).
int bits_of(AVPixelFormat format);

// Copies a tightly packed RGBA image from `src` rows into `dst`, rotated clockwise by `degrees`.
template <typename Channel>
void copy_rotated(const uint8_t* src, int src_stride_bytes, int width, int height, int degrees,
                  std::vector<Channel>& dst) {
  dst.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4);
  const int out_width = (degrees == 90 || degrees == 270) ? height : width;
  for (int y = 0; y < height; ++y) {
    const auto* row = reinterpret_cast<const Channel*>(src + static_cast<std::ptrdiff_t>(y) * src_stride_bytes);
    if (degrees == 0) {
      std::copy(row, row + static_cast<std::ptrdiff_t>(width) * 4,
                dst.begin() + static_cast<std::ptrdiff_t>(y) * width * 4);
      continue;
    }
    for (int x = 0; x < width; ++x) {
      int out_x = x, out_y = y;
      if (degrees == 90) {
        out_x = height - 1 - y;
        out_y = x;
      } else if (degrees == 180) {
        out_x = width - 1 - x;
        out_y = height - 1 - y;
      } else {  // 270
        out_x = y;
        out_y = width - 1 - x;
      }
      const std::size_t o =
          (static_cast<std::size_t>(out_y) * static_cast<std::size_t>(out_width) + static_cast<std::size_t>(out_x)) * 4;
      std::copy(row + x * 4, row + x * 4 + 4, dst.begin() + static_cast<std::ptrdiff_t>(o));
    }
  }
}

}  // namespace nelf::video_pixels
