#pragma once
// A PGS subtitle file (.sup, as Blu-ray rips carry them) written at test time: FFmpeg has no PGS
// encoder, so the segments are laid out here as the format defines them (presentation, window,
// palette, object and end segments, each behind "PG" and its 90 kHz time stamps); FFmpeg's sup
// demuxer and pgssub decoder read them back. The ffmpeg CLI turns one into DVB or VobSub subtitles
// (-c:s dvbsub / dvdsub) for the other bitmap formats.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace nelf::test {

// An opaque white box on the subtitle canvas.
struct PgsBox {
  int x = 0, y = 0, w = 0, h = 0;
};

// Boxes shown from `start_s` until `end_s` (a display set that clears the screen then).
struct PgsCue {
  double start_s = 0.0, end_s = 0.0;
  std::vector<PgsBox> boxes;
};

namespace pgs_detail {

inline void be16(std::string& out, int v) {
  out += static_cast<char>((v >> 8) & 0xff);
  out += static_cast<char>(v & 0xff);
}

inline void segment(std::string& file, double t_s, int type, const std::string& payload) {
  const auto pts = static_cast<std::uint32_t>(t_s * 90000.0 + 0.5);
  file += "PG";
  for (int shift = 24; shift >= 0; shift -= 8) file += static_cast<char>((pts >> shift) & 0xff);  // PTS
  file += std::string(4, '\0');                                                                   // DTS
  file += static_cast<char>(type);
  be16(file, static_cast<int>(payload.size()));
  file += payload;
}

// Run-length coded lines of palette entries 0 (transparent) and 1 (white).
inline std::string rle(const std::vector<std::vector<bool>>& rows) {
  std::string out;
  for (const std::vector<bool>& row : rows) {
    std::size_t x = 0;
    while (x < row.size()) {
      std::size_t run = 1;
      while (x + run < row.size() && row[x + run] == row[x] && run < 16383) ++run;
      out += '\0';
      const int colour = row[x] ? 1 : 0;
      if (colour == 0 && run < 64) {
        out += static_cast<char>(run);
      } else if (colour == 0) {
        out += static_cast<char>(0x40 | (run >> 8));
        out += static_cast<char>(run & 0xff);
      } else if (run < 64) {
        out += static_cast<char>(0x80 | run);
        out += static_cast<char>(colour);
      } else {
        out += static_cast<char>(0xC0 | (run >> 8));
        out += static_cast<char>(run & 0xff);
        out += static_cast<char>(colour);
      }
      x += run;
    }
    out += std::string(2, '\0');  // end of line
  }
  return out;
}

}  // namespace pgs_detail

// Writes `cues` (in time order, not overlapping) for a `canvas_w`×`canvas_h` video as a .sup file.
inline std::filesystem::path write_pgs(const std::filesystem::path& path, int canvas_w, int canvas_h,
                                       const std::vector<PgsCue>& cues) {
  using pgs_detail::be16;
  using pgs_detail::segment;
  std::string file;
  int composition = 0;
  for (const PgsCue& cue : cues) {
    if (cue.boxes.empty()) throw std::invalid_argument("write_pgs: a cue without boxes");
    int x0 = canvas_w, y0 = canvas_h, x1 = 0, y1 = 0;
    for (const PgsBox& b : cue.boxes) {
      x0 = std::min(x0, b.x);
      y0 = std::min(y0, b.y);
      x1 = std::max(x1, b.x + b.w);
      y1 = std::max(y1, b.y + b.h);
    }
    const int w = x1 - x0, h = y1 - y0;
    std::vector<std::vector<bool>> rows(static_cast<std::size_t>(h), std::vector<bool>(static_cast<std::size_t>(w)));
    for (const PgsBox& b : cue.boxes)
      for (int y = b.y; y < b.y + b.h; ++y)
        for (int x = b.x; x < b.x + b.w; ++x)
          rows[static_cast<std::size_t>(y - y0)][static_cast<std::size_t>(x - x0)] = true;
    const auto presentation = [&](bool with_object) {
      std::string p;
      be16(p, canvas_w);
      be16(p, canvas_h);
      p += '\x10';  // frame rate (unused)
      be16(p, composition++);
      p += with_object ? '\x80' : '\x00';  // epoch start / normal
      p += '\0';                           // no palette-only update
      p += '\0';                           // palette 0
      p += static_cast<char>(with_object ? 1 : 0);
      if (with_object) {
        be16(p, 0);  // object 0
        p += '\0';   // window 0
        p += '\0';   // not cropped
        be16(p, x0);
        be16(p, y0);
      }
      return p;
    };
    std::string window = "\x01";  // one window: 0 at the object's place
    window += '\0';
    be16(window, x0);
    be16(window, y0);
    be16(window, w);
    be16(window, h);
    // Palette 0, version 0: entry 0 transparent, entry 1 opaque white (Y, Cr, Cb, alpha).
    const std::string palette("\x00\x00\x00\x10\x80\x80\x00\x01\xeb\x80\x80\xff", 12);
    const std::string data = pgs_detail::rle(rows);
    std::string object;
    be16(object, 0);   // object 0
    object += '\0';    // version 0
    object += '\xC0';  // first and last in sequence
    const auto length = static_cast<std::uint32_t>(data.size() + 4);
    object += static_cast<char>((length >> 16) & 0xff);
    object += static_cast<char>((length >> 8) & 0xff);
    object += static_cast<char>(length & 0xff);
    be16(object, w);
    be16(object, h);
    object += data;
    segment(file, cue.start_s, 0x16, presentation(true));
    segment(file, cue.start_s, 0x17, window);
    segment(file, cue.start_s, 0x14, palette);
    segment(file, cue.start_s, 0x15, object);
    segment(file, cue.start_s, 0x80, "");
    segment(file, cue.end_s, 0x16, presentation(false));
    segment(file, cue.end_s, 0x17, window);
    segment(file, cue.end_s, 0x80, "");
  }
  std::ofstream(path, std::ios::binary) << file;
  return path;
}

}  // namespace nelf::test
