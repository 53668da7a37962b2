#pragma once
// Where `nelf convert` sends its packed frames, one after the other: an encoded video file, an image
// sequence, one image, or raw RGBA on stdout. Chosen by the output name, one row each in the
// table of player/convert_video.cpp. A sink destroyed before finish() leaves nothing behind.
#include <memory>
#include <string>

#include "core/frames.hpp"

namespace nelf {

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  virtual void write(const PackedFrame& frame) = 0;
  // Everything written is complete and in place.
  virtual void finish() = 0;
  // What was written, for the last line: "out.mkv", "raw video to stdout".
  virtual std::string description() const = 0;
};

// `-`: the packed frames as 8-bit RGBA on file descriptor `fd` (stdout), frame after frame, no
// header (DESIGN.md §7), as `ffmpeg -f rawvideo -pix_fmt rgba -` reads them; 16-bit frames are
// rounded to 8 bits. Says on stderr, once, the frame size and rate a reader must be given.
// A reader that goes away (EPIPE) ends the conversion as a std::system_error(broken_pipe), which
// nelf ends quietly; any other failed write throws UserError naming it.
std::unique_ptr<FrameSink> open_raw_frame_sink(int fd, int width, int height, double frame_rate);

}  // namespace nelf
