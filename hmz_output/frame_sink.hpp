#pragma once
// Where `nelf convert` sends its packed frames, one after the other: an encoded video file, an image
// sequence, one image, or raw RGBA on stdout. Chosen by the output name, one row each in the
// table of hmz_output/output_drivers.cpp. A sink destroyed before finish() leaves nothing behind.
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "core/audio_stream.hpp"
#include "core/carried_streams.hpp"
#include "core/frames.hpp"
#include "hmz_output/sink.hpp"
#include "hmz_output/video_encoder.hpp"

namespace nelf {

class FrameSink : public Sink {
 public:
  virtual void write(const PackedFrame& frame) = 0;
  // Everything written is complete and in place.
  void finish() override = 0;
  // What was written, for the last line: "out.mkv", "raw video to stdout".
  std::string description() const override = 0;
  // Untimed: frames are written as fast as they are composited.
  double refresh_hz() const override { return 0.0; }
};

// What a file sink is opened with, once the packed frame's size is known.
struct FrameSinkRequest {
  std::string output;  // the output name as given: `-`, frames_%05d.png, x.png, out.mkv
  int width = 0, height = 0;
  int bits = 8;  // of the packed frames
  double frame_rate = 0.0;
  EncoderSettings encoder;           // codec, quality, -y, audio wanted
  std::optional<double> duration_s;  // --duration: carried streams end there at the latest
  // The source's own streams (a file's audio, subtitles, chapters), else its decoded sound; only
  // for a row that carries streams (OutputDriver::carries_streams), null when there are none.
  std::unique_ptr<CarriedStreams> carried;
  std::unique_ptr<AudioStream> audio;
  // Throws (UserError, status 2) when a file name is one of the inputs: every frame of an image
  // sequence is checked, as its names may expand to an input's. Empty: nothing to refuse.
  std::function<void(const std::string& name)> refuse_as_output;
  int raw_fd = 1;  // where the raw sink writes: stdout
};

// `-`: the packed frames as 8-bit RGBA on file descriptor `fd` (stdout), frame after frame, no
// header (DESIGN.md §7), as `ffmpeg -f rawvideo -pix_fmt rgba -` reads them; 16-bit frames are
// rounded to 8 bits. Says on stderr, once, the frame size and rate a reader must be given.
// A reader that goes away (EPIPE) ends the conversion as a std::system_error(broken_pipe), which
// nelf ends quietly; any other failed write throws UserError naming it.
std::unique_ptr<FrameSink> open_raw_frame_sink(int fd, int width, int height, double frame_rate);

// An encoded video file, with the carried streams copied when the request has them, else its audio
// stream encoded. Throws UserError (2 for settings the encoder refuses, else 1).
std::unique_ptr<FrameSink> open_encoded_file_sink(FrameSinkRequest request);

// frames_%05d.png: one image per frame, removed again unless finish() is reached. A plain image
// name (x.png) holds the one frame converted, written only by finish().
std::unique_ptr<FrameSink> open_image_sequence_sink(FrameSinkRequest request);

// True for `-`: raw packed frames on stdout.
bool is_raw_output(const std::string& output);

// True when `output` names an image sequence (a printf pattern like %05d).
bool is_image_sequence_pattern(const std::string& output);

}  // namespace nelf
