#include "inputs/video_pixels.hpp"

#include <cmath>
#include <cstring>

extern "C" {
#include <libavutil/display.h>
#include <libavutil/pixdesc.h>
#include <libswscale/swscale.h>
}

namespace nelf::video_pixels {

// Clockwise rotation a player must apply, from the stream's display matrix, snapped to a quarter
// turn (the same reading as ffmpeg's autorotate: the matrix's angle is counter-clockwise).
int rotation_from_display_matrix(const AVStream& stream) {
  size_t size = 0;
  const uint8_t* data = av_stream_get_side_data(&stream, AV_PKT_DATA_DISPLAYMATRIX, &size);
  if (data == nullptr || size < 9 * sizeof(int32_t)) return 0;
  int32_t matrix[9];
  std::memcpy(matrix, data, sizeof matrix);
  const double counter_clockwise = av_display_rotation_get(matrix);
  if (std::isnan(counter_clockwise)) return 0;
  const long quarter_turns = std::lround(-counter_clockwise / 90.0);
  return static_cast<int>(((quarter_turns % 4) + 4) % 4) * 90;
}

ColorMatrix matrix_from_av(int space, bool& tagged) {
  tagged = true;
  switch (space) {
    case AVCOL_SPC_BT709:
      return ColorMatrix::bt709;
    case AVCOL_SPC_BT470BG:
    case AVCOL_SPC_SMPTE170M:
      return ColorMatrix::bt601;
    case AVCOL_SPC_BT2020_NCL:
    case AVCOL_SPC_BT2020_CL:
      return ColorMatrix::bt2020;
    case AVCOL_SPC_SMPTE240M:
      return ColorMatrix::smpte240m;
    case AVCOL_SPC_FCC:
      return ColorMatrix::fcc;
    case AVCOL_SPC_RGB:
      return ColorMatrix::rgb;
    default:
      tagged = false;
      return ColorMatrix::bt709;
  }
}

// Untagged content: HD and up is BT.709, SD is BT.601 — what broadcast and players assume.
ColorMatrix default_matrix_for_height(int height) { return height >= 720 ? ColorMatrix::bt709 : ColorMatrix::bt601; }

int sws_colorspace_for(ColorMatrix matrix) {
  switch (matrix) {
    case ColorMatrix::bt601:
      return SWS_CS_ITU601;
    case ColorMatrix::bt709:
      return SWS_CS_ITU709;
    case ColorMatrix::bt2020:
      return SWS_CS_BT2020;
    case ColorMatrix::smpte240m:
      return SWS_CS_SMPTE240M;
    case ColorMatrix::fcc:
      return SWS_CS_FCC;
    case ColorMatrix::rgb:
      break;
  }
  return SWS_CS_DEFAULT;
}

// The deprecated "J" formats mean full-range YUV; swscale wants the plain format plus the range.
AVPixelFormat without_jpeg_range(AVPixelFormat format, bool& full_range) {
  switch (format) {
    case AV_PIX_FMT_YUVJ420P:
      full_range = true;
      return AV_PIX_FMT_YUV420P;
    case AV_PIX_FMT_YUVJ422P:
      full_range = true;
      return AV_PIX_FMT_YUV422P;
    case AV_PIX_FMT_YUVJ444P:
      full_range = true;
      return AV_PIX_FMT_YUV444P;
    case AV_PIX_FMT_YUVJ440P:
      full_range = true;
      return AV_PIX_FMT_YUV440P;
    case AV_PIX_FMT_YUVJ411P:
      full_range = true;
      return AV_PIX_FMT_YUV411P;
    default:
      return format;
  }
}

bool is_yuv_or_gray(AVPixelFormat format) {
  const AVPixFmtDescriptor* desc = av_pix_fmt_desc_get(format);
  return desc != nullptr && (desc->flags & AV_PIX_FMT_FLAG_RGB) == 0 && (desc->flags & AV_PIX_FMT_FLAG_PAL) == 0;
}

// Whether samples in `format` tagged `range` use the full code range. Untagged YUV is limited
// (video); untagged grey is full (stills, as swscale assumes); RGB and palettes are always full.
bool is_full_range(AVPixelFormat format, int range) {
  bool jpeg = false;
  without_jpeg_range(format, jpeg);
  if (jpeg || !is_yuv_or_gray(format)) return true;
  const AVPixFmtDescriptor* desc = av_pix_fmt_desc_get(format);
  const bool gray = desc != nullptr && desc->nb_components <= 2;
  if (gray) return range != AVCOL_RANGE_MPEG;
  return range == AVCOL_RANGE_JPEG;
}

int bits_of(AVPixelFormat format) {
  const AVPixFmtDescriptor* desc = av_pix_fmt_desc_get(format);
  return desc != nullptr && desc->nb_components > 0 ? desc->comp[0].depth : 8;
}

}  // namespace nelf::video_pixels
