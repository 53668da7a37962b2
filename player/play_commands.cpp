#include "player/play_commands.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "compositor/gl/gl_compositor.hpp"
#include "compositor/overlays/subtitle_overlay.hpp"
#include "core/printable.hpp"
#include "core/user_error.hpp"
#include "hmz_output/image_sink.hpp"
#include "inputs/test_patterns.hpp"
#include "player/views_screenshot.hpp"

namespace nelf::playback {

FrameCompositor::GridPattern calibration_grid_pattern() {
  return [](const Profile& profile, int width, int height) {
    StereoPair pair = make_test_pattern(TestPattern::grid, pattern_geometry(profile, width, height));
    return EyeImages{std::move(pair.left.image), std::move(pair.right.image)};
  };
}

void PlayCommands::say(std::string text) {
  state_.dirty = true;
  if (!options_.on_screen_messages) return;
  message_ = std::move(text);
  message_until_ = std::chrono::steady_clock::now() + std::chrono::seconds(2);
}

std::string clock_time(double seconds) {
  const auto s = static_cast<long>(std::floor(std::max(0.0, seconds)));
  return fmt::format("{}:{:02d}:{:02d}", s / 3600, s / 60 % 60, s % 60);
}

void PlayCommands::expire_message() {
  const auto now = std::chrono::steady_clock::now();
  if (!message_.empty() && now > message_until_) {
    message_.clear();
    state_.dirty = true;
  }
  if (progress_until_ && now > *progress_until_) {
    progress_until_.reset();
    state_.dirty = true;
  }
}

void PlayCommands::update_preview_caption() {
  if (!display_.takes_preview_caption()) return;
  const FrameOverlays now = overlays();
  if (now.message == caption_shown_.message && now.bar == caption_shown_.bar) return;
  caption_shown_ = now;
  if (now.message.empty()) {
    display_.set_preview_caption({});
    return;
  }
  if (!caption_label_) caption_label_ = std::make_unique<TextOverlay>();
  caption_label_->set_text(now.message);
  caption_label_->set_bar(now.bar);
  // At the size a 720-row view's message has (1/16 of it), over black: the window scales it.
  constexpr int kFontPx = 45;
  const Image label = caption_label_->label_image(kFontPx);
  PreviewCaption caption{label.width(), label.height(), {}};
  caption.rgba.resize(static_cast<std::size_t>(caption.width) * caption.height * 4);
  for (std::size_t i = 0; i < caption.rgba.size(); i += 4) {
    const float* p = &label.data()[i];
    for (int c = 0; c < 3; ++c)
      caption.rgba[i + c] = static_cast<std::uint8_t>(std::lround(std::clamp(p[c] * p[3], 0.f, 1.f) * 255.f));
    caption.rgba[i + 3] = 255;
  }
  display_.set_preview_caption(std::move(caption));
}

void PlayCommands::show_progress() {
  state_.dirty = true;
  if (options_.on_screen_messages) progress_until_ = std::chrono::steady_clock::now() + std::chrono::seconds(2);
}

double PlayCommands::position() const {
  if (state_.awaiting_seek) return state_.seek_target_s;
  return state_.current ? state_.current->pts_s : sound_.clock().now();
}

FrameOverlays PlayCommands::overlays() const {
  FrameOverlays o{message_, state_.calibration, state_.swap_eyes};
  if (!progress_until_ && !keep_progress_) return o;
  // Whole seconds, as the time line says: the bar then moves when the text changes, not with every
  // frame (each change draws the label again).
  const double at = std::floor(std::max(0.0, position()));
  if (duration_s_ && *duration_s_ > 0) {
    o.bar = std::clamp(at / *duration_s_, 0.0, 1.0);
    if (o.message.empty()) o.message = fmt::format("{} / {}", clock_time(at), clock_time(*duration_s_));
  } else if (o.message.empty()) {
    o.message = clock_time(at);
  }
  return o;
}

void PlayCommands::seek_to(double seconds, const std::string& what) {
  double target = std::max(0.0, seconds);
  if (duration_s_) target = std::min(target, std::max(0.0, *duration_s_ - 0.001));
  PlaybackClock& clock = sound_.clock();
  queue_.seek(target);
  sound_.seek(target);
  clock.restart_at(target);
  clock.set_paused(true);  // until the first frame after the seek is decoded
  state_.awaiting_seek = true;
  state_.seek_target_s = target;
  scheduler_.reset();
  if (!what.empty()) say(what);
}

void PlayCommands::seek_by(double delta) {
  const double from = state_.current ? state_.current->pts_s : sound_.clock().now();
  seek_shown(from + delta);
}

void PlayCommands::seek_shown(double target) {
  seek_to(target, "");
  // mpv's OSD after a seek: where it is now, on the time line and the bar.
  message_.clear();
  show_progress();
}

void PlayCommands::decode_again_from_here() { seek_to(position(), ""); }

int PlayCommands::index_of_first_track(const PlayerOptions& options) {
  if (!options.subtitles) return -1;
  for (std::size_t i = 0; i < options.subtitle_tracks.size(); ++i)
    if (options.subtitle_tracks[i].path == options.subtitles->path() &&
        options.subtitle_tracks[i].stream == options.subtitles->stream_number())
      return static_cast<int>(i);
  return -1;
}

bool PlayCommands::set_subtitle_track(int number) {
  const std::vector<SubtitleTrackRef>& tracks = options_.subtitle_tracks;
  if (!subtitles_ || number < 0 || number > static_cast<int>(tracks.size())) return false;
  std::string what;
  bool ok = true;
  // (v's hiding stays as it is, as mpv's sub-visibility does.)
  if (number == 0) {
    subtitles_->track.store(nullptr);
    what = "Subtitles: off";
  } else {
    const SubtitleTrackRef& ref = tracks[static_cast<std::size_t>(number - 1)];
    const std::string name = std::filesystem::path(ref.path).filename().string();
    try {
      subtitles_->track = open_subtitle_track(ref, options_.sub_stereo);
      what = fmt::format("Subtitles: track {}/{} ({}, {})", number, tracks.size(), ref.words, name);
    } catch (const UserError& e) {
      subtitles_->track.store(nullptr);
      what = fmt::format("Subtitles: track {}/{} cannot be shown ({})", number, tracks.size(), e.what());
      ok = false;
    }
  }
  subtitle_index_ = number - 1;  // a track that cannot be shown is passed by the next j
  decode_again_from_here();
  if (!options_.quiet) fmt::print(stderr, "nelf: {}\n", printable(what));
  say(what);
  return ok;
}

void PlayCommands::cycle_subtitles(int step) {
  const int count = static_cast<int>(options_.subtitle_tracks.size());
  if (!subtitles_ || count == 0) {
    say("no subtitles");
    return;
  }
  // Numbers 0 (off) to count, in a ring.
  set_subtitle_track(((subtitle_index_ + 1 + step) % (count + 1) + count + 1) % (count + 1));
}

bool PlayCommands::set_audio_track(int number) {
  bool changed = false;
  const std::string what = sound_.set_track(number, changed);
  if (changed) decode_again_from_here();
  if (!options_.quiet) fmt::print(stderr, "nelf: {}\n", what);
  say(what);
  return changed || number == sound_.track();
}

std::optional<PlayEnd> PlayCommands::other_file(bool next) {
  if (next ? options_.has_next : options_.has_previous) return next ? PlayEnd::next_file : PlayEnd::previous_file;
  say(next ? "this is the last file" : "this is the first file");
  return std::nullopt;
}

void PlayCommands::change_profile(const Profile& changed, const std::string& what) {
  try {
    compositor_.set_profile(changed);
    queue_.negotiate(compositor_.wanted_view_format(view_));
    state_.dirty = true;
    say(what);
  } catch (const std::exception& e) {
    say(fmt::format("cannot: {}", e.what()));
  }
}

void PlayCommands::finish_screenshots() {
  report_views_screenshot(true);
  while (views_pending_ > 0 && state_.current) {  // asked for while another was being written
    start_views_screenshot();
    report_views_screenshot(true);
  }
}

void PlayCommands::start_views_screenshot() {
  --views_pending_;
  ViewsShot shot{state_.current->pts_s, state_.swap_eyes, std::nullopt, options_.sub_stereo, 0.0};
  if (subtitles_ && subtitles_->shown && subtitle_track() > 0) {
    shot.subtitles = options_.subtitle_tracks[static_cast<std::size_t>(subtitle_index_)];
    shot.sub_parallax_percent = subtitles_->drawn_percent;
  }
  views_job_ = std::async(std::launch::async, [shot, reopen = options_.reopen_input, frame = state_.current] {
    return write_views_screenshot(shot, reopen, *frame);
  });
}

void PlayCommands::report_views_screenshot(bool wait) {
  if (!views_job_.valid()) return;
  if (!wait && views_job_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  try {
    const std::string name = views_job_.get();
    if (!options_.quiet) fmt::print(stderr, "nelf: screenshot {}\n", printable(name));
    say(fmt::format("screenshot {}", name));
  } catch (const std::exception& e) {
    fmt::print(stderr, "nelf: warning: no screenshot of the views: {}\n", printable(e.what()));
    say(fmt::format("no screenshot of the views: {}", e.what()));
  }
}

void PlayCommands::take_pending_screenshot() {
  report_views_screenshot(false);
  if (views_pending_ > 0 && state_.current && !views_job_.valid()) start_views_screenshot();
  if (screenshots_pending_ == 0 || !state_.current) return;  // nothing drawn yet: the next refresh
  --screenshots_pending_;
  try {
    const std::filesystem::path path = first_free_name("nelf-shot{:04d}.png");
    const auto [width, height] = display_.packed_size();
    // As the display shows it: the frame with its messages, the grid, the eyes as swapped.
    write_image_file(read_back(display_.packed_framebuffer(), 0, 0, width, height), path, {});
    if (!options_.quiet) fmt::print(stderr, "nelf: screenshot {}\n", printable(path.string()));
    say(fmt::format("screenshot {}", path.string()));
  } catch (const std::exception& e) {
    fmt::print(stderr, "nelf: warning: no screenshot: {}\n", printable(e.what()));
    say(fmt::format("no screenshot: {}", e.what()));
  }
}

std::optional<PlayEnd> PlayCommands::apply(Command command) {
  switch (command) {
    case Command::quit:
      return PlayEnd::quit_key;
    case Command::next_file:
      return other_file(true);
    case Command::previous_file:
      return other_file(false);
    case Command::pause:
      state_.paused = !state_.paused;
      if (!state_.awaiting_seek && state_.started) sound_.clock().set_paused(state_.paused);
      say(state_.paused ? "paused" : "playing");
      break;
    case Command::seek_back_10s:
      if (still_) return other_file(false);  // a photo has no time to seek in: the arrows step as in a viewer
      seek_by(-10);
      break;
    case Command::seek_forward_10s:
      if (still_) return other_file(true);
      seek_by(10);
      break;
    case Command::seek_forward_60s:
      seek_by(60);
      break;
    case Command::seek_back_60s:
      seek_by(-60);
      break;
    case Command::screen_farther:
    case Command::screen_nearer: {
      Profile p = compositor_.profile();
      const double now_mm = p.screen.distance_mm > 0 ? p.screen.distance_mm : p.viewing.virtual_image_mm;
      p.screen.distance_mm = command == Command::screen_nearer ? now_mm / 1.25 : now_mm * 1.25;
      change_profile(p, fmt::format("screen distance {:.0f} mm", p.screen.distance_mm));
      break;
    }
    case Command::ipd_narrower:
    case Command::ipd_wider: {
      Profile p = compositor_.profile();
      p.viewing.ipd_mm += command == Command::ipd_narrower ? -0.5 : 0.5;
      change_profile(p, fmt::format("IPD {:.1f} mm", p.viewing.ipd_mm));
      break;
    }
    case Command::swap_eyes:
      state_.swap_eyes = !state_.swap_eyes;
      state_.dirty = true;
      say(state_.swap_eyes ? "eyes swapped" : "eyes as the source says");
      break;
    case Command::calibration_grid:
      state_.calibration = !state_.calibration;
      try {
        compositor_.prepare(state_.current, overlays());
      } catch (const TestPatternError& e) {
        state_.calibration = false;
        compositor_.prepare(state_.current, overlays());
        say(fmt::format("no calibration grid: {}", e.what()));
        break;
      }
      state_.dirty = true;
      say(state_.calibration ? "calibration grid on" : "calibration grid off");
      break;
    case Command::fullscreen:
      say(display_.toggle_fullscreen());
      state_.dirty = true;
      break;
    case Command::show_progress:
      show_progress();
      break;
    case Command::keep_progress:
      keep_progress_ = !keep_progress_;
      progress_until_.reset();
      state_.dirty = true;
      break;
    case Command::volume_down:
    case Command::volume_up:
      say(sound_.change_volume(command == Command::volume_up ? 2.0 : -2.0));
      break;
    case Command::mute:
      say(sound_.toggle_mute());
      break;
    case Command::next_audio_track: {
      bool changed = false;
      const std::string what = sound_.next_track(changed);
      // The new track starts where the picture is, the clock, the sound and the frames in step.
      if (changed) decode_again_from_here();
      if (!options_.quiet) fmt::print(stderr, "nelf: {}\n", what);  // as the status line named the first
      say(what);
      break;
    }
    case Command::screenshot:
      ++screenshots_pending_;
      break;
    case Command::screenshot_views:
      ++views_pending_;
      break;
    case Command::next_subtitle_track:
    case Command::previous_subtitle_track:
      cycle_subtitles(command == Command::next_subtitle_track ? 1 : -1);
      break;
    case Command::toggle_subtitles:
      if (!subtitles_) {
        say("no subtitles");
        break;
      }
      subtitles_->shown = !subtitles_->shown;
      decode_again_from_here();
      say(subtitles_->shown ? "subtitles on" : "subtitles off");
      break;
    case Command::subtitles_nearer:
    case Command::subtitles_farther: {
      if (!subtitles_) {
        say("no subtitles");
        break;
      }
      const double step = command == Command::subtitles_nearer ? 0.25 : -0.25;
      subtitles_->parallax_percent =
          std::clamp(subtitles_->parallax_percent + step, -max_sub_parallax_percent, max_sub_parallax_percent);
      decode_again_from_here();
      const double percent = subtitles_->parallax_percent;
      if (subtitles_->follows_content)
        say(fmt::format("subtitle depth auto, {:+.2f} % ({})", percent,
                        percent > 0   ? "in front of the content"
                        : percent < 0 ? "behind the content"
                                      : "at the content's depth"));
      else
        say(fmt::format("subtitle depth {:+.2f} % ({})", percent,
                        percent > 0   ? "in front of the screen"
                        : percent < 0 ? "behind the screen"
                                      : "on the screen"));
      break;
    }
    case Command::help: {
      // Each press shows the next line on screen; the first also prints them all.
      const std::vector<std::string> lines = key_help(KeyScope::play, options_.key_rebindings);
      if (help_line_ == 0 && !options_.quiet)
        for (const std::string& line : lines) fmt::print(stderr, "nelf: key {}\n", line);
      say(lines[help_line_++ % lines.size()]);
      state_.dirty = true;
      break;
    }
    default:
      break;  // a calibrate command: not bound in play
  }
  return std::nullopt;
}

}  // namespace nelf::playback
