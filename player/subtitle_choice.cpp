#include "player/subtitle_choice.hpp"

#include <fmt/format.h>

#include <vector>

#include "core/printable.hpp"
#include "core/user_error.hpp"

namespace nelf {

std::unique_ptr<SubtitleTrack> choose_subtitles(const std::string& input, const std::string& file, double start_s,
                                                bool required, bool quiet, const SubtitleStreamChoice& stream,
                                                SubtitleStereo stereo) {
  std::string chosen = file;
  if (chosen.empty() && stream.any()) chosen = input;
  if (chosen.empty()) {
    const std::vector<std::string> beside = SubtitleTrack::beside(input);
    if (!beside.empty())
      chosen = beside.front();
    else if (SubtitleTrack::has_subtitles(input))
      chosen = input;
    else if (required)
      throw UserError(fmt::format("{}: no subtitles to burn in (no subtitle stream, no subtitle file beside it; "
                                  "--sub-file FILE names one)",
                                  printable(input)),
                      1);
    else
      return nullptr;
  }
  std::unique_ptr<SubtitleTrack> track;
  try {
    track = std::make_unique<SubtitleTrack>(chosen, start_s, stream);
  } catch (const UserError& e) {
    // Subtitles found on their own (not named, not asked to be burned in) are no reason to refuse
    // the movie.
    if (required || !file.empty() || stream.any()) throw;
    fmt::print(stderr, "nelf: warning: {}; playing without subtitles\n", printable(e.what()));
    return nullptr;
  }
  track->set_stereo(stereo);
  if (!quiet) fmt::print(stderr, "nelf: {}\n", printable(track->description()));
  return track;
}

std::vector<SubtitleTrackRef> subtitle_tracks(const std::string& input, const std::string& file) {
  std::vector<std::string> files = file.empty() ? SubtitleTrack::beside(input) : std::vector<std::string>{file};
  files.push_back(input);
  std::vector<SubtitleTrackRef> tracks;
  for (const std::string& path : files) {
    const std::vector<std::string> streams = SubtitleTrack::streams(path);
    for (std::size_t i = 0; i < streams.size(); ++i) tracks.push_back({path, static_cast<int>(i) + 1, streams[i]});
  }
  return tracks;
}

std::shared_ptr<SubtitleTrack> open_subtitle_track(const SubtitleTrackRef& ref, SubtitleStereo stereo) {
  auto track = std::make_shared<SubtitleTrack>(ref.path, 0.0, SubtitleStreamChoice{ref.stream, {}});
  try {
    track->set_stereo(stereo);
  } catch (const UserError&) {
    // --sub-stereo is the bitmap tracks'; a text track switched to is laid out once, as always.
  }
  return track;
}

}  // namespace nelf
