#include "player/play_commands.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "compositor/gl/gl_compositor.hpp"
#include "inputs/test_patterns.hpp"

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

void PlayCommands::expire_message() {
  if (message_.empty() || std::chrono::steady_clock::now() <= message_until_) return;
  message_.clear();
  state_.dirty = true;
}

void PlayCommands::seek_by(double delta) {
  const double from = state_.current ? state_.current->pts_s : sound_.clock().now();
  seek(from + delta, fmt::format("{} {:.0f} s", delta < 0 ? "back" : "forward", std::abs(delta)));
}

void PlayCommands::seek_to(double target) { seek(target, "to"); }

void PlayCommands::seek(double target, const std::string& what) {
  PlaybackClock& clock = sound_.clock();
  target = std::max(0.0, target);
  if (duration_s_) target = std::min(target, std::max(0.0, *duration_s_ - 0.001));
  queue_.seek(target);
  sound_.seek(target);
  clock.restart_at(target);
  clock.set_paused(true);  // until the first frame after the seek is decoded
  state_.awaiting_seek = true;
  state_.seek_target_s = target;
  scheduler_.reset();
  say(fmt::format("{}: {}:{:02d}", what, static_cast<int>(target) / 60, static_cast<int>(target) % 60));
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

bool PlayCommands::apply(Command command) {
  switch (command) {
    case Command::quit:
      return false;
    case Command::pause:
      state_.paused = !state_.paused;
      if (!state_.awaiting_seek && state_.started) sound_.clock().set_paused(state_.paused);
      say(state_.paused ? "paused" : "playing");
      break;
    case Command::seek_back_10s:
      seek_by(-10);
      break;
    case Command::seek_forward_10s:
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
  return true;
}

}  // namespace nelf::playback
