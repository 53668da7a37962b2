#include "hmz_output/output_drivers.hpp"

#include <algorithm>
#include <iterator>

#include "hmz_output/image_sink.hpp"
#include "hmz_output/kms_display.hpp"
#include "hmz_output/window_display.hpp"

namespace nelf {

// Outputs that are one file with no header of their own declare their opener here, beside their row.
std::unique_ptr<Display> open_offscreen_display(const DisplayOptions& options);
std::unique_ptr<Display> open_quad_buffer_display(const DisplayOptions& options);

namespace {

constexpr OutputDriver live_row(std::string_view name, std::string_view help,
                                std::unique_ptr<Display> (*open)(const DisplayOptions&)) {
  return {name, help, true, open, nullptr, false, nullptr};
}

constexpr OutputDriver file_row(std::string_view name, std::string_view help, bool (*accepts)(const std::string&),
                                bool carries_streams, std::unique_ptr<FrameSink> (*open)(FrameSinkRequest)) {
  return {name, help, false, nullptr, accepts, carries_streams, open};
}

constexpr OutputDriver kOutputs[] = {
    live_row("window", "a desktop window, the packed frame scaled to fit",
             [](const DisplayOptions& o) { return open_window_display(o, WindowMode::window); }),
    live_row("fullscreen", "1:1 on the monitor --monitor names, the HMD by default",
             [](const DisplayOptions& o) { return open_window_display(o, WindowMode::fullscreen); }),
    live_row("kms", "scan-out on the --connector without a desktop (docs/kms.md)", open_kms_display),
    live_row("quad-buffer", "an OpenGL quad-buffer stereo window, an eye in each back buffer",
             open_quad_buffer_display),
    live_row("offscreen", "no display: rendered off screen and paced by the clock, for tests and timing",
             open_offscreen_display),
    // Files, by the output name; the encoded file last, as it takes any name.
    file_row("raw", "`-`: raw RGBA frames on stdout", is_raw_output, false,
             [](FrameSinkRequest r) { return open_raw_frame_sink(r.raw_fd, r.width, r.height, r.frame_rate); }),
    file_row(
        "image", "an image sequence (frames_%05d.png) or one image (x.png, .tif, .exr, .jpg)",
        [](const std::string& o) { return is_image_sequence_pattern(o) || is_image_file_name(o); }, false,
        open_image_sequence_sink),
    file_row(
        "encoded", "any other name: an encoded video file", [](const std::string&) { return true; }, true,
        open_encoded_file_sink),
};

static_assert(std::is_partitioned(std::begin(kOutputs), std::end(kOutputs),
                                  [](const OutputDriver& d) { return d.live; }),
              "the live rows come first: display_drivers() and file_sink_drivers() are the two parts");

}  // namespace

std::span<const OutputDriver> output_drivers() { return kOutputs; }

}  // namespace nelf
