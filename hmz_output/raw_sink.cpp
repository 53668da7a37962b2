// `nelf convert IN -`: raw packed frames on stdout, for a pipe into ffplay, ffmpeg, mpv or a
// program of one's own (DESIGN.md §7), as `ffmpeg … -f rawvideo -` writes them.
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>
#include <vector>

#include "core/user_error.hpp"
#include "hmz_output/frame_sink.hpp"

namespace nelf {
namespace {

class RawFrameSink final : public FrameSink {
 public:
  RawFrameSink(int fd, int width, int height, double frame_rate) : fd_(fd), width_(width), height_(height) {
    // The stream has no header: the reader is told its format here, in the words it takes them.
    fmt::print(stderr,
               "nelf: raw video to stdout: rgba {}x{} at {:g} fps (e.g. | ffplay -f rawvideo -pixel_format rgba "
               "-video_size {}x{} -framerate {:g} -)\n",
               width, height, frame_rate, width, height, frame_rate);
  }

  void write(const PackedFrame& frame) override {
    if (frame.width != width_ || frame.height != height_)
      throw UserError(fmt::format("-: the packed frame changed size ({}x{}, was {}x{})", frame.width, frame.height,
                                  width_, height_),
                      1);
    const std::size_t values = static_cast<std::size_t>(frame.width) * frame.height * 4;
    if (frame.bits <= 8) return write_all(frame.rgba.data(), values);
    eight_bit_.resize(values);
    for (std::size_t i = 0; i < values; ++i) {
      std::uint16_t v;
      std::memcpy(&v, &frame.rgba[i * 2], 2);
      eight_bit_[i] = static_cast<std::uint8_t>((v * 255u + 32767u) / 65535u);
    }
    write_all(eight_bit_.data(), values);
  }

  void finish() override {}
  std::string description() const override { return "raw video to stdout"; }

 private:
  void write_all(const std::uint8_t* bytes, std::size_t size) const {
    while (size > 0) {
      const ssize_t n = ::write(fd_, bytes, size);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && errno == EPIPE) throw std::system_error(std::make_error_code(std::errc::broken_pipe));
      if (n <= 0) throw UserError(fmt::format("-: cannot write to stdout: {}", std::strerror(errno)), 1);
      bytes += n;
      size -= static_cast<std::size_t>(n);
    }
  }

  int fd_, width_, height_;
  std::vector<std::uint8_t> eight_bit_;
};

}  // namespace

std::unique_ptr<FrameSink> open_raw_frame_sink(int fd, int width, int height, double frame_rate) {
  return std::make_unique<RawFrameSink>(fd, width, height, frame_rate);
}

bool is_raw_output(const std::string& output) { return output == "-"; }

}  // namespace nelf
