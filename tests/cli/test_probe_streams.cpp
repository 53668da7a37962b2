// `nelf probe` lists every stream of a file (plain and --json), and finds a second coded view
// (H.264 MVC) that FFmpeg does not decode: probe reports it, play and convert show it in 2D with one
// line that says why. FFmpeg cannot encode MVC: the test stream is an x264 stream with a subset SPS
// (NAL type 15) and an MVC slice extension (type 20) spliced into every access unit, as a Blu-ray
// 3D's dependent view interleaves with its base view, and read back by libavformat.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/media.hpp"
#include "support/release_media.hpp"
#include "support/test_support.hpp"

namespace nelf::test {
namespace {

// Splices MVC NAL units into an Annex B H.264 stream: a subset SPS after each PPS, a slice
// extension (view 1) after each slice of the base view.
void splice_mvc(const std::filesystem::path& from, const std::filesystem::path& to) {
  std::ifstream in(from, std::ios::binary);
  const std::vector<std::uint8_t> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::size_t> starts;  // first byte of each NAL unit, after its start code
  for (std::size_t i = 0; i + 3 <= data.size(); ++i)
    if (data[i] == 0 && data[i + 1] == 0 && data[i + 2] == 1) starts.push_back(i + 3);
  ASSERT_FALSE(starts.empty());
  // nal_ref_idc 3; profile_idc 128 (Stereo High) …; MVC header: view_id 1, anchor, inter-view.
  const std::vector<std::uint8_t> subset_sps = {0x6f, 0x80, 0x00, 0x1f, 0xe2, 0x40, 0x50, 0x16, 0xe4, 0x80};
  const std::vector<std::uint8_t> slice_extension = {0x74, 0x00, 0x00, 0x47, 0x88, 0x84, 0x21, 0xa5, 0x5a, 0x80};
  std::vector<std::uint8_t> out;
  const auto put = [&out](auto first, auto last) {
    out.insert(out.end(), {0, 0, 0, 1});
    out.insert(out.end(), first, last);
  };
  for (std::size_t n = 0; n < starts.size(); ++n) {
    std::size_t end = n + 1 < starts.size() ? starts[n + 1] - 3 : data.size();
    while (end > starts[n] && data[end - 1] == 0) --end;  // a 4-byte start code's leading zero
    const auto first = data.begin() + static_cast<std::ptrdiff_t>(starts[n]);
    put(first, data.begin() + static_cast<std::ptrdiff_t>(end));
    const int type = data[starts[n]] & 0x1f;
    if (type == 8) put(subset_sps.begin(), subset_sps.end());
    if (type == 1 || type == 5) put(slice_extension.begin(), slice_extension.end());
  }
  std::ofstream(to, std::ios::binary)
      .write(reinterpret_cast<const char*>(out.data()), static_cast<std::streamsize>(out.size()));
}

// Gives every VCL NAL unit (types 0-21) of an Annex B HEVC stream a copy in layer 1 (nuh_layer_id
// in the header's second byte), as MV-HEVC carries its second view; FFmpeg skips layers above 0.
void add_hevc_layer(const std::filesystem::path& from, const std::filesystem::path& to) {
  std::ifstream in(from, std::ios::binary);
  const std::vector<std::uint8_t> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i + 3 <= data.size(); ++i)
    if (data[i] == 0 && data[i + 1] == 0 && data[i + 2] == 1) starts.push_back(i + 3);
  ASSERT_FALSE(starts.empty());
  std::vector<std::uint8_t> out;
  for (std::size_t n = 0; n < starts.size(); ++n) {
    std::size_t end = n + 1 < starts.size() ? starts[n + 1] - 3 : data.size();
    while (end > starts[n] && data[end - 1] == 0) --end;
    std::vector<std::uint8_t> nal(data.begin() + static_cast<std::ptrdiff_t>(starts[n]),
                                  data.begin() + static_cast<std::ptrdiff_t>(end));
    ASSERT_GE(nal.size(), 2u);
    out.insert(out.end(), {0, 0, 0, 1});
    out.insert(out.end(), nal.begin(), nal.end());
    if (((nal[0] >> 1) & 0x3f) <= 21) {
      nal[1] = static_cast<std::uint8_t>((1 << 3) | (nal[1] & 7));
      out.insert(out.end(), {0, 0, 0, 1});
      out.insert(out.end(), nal.begin(), nal.end());
    }
  }
  std::ofstream(to, std::ios::binary)
      .write(reinterpret_cast<const char*>(out.data()), static_cast<std::streamsize>(out.size()));
}

CommandResult nelf_probe(const std::filesystem::path& path, const std::string& extra = "") {
  return run_nelf("probe " + extra + " " + q(path));
}

TEST(ProbeStreams, JsonListsEveryStreamChapterAndAttachment) {
  TempDir dir;
  const auto path = make_release_mkv(dir.path());
  const CommandResult r = nelf_probe(path, "--json");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const nlohmann::json& streams = j["streams"];
  ASSERT_EQ(streams.size(), 6u) << streams.dump();
  EXPECT_EQ(streams[0]["type"], "video");
  EXPECT_EQ(streams[0]["codec"], "h264");
  EXPECT_EQ(streams[0]["width"], 320);
  EXPECT_EQ(streams[0]["multiview"], nullptr);
  EXPECT_EQ(streams[0]["stereo_metadata"], nullptr);
  EXPECT_EQ(streams[1]["codec"], "ac3");
  EXPECT_EQ(streams[1]["channels"], 6);
  EXPECT_EQ(streams[1]["channel_layout"], "5.1(side)");
  EXPECT_EQ(streams[1]["language"], "eng");
  EXPECT_EQ(streams[1]["title"], "Surround 5.1");
  EXPECT_EQ(streams[2]["codec"], "aac");
  EXPECT_EQ(streams[2]["channels"], 2);
  EXPECT_EQ(streams[2]["channel_layout"], "stereo");
  EXPECT_EQ(streams[2]["language"], "fre");
  EXPECT_EQ(streams[3]["type"], "subtitle");
  EXPECT_EQ(streams[3]["codec"], "subrip");
  EXPECT_EQ(streams[3]["default"], true);
  EXPECT_EQ(streams[4]["default"], false);
  EXPECT_EQ(streams[4]["title"], "French");
  EXPECT_EQ(streams[5]["type"], "attachment");
  EXPECT_EQ(streams[5]["filename"], "DejaVuSans.ttf");
  EXPECT_EQ(streams[5]["mimetype"], "application/x-truetype-font");
  const nlohmann::json& chapters = j["chapters"];
  ASSERT_EQ(chapters.size(), 3u);
  EXPECT_EQ(chapters[1]["title"], "B");
  EXPECT_NEAR(chapters[1]["start_s"].get<double>(), 1.5, 1e-6);
  EXPECT_NEAR(chapters[1]["end_s"].get<double>(), 3.0, 1e-6);
  EXPECT_EQ(j["multiview"], nullptr);
}

TEST(ProbeStreams, PlainSummaryHasALinePerStreamAndChapter) {
  TempDir dir;
  const CommandResult r = nelf_probe(make_release_mkv(dir.path()));
  ASSERT_EQ(r.status, 0) << r.err;
  for (const std::string line :
       {"  #1 audio ac3 5.1(side), 48000 Hz [eng] \"Surround 5.1\"\n", "  #3 subtitle subrip [eng] (default)\n",
        "  #4 subtitle subrip [fre] \"French\"\n", "  #5 attachment ttf DejaVuSans.ttf (application/x-truetype-font)\n",
        "      1.500 -     3.000 s  B\n"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\nin:\n" << r.out;
}

TEST(ProbeStreams, StereoMetadataPerStream) {
  TempDir dir;
  const auto path = make_media(dir / "tb.mkv",
                               two_colour_input(64, 36, true, 3) + " -c:v ffv1 -metadata:s:v:0 stereo_mode=top_bottom");
  const nlohmann::json j = nlohmann::json::parse(nelf_probe(path, "--json").out);
  EXPECT_EQ(j["streams"][0]["stereo_metadata"]["type"], "top-bottom") << j.dump();
}

class MvcStream : public ::testing::Test {
 protected:
  void SetUp() override {
    make_media(dir_ / "base.h264", "-f lavfi -i testsrc2=s=320x180:r=10 -frames:v 10 -c:v libx264 -bf 0 -f h264");
    splice_mvc(dir_ / "base.h264", dir_ / "mvc.h264");
  }
  TempDir dir_;
};

TEST_F(MvcStream, ProbeReportsItAndShowsIt2D) {
  // Raw, and carried as they are into MPEG-TS and Matroska (length-prefixed NAL units there).
  make_media(dir_ / "mvc.ts", "-r 10 -i " + q(dir_ / "mvc.h264") + " -c copy");
  make_media(dir_ / "mvc.mkv", "-r 10 -i " + q(dir_ / "mvc.h264") + " -c copy");
  for (const char* name : {"mvc.h264", "mvc.ts", "mvc.mkv"}) {
    const CommandResult r = nelf_probe(dir_ / name, "--json");
    ASSERT_EQ(r.status, 0) << name << ": " << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["multiview"], "H.264 MVC") << name;
    EXPECT_EQ(j["streams"][0]["multiview"], "H.264 MVC") << name;
    EXPECT_EQ(j["layout"], "mono") << name;
    EXPECT_EQ(j["rule"], "multiview") << name;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("H.264 MVC stereo: FFmpeg decodes only its base view, so it plays in 2D"), std::string::npos)
        << r.err;
  }
  const CommandResult plain = nelf_probe(dir_ / "mvc.h264");
  EXPECT_NE(plain.out.find("multiview: H.264 MVC"), std::string::npos) << plain.out;
  // The base view alone is an ordinary stream.
  const nlohmann::json base = nlohmann::json::parse(nelf_probe(dir_ / "base.h264", "--json").out);
  EXPECT_EQ(base["multiview"], nullptr);
  EXPECT_EQ(base["rule"], "default");
}

TEST_F(MvcStream, ConvertAndPlaySayWhyItIs2D) {
  const CommandResult c = run_nelf("convert " + q(dir_ / "mvc.h264") + " " + q(dir_ / "out.mkv") +
                                   " --signal sbs --quiet --profile " + q(write_small_profile(dir_)));
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_NE(c.err.find("nelf: warning: mvc.h264: H.264 MVC stereo: FFmpeg decodes only its base view"),
            std::string::npos)
      << c.err;
  EXPECT_EQ(std::count(c.err.begin(), c.err.end(), '\n'), 1) << c.err;
  const CommandResult p = run_nelf("play " + q(dir_ / "mvc.h264") + " --output offscreen --no-audio --quiet");
  ASSERT_EQ(p.status, 0) << p.err;
  EXPECT_NE(p.err.find("H.264 MVC stereo: FFmpeg decodes only its base view"), std::string::npos) << p.err;
  // --layout still decides: the user knows better than nelf.
  const nlohmann::json j = nlohmann::json::parse(nelf_probe(dir_ / "mvc.h264", "--json --layout sbs-half").out);
  EXPECT_EQ(j["rule"], "flag");
  EXPECT_EQ(j["multiview"], "H.264 MVC");
}

TEST(ProbeStreams, MvHevcRawAndInMp4) {
  TempDir dir;
  make_media(dir / "base.hevc",
             "-f lavfi -i testsrc2=s=320x180:r=10 -frames:v 5 -c:v libx265 -x265-params log-level=error -f hevc");
  add_hevc_layer(dir / "base.hevc", dir / "mv.hevc");
  make_media(dir / "mv.mp4", "-r 10 -i " + q(dir / "mv.hevc") + " -c copy");  // hvcC, length-prefixed
  for (const char* name : {"mv.hevc", "mv.mp4"}) {
    const CommandResult r = nelf_probe(dir / name, "--json");
    ASSERT_EQ(r.status, 0) << name << ": " << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["multiview"], "MV-HEVC") << name;
    EXPECT_EQ(j["rule"], "multiview") << name;
    EXPECT_NE(r.err.find("MV-HEVC stereo: FFmpeg decodes only its base view"), std::string::npos) << r.err;
  }
  EXPECT_EQ(nlohmann::json::parse(nelf_probe(dir / "base.hevc", "--json").out)["multiview"], nullptr);
}

TEST(ProbeStreams, BadInputsFailInOneLine) {
  TempDir dir;
  write_file(dir / "fake.h264", std::string("\x00\x00\x01\x74\x00\x00\x47", 7) + "not really video");
  const CommandResult r = nelf_probe(dir / "fake.h264", "--json");
  EXPECT_NE(r.status, 0);
  EXPECT_LT(r.status, 128);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("fake.h264"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace nelf::test
