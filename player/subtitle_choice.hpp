#pragma once
// Which subtitles play shows and convert --burn-subs draws: the same choice for both.
#include <memory>
#include <string>
#include <vector>

#include "inputs/subtitle_track.hpp"

namespace nelf {

// The subtitles for `input`: `file` (--sub-file) when given, else a subtitle file beside the input
// (SubtitleTrack::beside), else the input's own first subtitle stream; `start_s` its --start.
// `stream` (--sid, --slang) picks among the streams of `file`, or of the input itself (the files
// beside it are then not looked at). `required` (--burn-subs): none found throws UserError;
// otherwise it is null, and subtitles found but not usable are a warning. A `file` or a `stream`
// asked for that is not usable always throws UserError, and so does `stereo` (--sub-stereo) for a
// text track. Says which track it took unless `quiet`.
std::unique_ptr<SubtitleTrack> choose_subtitles(const std::string& input, const std::string& file, double start_s,
                                                bool required, bool quiet, const SubtitleStreamChoice& stream = {},
                                                SubtitleStereo stereo = SubtitleStereo::flat);

// A subtitle track play can switch to (keys j and J, the IPC's sid): the `stream`-th subtitle
// stream (from 1) of `path`, `words` as a track list shows it ("eng, subrip").
struct SubtitleTrackRef {
  std::string path;
  int stream = 1;
  std::string words;
};

// The tracks play cycles through for `input`, in mpv's order, external first: each subtitle stream
// of `file` (--sub-file), else of each file beside the input, then the input's own streams.
std::vector<SubtitleTrackRef> subtitle_tracks(const std::string& input, const std::string& file);

// Opens `ref` on the movie's clock, its bitmaps laid out as `stereo` says (flat for a text track).
// Throws UserError when it cannot be read.
std::shared_ptr<SubtitleTrack> open_subtitle_track(const SubtitleTrackRef& ref, SubtitleStereo stereo);

}  // namespace nelf
