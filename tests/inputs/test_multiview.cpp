// inputs/multiview: a second coded view found from codec parameters and NAL unit headers.
#include "inputs/multiview.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

extern "C" {
#include <libavcodec/avcodec.h>
}

namespace nelf {
namespace {

struct Parameters {
  explicit Parameters(AVCodecID id, std::vector<std::uint8_t> extra = {}) : codec(avcodec_parameters_alloc()) {
    codec->codec_id = id;
    codec->codec_type = AVMEDIA_TYPE_VIDEO;
    if (!extra.empty()) {
      codec->extradata = static_cast<std::uint8_t*>(av_mallocz(extra.size() + AV_INPUT_BUFFER_PADDING_SIZE));
      std::copy(extra.begin(), extra.end(), codec->extradata);
      codec->extradata_size = static_cast<int>(extra.size());
    }
  }
  ~Parameters() { avcodec_parameters_free(&codec); }
  Parameters(const Parameters&) = delete;
  Parameters& operator=(const Parameters&) = delete;
  AVCodecParameters* codec;
};

// IDR slice of the base view, then an MVC slice extension (type 20), Annex B.
const std::vector<std::uint8_t> kAnnexBMvc = {0, 0, 0, 1, 0x65, 0x88, 0x84, 0, 0, 1, 0x74, 0x00, 0x00, 0x47, 0x88};
const std::vector<std::uint8_t> kAnnexBPlain = {0, 0, 0, 1, 0x67, 0x64, 0x00, 0x1f, 0, 0, 1, 0x65, 0x88, 0x84};

TEST(Multiview, H264NalTypesInAnnexB) {
  Parameters h264(AV_CODEC_ID_H264);
  EXPECT_EQ(multiview_from_packet(*h264.codec, kAnnexBMvc), Multiview::h264_mvc);
  EXPECT_EQ(multiview_from_packet(*h264.codec, kAnnexBPlain), Multiview::none);
  EXPECT_EQ(multiview_from_codec(*h264.codec), Multiview::none);
}

TEST(Multiview, H264LengthPrefixedAfterAvcC) {
  // avcC: version 1, profile, compatibility, level, 0xff (4-byte lengths), no parameter sets.
  Parameters h264(AV_CODEC_ID_H264, {1, 0x64, 0x00, 0x1f, 0xff, 0xe0, 0x00});
  const std::vector<std::uint8_t> mvc = {0, 0, 0, 3, 0x65, 0x88, 0x84, 0, 0, 0, 2, 0x6f, 0x80};
  const std::vector<std::uint8_t> plain = {0, 0, 0, 3, 0x65, 0x88, 0x84};
  EXPECT_EQ(multiview_from_packet(*h264.codec, mvc), Multiview::h264_mvc);
  EXPECT_EQ(multiview_from_packet(*h264.codec, plain), Multiview::none);
  // A length past the packet's end reads as damage, not as a view.
  const std::vector<std::uint8_t> damaged = {0, 0, 0, 9, 0x74, 0x00};
  EXPECT_EQ(multiview_from_packet(*h264.codec, damaged), Multiview::none);
}

TEST(Multiview, H264MultiviewProfiles) {
  Parameters h264(AV_CODEC_ID_H264);
  h264.codec->profile = 128;
  EXPECT_EQ(multiview_from_codec(*h264.codec), Multiview::h264_mvc);
  h264.codec->profile = 118;
  EXPECT_EQ(multiview_from_codec(*h264.codec), Multiview::h264_mvc);
  h264.codec->profile = 100;
  EXPECT_EQ(multiview_from_codec(*h264.codec), Multiview::none);
}

TEST(Multiview, HevcLayerAboveZero) {
  Parameters hevc(AV_CODEC_ID_HEVC);
  // TRAIL_R (type 1) in layer 0, then in layer 1: the second byte's top five bits are the layer.
  const std::vector<std::uint8_t> layered = {0, 0, 1, 0x02, 0x01, 0xaf, 0, 0, 1, 0x02, 0x09, 0xaf};
  const std::vector<std::uint8_t> base = {0, 0, 1, 0x02, 0x01, 0xaf};
  EXPECT_EQ(multiview_from_packet(*hevc.codec, layered), Multiview::mv_hevc);
  EXPECT_EQ(multiview_from_packet(*hevc.codec, base), Multiview::none);
  EXPECT_EQ(multiview_from_packet(*hevc.codec, {}), Multiview::none);
}

TEST(Multiview, OtherCodecsAreNever) {
  Parameters vp9(AV_CODEC_ID_VP9);
  EXPECT_EQ(multiview_from_packet(*vp9.codec, kAnnexBMvc), Multiview::none);
  EXPECT_EQ(to_string(Multiview::h264_mvc), "H.264 MVC");
  EXPECT_EQ(to_string(Multiview::mv_hevc), "MV-HEVC");
}

}  // namespace
}  // namespace nelf
