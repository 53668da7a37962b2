#include "player/views_screenshot.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "compositor/overlays/subtitle_overlay.hpp"
#include "hmz_output/image_sink.hpp"

namespace nelf::playback {

namespace {

// Channel `c` of pixel `i` of a view, 0..1.
float channel(const std::vector<std::uint8_t>& view, int bits, std::size_t i, int c) {
  if (bits > 8) {
    std::uint16_t v = 0;
    std::memcpy(&v, &view[(i * 4 + static_cast<std::size_t>(c)) * 2], 2);
    return v / 65535.f;
  }
  return view[i * 4 + static_cast<std::size_t>(c)] / 255.f;
}

// The frame at `pts_s` (the first at or after it, within half a frame), at full resolution.
StereoVideoFrame decode_again(Source& source, double pts_s) {
  const SourceInfo info = source.info();
  source.negotiate({});  // whole views
  if (pts_s > 0) source.seek(pts_s);
  const double half_frame = info.frame_rate > 0 ? 0.5 / info.frame_rate : 0.02;
  std::optional<StereoVideoFrame> last;
  while (std::optional<StereoVideoFrame> frame = source.next()) {
    last = std::move(frame);
    if (last->pts_s >= pts_s - half_frame) break;
  }
  if (!last) throw std::runtime_error("the input has no frame there any more");
  return std::move(*last);
}

}  // namespace

std::string first_free_name(const std::string& pattern) {
  std::error_code error;
  for (int n = 1; n <= 9999; ++n) {
    std::string candidate = fmt::format(fmt::runtime(pattern), n);
    if (!std::filesystem::exists(candidate, error) && !error) return candidate;
  }
  throw ImageWriteError(fmt::format("{} to {} are all taken", fmt::format(fmt::runtime(pattern), 1),
                                    fmt::format(fmt::runtime(pattern), 9999)));
}

std::string write_views_screenshot(const ViewsShot& shot, const std::function<std::unique_ptr<Source>()>& reopen,
                                   const StereoVideoFrame& on_screen) {
  StereoVideoFrame frame;
  if (reopen) {
    const std::unique_ptr<Source> source = reopen();
    frame = decode_again(*source, shot.pts_s);
    if (shot.subtitles) {
      const std::shared_ptr<SubtitleTrack> track = open_subtitle_track(*shot.subtitles, shot.sub_stereo);
      const auto [width, height] = subtitle_canvas(frame);
      draw_subtitles(frame, track->render(frame.pts_s, width, height, frame.aspect), shot.sub_parallax_percent);
    }
  } else {
    frame = on_screen;  // its subtitles are drawn into it already
  }
  const int w = frame.width / frame.block[0], h = frame.height / frame.block[1];
  // Each view at its display aspect (a half side-by-side movie's squeezed views widened again), so
  // that the picture is a full side-by-side pair as stereo viewers take it.
  const double aspect = frame.aspect > 0 ? frame.aspect : static_cast<double>(frame.width) / frame.height;
  const int out_w = std::max(1, static_cast<int>(std::lround(h * aspect)));
  Image both(2 * out_w, h);
  const std::vector<std::uint8_t>& left = shot.swap_eyes ? frame.right : frame.left;
  const std::vector<std::uint8_t>& right = shot.swap_eyes ? frame.left : frame.right;
  for (int x = 0; x < out_w; ++x) {
    // Linear between the two stored columns nearest the output column's centre.
    const double sx = std::clamp((x + 0.5) * w / out_w - 0.5, 0.0, static_cast<double>(w - 1));
    const int x0 = static_cast<int>(sx), x1 = std::min(x0 + 1, w - 1);
    const float t = static_cast<float>(sx - x0);
    for (int y = 0; y < h; ++y) {
      const std::size_t i0 = static_cast<std::size_t>(y) * w + x0, i1 = static_cast<std::size_t>(y) * w + x1;
      for (int eye = 0; eye < 2; ++eye) {
        const std::vector<std::uint8_t>& view = eye == 0 ? left : right;
        const auto at = [&](int c) {
          return channel(view, frame.bits, i0, c) * (1.f - t) + channel(view, frame.bits, i1, c) * t;
        };
        both.at(eye * out_w + x, y) = {at(0), at(1), at(2), 1.f};
      }
    }
  }
  const std::string name = first_free_name("nelf-views{:04d}.png");
  write_image_file(both, name, {false, frame.bits > 8 ? 16 : 8});
  return name;
}

}  // namespace nelf::playback
