// frames_%05d.png: one image per frame. Written files are removed again unless finish() is reached.
// A plain image name (x.png) holds the one frame converted, written only by finish(): the file
// appears when the conversion succeeded, or not at all.
#include <fmt/printf.h>

#include <cstring>
#include <exception>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <vector>

#include "core/image.hpp"
#include "core/user_error.hpp"
#include "hmz_output/frame_sink.hpp"
#include "hmz_output/image_sink.hpp"

namespace nelf {
namespace {

class ImageSequenceSink final : public FrameSink {
 public:
  explicit ImageSequenceSink(FrameSinkRequest r)
      : pattern_(r.output),
        refuse_as_output_(std::move(r.refuse_as_output)),
        single_(!is_image_sequence_pattern(r.output)),
        options_{r.encoder.overwrite, 8} {}
  ~ImageSequenceSink() override {
    if (finished_) return;
    std::error_code ec;
    for (const auto& f : written_) std::filesystem::remove(f, ec);
  }
  void write(const PackedFrame& frame) override {
    if (single_) {
      if (single_frame_) throw std::logic_error("a single image output was given a second frame");
      single_frame_.emplace(frame);
      return;
    }
    write_frame(frame, fmt::sprintf(pattern_, static_cast<int>(written_.size()) + 1));
  }
  void finish() override {
    if (single_ && single_frame_) write_frame(*single_frame_, pattern_);
    finished_ = true;
  }
  std::string description() const override { return pattern_; }

 private:
  void write_frame(const PackedFrame& frame, const std::string& name) {
    // Any frame's name may be an input (out_%05d.png expanding to an input's name, or a link to it).
    if (refuse_as_output_) refuse_as_output_(name);
    Image image(frame.width, frame.height);
    const std::size_t bpp = bytes_per_pixel(frame.bits);
    float* out = image.data();
    for (std::size_t i = 0; i < static_cast<std::size_t>(frame.width) * frame.height * 4; ++i) {
      if (bpp == 8) {
        std::uint16_t v;
        std::memcpy(&v, &frame.rgba[i * 2], 2);
        out[i] = v / 65535.f;
      } else {
        out[i] = frame.rgba[i] / 255.f;
      }
    }
    options_.bits = frame.bits > 8 ? 16 : 8;
    try {
      write_image_file(image, name, options_);
    } catch (const std::exception& e) {
      throw UserError(e.what(), 1);
    }
    written_.push_back(name);
  }

  std::string pattern_;
  std::function<void(const std::string&)> refuse_as_output_;
  bool single_;
  std::optional<PackedFrame> single_frame_;
  ImageWriteOptions options_;
  std::vector<std::filesystem::path> written_;
  bool finished_ = false;
};

}  // namespace

std::unique_ptr<FrameSink> open_image_sequence_sink(FrameSinkRequest request) {
  return std::make_unique<ImageSequenceSink>(std::move(request));
}

// A printf conversion of the frame number in the file name: %d, %4d, %04d (%% is a literal %). A
// scan rather than std::regex, whose header alone took this file from 8 to 15 s to compile.
bool is_image_sequence_pattern(const std::string& output) {
  const std::string name = std::filesystem::path(output).filename().string();
  for (std::size_t i = name.find('%'); i != std::string::npos; i = name.find('%', i)) {
    std::size_t end = i + 1;
    if (end < name.size() && name[end] == '%') {
      i = end + 1;
      continue;
    }
    while (end < name.size() && name[end] >= '0' && name[end] <= '9') ++end;
    if (end < name.size() && name[end] == 'd') return true;
    i = end;
  }
  return false;
}

}  // namespace nelf
