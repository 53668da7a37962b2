#include "inputs/pipewire_frame.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>

extern "C" {
#include <libavutil/imgutils.h>
#include <libavutil/pixdesc.h>
}

namespace nelf {
namespace {

// Every format read: its name, and for RGB the bytes a pixel and where R, G and B sit in it, for
// YUV FFmpeg's name of it (YV12 is I420 with its chroma planes the other way round: swapped when
// read). In the order a stream offers them.
struct ReadFormat {
  spa_video_format format;
  const char* name;
  int bytes, r, g, b;  // RGB; bytes 0 for YUV
  AVPixelFormat yuv;
};
constexpr ReadFormat kReadFormats[] = {
    {SPA_VIDEO_FORMAT_BGRx, "BGRx", 4, 2, 1, 0, AV_PIX_FMT_NONE},
    {SPA_VIDEO_FORMAT_BGRA, "BGRA", 4, 2, 1, 0, AV_PIX_FMT_NONE},
    {SPA_VIDEO_FORMAT_RGBx, "RGBx", 4, 0, 1, 2, AV_PIX_FMT_NONE},
    {SPA_VIDEO_FORMAT_RGBA, "RGBA", 4, 0, 1, 2, AV_PIX_FMT_NONE},
    {SPA_VIDEO_FORMAT_xRGB, "xRGB", 4, 1, 2, 3, AV_PIX_FMT_NONE},
    {SPA_VIDEO_FORMAT_ARGB, "ARGB", 4, 1, 2, 3, AV_PIX_FMT_NONE},
    {SPA_VIDEO_FORMAT_xBGR, "xBGR", 4, 3, 2, 1, AV_PIX_FMT_NONE},
    {SPA_VIDEO_FORMAT_ABGR, "ABGR", 4, 3, 2, 1, AV_PIX_FMT_NONE},
    {SPA_VIDEO_FORMAT_RGB, "RGB", 3, 0, 1, 2, AV_PIX_FMT_NONE},
    {SPA_VIDEO_FORMAT_BGR, "BGR", 3, 2, 1, 0, AV_PIX_FMT_NONE},
    {SPA_VIDEO_FORMAT_I420, "I420", 0, 0, 0, 0, AV_PIX_FMT_YUV420P},
    {SPA_VIDEO_FORMAT_YV12, "YV12", 0, 0, 0, 0, AV_PIX_FMT_YUV420P},
    {SPA_VIDEO_FORMAT_NV12, "NV12", 0, 0, 0, 0, AV_PIX_FMT_NV12},
    {SPA_VIDEO_FORMAT_NV21, "NV21", 0, 0, 0, 0, AV_PIX_FMT_NV21},
    {SPA_VIDEO_FORMAT_YUY2, "YUY2", 0, 0, 0, 0, AV_PIX_FMT_YUYV422},
    {SPA_VIDEO_FORMAT_UYVY, "UYVY", 0, 0, 0, 0, AV_PIX_FMT_UYVY422},
    {SPA_VIDEO_FORMAT_YVYU, "YVYU", 0, 0, 0, 0, AV_PIX_FMT_YVYU422},
    {SPA_VIDEO_FORMAT_Y42B, "Y42B", 0, 0, 0, 0, AV_PIX_FMT_YUV422P},
    {SPA_VIDEO_FORMAT_Y444, "Y444", 0, 0, 0, 0, AV_PIX_FMT_YUV444P},
};

// swscale's coefficients for the node's matrix; when it gives none, BT.601 up to 576 rows and
// BT.709 above, as FFmpeg and mpv guess.
int yuv_coefficients(const spa_video_info_raw& format) {
  switch (format.color_matrix) {
    case SPA_VIDEO_COLOR_MATRIX_BT709:
      return SWS_CS_ITU709;
    case SPA_VIDEO_COLOR_MATRIX_BT601:
      return SWS_CS_ITU601;
    case SPA_VIDEO_COLOR_MATRIX_SMPTE240M:
      return SWS_CS_SMPTE240M;
    case SPA_VIDEO_COLOR_MATRIX_BT2020:
      return SWS_CS_BT2020;
    case SPA_VIDEO_COLOR_MATRIX_FCC:
      return SWS_CS_FCC;
    default:
      return format.size.height > 576 ? SWS_CS_ITU709 : SWS_CS_ITU601;
  }
}

// Where a chunk's bytes start in its data (the chunk's offset wraps at maxsize, as SPA's ring does).
std::size_t chunk_offset(const spa_data& d) { return d.chunk->offset % std::max<std::uint32_t>(d.maxsize, 1); }

// Whether `rows` rows of `row` bytes, `stride` apart from `offset`, lie within the data.
bool fits(const spa_data& d, std::size_t offset, std::size_t stride, int rows, std::size_t row) {
  return stride >= row && rows > 0 && offset + stride * static_cast<std::size_t>(rows - 1) + row <= d.maxsize;
}

bool holds_frame(const spa_data& d) {
  return d.data && d.chunk && d.chunk->size > 0 && (d.chunk->flags & SPA_CHUNK_FLAG_CORRUPTED) == 0;
}

}  // namespace

std::vector<spa_video_format> PipeWireFrameReader::formats() {
  std::vector<spa_video_format> out;
  for (const ReadFormat& f : kReadFormats) out.push_back(f.format);
  return out;
}

std::string PipeWireFrameReader::formats_in_words() {
  std::string rgb, yuv;
  for (const ReadFormat& f : kReadFormats) {
    std::string& list = f.bytes > 0 ? rgb : yuv;
    list += (list.empty() ? "" : ", ") + std::string(f.name);
  }
  return "8-bit RGB frames (" + rgb + ") and 8-bit YUV ones (" + yuv + ")";
}

PipeWireFrameReader::PipeWireFrameReader(const spa_video_info_raw& format)
    : format_(format), width_(static_cast<int>(format.size.width)), height_(static_cast<int>(format.size.height)) {
  for (const ReadFormat& f : kReadFormats) {
    if (f.format != format.format) continue;
    if (f.bytes > 0) rgb_ = PixelOrder{f.bytes, f.r, f.g, f.b};
    yuv_ = f.yuv;
  }
}

bool PipeWireFrameReader::readable() const { return rgb_ || yuv_ != AV_PIX_FMT_NONE; }

std::optional<CapturedImage> PipeWireFrameReader::read(const spa_buffer& buffer) {
  if (!readable() || width_ <= 0 || height_ <= 0 || buffer.n_datas < 1 || !holds_frame(buffer.datas[0]))
    return std::nullopt;
  return rgb_ ? copy_rgb(buffer.datas[0]) : convert_yuv(buffer);
}

std::optional<CapturedImage> PipeWireFrameReader::copy_rgb(const spa_data& d) const {
  const PixelOrder o = *rgb_;
  const std::size_t row = static_cast<std::size_t>(width_) * static_cast<std::size_t>(o.bytes);
  const std::size_t stride = d.chunk->stride > 0 ? static_cast<std::size_t>(d.chunk->stride) : row;
  const std::size_t offset = chunk_offset(d);
  if (!fits(d, offset, stride, height_, row)) return std::nullopt;
  CapturedImage image;
  image.width = width_;
  image.height = height_;
  image.pixels.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4);
  const auto* base = static_cast<const std::uint8_t*>(d.data) + offset;
  if (o.bytes == 4 && o.r == 2 && o.g == 1 && o.b == 0) {
    // BGRx and BGRA, what desktops' screencasts send: kept in their order, a copy of each row (the
    // block means reorder a quarter of the bytes or fewer), as the X11 capture keeps its server's.
    image.order = ByteOrder::bgrx;
    av_image_copy_plane(image.pixels.data(), static_cast<int>(row), base, static_cast<int>(stride),
                        static_cast<int>(row), height_);
    return image;
  }
  for (int y = 0; y < height_; ++y) {
    const std::uint8_t* src = base + static_cast<std::size_t>(y) * stride;
    std::uint8_t* dst = image.pixels.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) * 4;
    for (int x = 0; x < width_; ++x, src += o.bytes, dst += 4) {
      dst[0] = src[o.r];
      dst[1] = src[o.g];
      dst[2] = src[o.b];
      dst[3] = 255;
    }
  }
  return image;
}

std::optional<CapturedImage> PipeWireFrameReader::convert_yuv(const spa_buffer& buffer) {
  const AVPixFmtDescriptor* desc = av_pix_fmt_desc_get(yuv_);
  const int planes = av_pix_fmt_count_planes(yuv_);
  int minimal[4] = {};  // each plane's bytes a row, unpadded
  if (av_image_fill_linesizes(minimal, yuv_, width_) < 0) return std::nullopt;
  const auto rows = [&](int plane) {
    return plane == 0 || plane == 3 ? height_ : AV_CEIL_RSHIFT(height_, desc->log2_chroma_h);
  };
  const std::uint8_t* data[4] = {};
  int strides[4] = {};
  if (buffer.n_datas >= static_cast<std::uint32_t>(planes)) {
    for (int p = 0; p < planes; ++p) {
      const spa_data& d = buffer.datas[p];
      if (!d.data || !d.chunk) return std::nullopt;
      const std::size_t row = static_cast<std::size_t>(minimal[p]);
      const std::size_t stride = d.chunk->stride > 0 ? static_cast<std::size_t>(d.chunk->stride) : row;
      const std::size_t offset = chunk_offset(d);
      if (!fits(d, offset, stride, rows(p), row)) return std::nullopt;
      data[p] = static_cast<const std::uint8_t*>(d.data) + offset;
      strides[p] = static_cast<int>(stride);
    }
  } else {
    const spa_data& d = buffer.datas[0];
    const int luma = d.chunk->stride > 0 ? d.chunk->stride : minimal[0];
    if (luma < minimal[0]) return std::nullopt;
    for (int p = 0; p < planes; ++p) strides[p] = minimal[p] * luma / minimal[0];
    const std::size_t offset = chunk_offset(d);
    std::uint8_t* pointers[4] = {};
    const int size =
        av_image_fill_pointers(pointers, yuv_, height_, static_cast<std::uint8_t*>(d.data) + offset, strides);
    if (size < 0 || offset + static_cast<std::size_t>(size) > d.maxsize) return std::nullopt;
    std::copy_n(pointers, planes, data);
  }
  if (format_.format == SPA_VIDEO_FORMAT_YV12) {
    std::swap(data[1], data[2]);
    std::swap(strides[1], strides[2]);
  }
  if (!yuv_to_rgba_) {
    // Bicubic chroma, rounded exactly: what ffmpeg's own conversion of the same frame gives.
    yuv_to_rgba_.reset(sws_getContext(width_, height_, yuv_, width_, height_, AV_PIX_FMT_RGBA,
                                      SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT, nullptr, nullptr, nullptr));
    if (!yuv_to_rgba_) return std::nullopt;
    const int* coefficients = sws_getCoefficients(yuv_coefficients(format_));
    const bool full_range = format_.color_range == SPA_VIDEO_COLOR_RANGE_0_255;
    sws_setColorspaceDetails(yuv_to_rgba_.get(), coefficients, full_range ? 1 : 0, coefficients, 1, 0, 1 << 16,
                             1 << 16);
  }
  CapturedImage image;
  image.width = width_;
  image.height = height_;
  image.pixels.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4);
  std::uint8_t* out[4] = {image.pixels.data(), nullptr, nullptr, nullptr};
  const int out_strides[4] = {width_ * 4, 0, 0, 0};
  if (sws_scale(yuv_to_rgba_.get(), data, strides, 0, height_, out, out_strides) != height_) return std::nullopt;
  return image;
}

}  // namespace nelf
