// Writes the seed corpora of the fuzz targets (docs/fuzzing.md): tiny valid inputs of every kind a
// target reads, made at build time with the ffmpeg CLI (media) and from the repository's own files
// (profiles), so that no binary file is committed. Usage: nelf_fuzz_seeds OUTPUT_DIR PROFILES_DIR
// writes OUTPUT_DIR/<target>/<seed>. The first byte of a media seed is the target's selector byte
// (see each fuzz_*.cpp), the rest the file.
extern "C" {
#include <libavutil/stereo3d.h>
}

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/image_files.hpp"

namespace fs = std::filesystem;

namespace {

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
  if (!out.flush()) throw std::runtime_error("cannot write " + path.string());
}

class Seeds {
 public:
  Seeds(fs::path out, fs::path scratch) : out_(std::move(out)), scratch_(std::move(scratch)) {}

  // ffmpeg ARGS scratch/NAME, quietly; returns the file's bytes.
  std::string media(const std::string& name, const std::string& args) const {
    const fs::path file = scratch_ / name;
    const std::string command = "ffmpeg -nostdin -hide_banner -loglevel error -y " + args + " '" + file.string() + "'";
    if (std::system(command.c_str()) != 0 || !fs::exists(file))
      throw std::runtime_error("ffmpeg could not make the seed " + name + ": " + command);
    return read_file(file);
  }

  void seed(const std::string& target, const std::string& name, const std::string& bytes) const {
    fs::create_directories(out_ / target);
    write_file(out_ / target / name, bytes);
  }
  void seed(const std::string& target, const std::string& name, char selector, const std::string& bytes) const {
    seed(target, name, std::string(1, selector) + bytes);
  }

 private:
  fs::path out_, scratch_;
};

std::string stereo3d_bytes(AVStereo3DType type, int flags) {
  AVStereo3D s{};
  s.type = type;
  s.flags = flags;
  return {reinterpret_cast<const char*>(&s), sizeof s};
}

// A tiny test picture as an input: `size` WxH, `frames` frames at 5 fps (bounded by the source's
// duration, so that further inputs may follow).
std::string picture(const std::string& size, int frames = 1) {
  return "-f lavfi -i testsrc=size=" + size + ":rate=5:duration=" + std::to_string(frames / 5.0);
}

void make_seeds(const fs::path& out, const fs::path& profiles) {
  const fs::path scratch = out / "scratch";
  fs::remove_all(out);
  fs::create_directories(scratch);
  const Seeds s(out, scratch);

  for (const auto& entry : fs::directory_iterator(profiles))
    if (entry.path().extension() == ".toml")
      s.seed("profile", entry.path().filename().string(), read_file(entry.path()));

  const char* names[] = {"Avatar.2009.3D.1080p.BluRay.Half-SBS.x264.mkv",
                         "Movie.2010.3D.HSBS.1080p.mkv",
                         "Some.Film.2012.3D.1080p.BluRay.SBS.DTS-GRP.mkv",
                         "Film.2011.3D.HOU.720p.mkv",
                         "Concert.3D.Full-OU.2160p.mkv",
                         "clip.3D.mp4",
                         "photo_rl.jpg",
                         "holiday.jps",
                         "trip.FSBS.mp4",
                         "Doc.H-TAB.1080p.ts",
                         "camera.mpo",
                         "plain.2d.mkv"};
  int n = 0;
  for (const char* name : names) s.seed("stereo_layout", "name" + std::to_string(n++), name);

  // Defect maps: selector = built-in profile in name order (0 hmz-t1, 1 hmz-t1-stock, 2
  // ii-2160-testbed, 3 lvt-prototype; fuzz_defect_map.cpp), then the map's text.
  const std::string defects =
      "# a dead pixel in the lit block, a stuck one near the panel's edge\n"
      "left 640 360 dead\n"
      "right 12 700 stuck 255 255 255   # white\n";
  std::string cluster;  // a 3 x 3 block: the bundles of its middle lose their healthy pixels
  for (int y = 359; y <= 361; ++y)
    for (int x = 639; x <= 641; ++x) cluster += "left " + std::to_string(x) + " " + std::to_string(y) + " dead\n";
  for (char profile = 0; profile < 4; ++profile) {
    s.seed("defect_map", "map" + std::to_string(profile), profile, defects);
    s.seed("defect_map", "cluster" + std::to_string(profile), profile, cluster);
  }

  // Stills: selector = extension (0 png, 1 jpg, 2 jps, 3 mpo) + 4 x name token (fuzz_still.cpp).
  const std::string png = s.media("a.png", picture("16x8"));
  const std::string gray16 = s.media("g.png", picture("8x8") + " -pix_fmt gray16be");
  const std::string jpeg = s.media("a.jpg", picture("32x8"));
  const std::string right = s.media("b.jpg", "-f lavfi -i color=c=blue:s=32x8 -frames:v 1");
  s.seed("still", "png", '\0', png);
  s.seed("still", "png-sbs", '\x04', png);
  s.seed("still", "png-gray16", '\0', gray16);
  s.seed("still", "jpeg", '\x01', jpeg);
  s.seed("still", "jps", '\x02', jpeg);
  s.seed("still", "mpo-concatenated", '\x03', jpeg + right);
  s.seed("still", "mpo-indexed", '\x03', nelf::test::mpo_with_index(jpeg, "gap", right));

  // Stereo metadata: selector 0 = raw AVStereo3D side data, 1 mkv, 2 mp4, 3 h264, 4 hevc.
  s.seed("stereo_metadata", "raw-sbs", '\0', stereo3d_bytes(AV_STEREO3D_SIDEBYSIDE, 0));
  s.seed("stereo_metadata", "raw-tab-inverted", '\0', stereo3d_bytes(AV_STEREO3D_TOPBOTTOM, AV_STEREO3D_FLAG_INVERT));
  s.seed("stereo_metadata", "raw-checkerboard", '\0', stereo3d_bytes(AV_STEREO3D_CHECKERBOARD, 0));
  const std::string x264 = " -c:v libx264 -preset ultrafast -g 2 -x264-params frame-packing=3";
  const std::string mkv = s.media("a.mkv", picture("32x16", 2) + x264 + " -metadata:s:v:0 stereo_mode=left_right");
  const std::string tab_mkv =
      s.media("b.mkv", picture("16x32", 2) + " -c:v ffv1 -metadata:s:v:0 stereo_mode=bottom_top");
  // The MP4 muxer writes st3d from the stream's stereo side data, which the remux carries over.
  const std::string mp4 = s.media("a.mp4", "-i '" + (scratch / "a.mkv").string() + "' -c copy -strict unofficial");
  const std::string h264 = s.media("a.h264", picture("32x16", 2) + x264 + " -f h264");
  const std::string hevc =
      s.media("a.hevc", picture("32x16", 2) + " -c:v libx265 -preset ultrafast -x265-params log-level=none -f hevc");
  s.seed("stereo_metadata", "mkv-sbs-sei", '\x01', mkv);
  s.seed("stereo_metadata", "mkv-bottom-top", '\x01', tab_mkv);
  s.seed("stereo_metadata", "mp4-st3d", '\x02', mp4);
  s.seed("stereo_metadata", "h264-sei", '\x03', h264);
  s.seed("stereo_metadata", "hevc", '\x04', hevc);

  // Video: selector = extension (0 mkv, 1 mp4, 2 ts, 3 m2ts, 4 mov, 5 avi, 6 h264, 7 webm).
  s.seed("video", "mkv-sbs-sei", '\0', mkv);
  s.seed("video", "mkv-ffv1", '\0', tab_mkv);
  s.seed("video", "mp4-st3d", '\x01', mp4);
  s.seed("video", "ts-mpeg2-mp2", '\x02',
         s.media("a.ts", picture("32x16", 2) + " -f lavfi -i sine=d=0.4 -c:v mpeg2video -c:a mp2 -shortest"));
  s.seed("video", "m2ts-h264-ac3", '\x03',
         s.media("a.m2ts", picture("32x16", 2) + " -f lavfi -i sine=d=0.4" + x264 + " -c:a ac3 -shortest"));
  s.seed("video", "mov-mjpeg-rotated", '\x04',
         s.media("a.mov", picture("32x16", 2) + " -c:v mjpeg -metadata:s:v:0 rotate=90"));
  s.seed("video", "avi-mpeg4", '\x05', s.media("a.avi", picture("32x16", 2) + " -c:v mpeg4"));
  s.seed("video", "h264-10bit", '\x06',
         s.media("b.h264", picture("32x16", 2) + " -c:v libx264 -preset ultrafast -pix_fmt yuv420p10le -f h264"));
  // A playlist with a network segment: with the network guard on it must be refused, not fetched.
  // Live variants of it (no #EXT-X-ENDLIST, a long target duration) must be given up, not waited on.
  s.seed("video", "hls-http", '\0',
         "#EXTM3U\n#EXT-X-TARGETDURATION:1\n#EXTINF:1,\nhttp://127.0.0.1:9/a.ts\n#EXT-X-ENDLIST\n");
  s.seed("video", "webm-vp8", '\x07', s.media("a.webm", picture("32x16", 2) + " -c:v libvpx"));
  fs::remove_all(scratch);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: nelf_fuzz_seeds OUTPUT_DIR PROFILES_DIR\n";
    return 2;
  }
  try {
    make_seeds(argv[1], argv[2]);
  } catch (const std::exception& e) {
    std::cerr << "nelf_fuzz_seeds: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
