#pragma once
// A subtitle stream of a media file (the movie itself, or an external .srt/.ass/.vtt/.sup/.idx file),
// decoded by libavcodec: text laid out and rasterised by libass with its styling, bitmaps (PGS, DVB,
// VobSub) scaled from their canvas to the view. Read forward as the times asked for advance (a seek
// back or far ahead seeks the file), so opening a long movie reads nothing in advance.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/subtitle_bitmap.hpp"

namespace nelf {

// Which of a file's subtitle streams (--sid, --slang): the N-th (from 1), else the first tagged with
// the first language of the list that one has, else FFmpeg's best.
struct SubtitleStreamChoice {
  std::optional<int> number;
  std::vector<std::string> languages;
  bool any() const { return number || !languages.empty(); }
};

// How a bitmap track's pictures are laid out (--sub-stereo): one picture for both eyes, or authored
// per eye, the left eye's in the left (top) half of the subtitle canvas and the right eye's in the
// other, as a 3D rip's converted subtitles are.
enum class SubtitleStereo { flat, side_by_side, top_bottom };

class SubtitleTrack {
 public:
  // The first subtitle stream of `path` (a movie or a subtitle file). The caller's time 0 is the
  // movie's `start_s` (--start): a movie's own subtitles are timed on its video's clock (from its
  // start time), a subtitle file's from the start of the movie. Throws UserError (one line) when
  // the file cannot be read, has no subtitle stream that FFmpeg decodes or does not parse; status 2,
  // listing the file's subtitle streams, when `choice` names none of them.
  SubtitleTrack(const std::string& path, double start_s, const SubtitleStreamChoice& choice = {});
  ~SubtitleTrack();
  SubtitleTrack(const SubtitleTrack&) = delete;
  SubtitleTrack& operator=(const SubtitleTrack&) = delete;

  // The subtitle files beside `movie` that belong to it, as mpv loads them: the movie's name with
  // .srt, .ass, .ssa, .vtt, .sup (PGS) or .idx (VobSub) for its extension, or with a language before it (movie.en.srt);
  // the exact name first, then the others in name order.
  static std::vector<std::string> beside(const std::string& movie);

  // The subtitle streams of `path` in file order, as "eng, subrip" ("no language, …" untagged);
  // none also when it cannot be opened.
  static std::vector<std::string> streams(const std::string& path);
  static bool has_subtitles(const std::string& path) { return !streams(path).empty(); }

  // What is shown at `t_s` (caller's time), drawn for view pixels of `width`×`height` that are
  // displayed at `aspect` (0 = width / height): text laid out at that aspect, so that a squeezed
  // (half side-by-side) view does not squeeze the letters; a bitmap's canvas (the video frame it
  // was authored for) scaled to the view. Empty when nothing is shown; with per-eye bitmaps
  // (set_stereo), each eye's own. Throws UserError when the stream turns out not to decode.
  SubtitleBitmap render(double t_s, int width, int height, double aspect);

  // Bitmaps authored per eye (--sub-stereo). Throws UserError (status 2) for a text track, whose
  // lines are laid out for one picture.
  void set_stereo(SubtitleStereo stereo);

  // "subtitles: movie.srt (subrip)".
  const std::string& description() const;
  // The file, and which of its subtitle streams this is (from 1, as --sid counts).
  const std::string& path() const;
  int stream_number() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nelf
