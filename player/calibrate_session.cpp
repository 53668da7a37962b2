#include "player/calibrate_session.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <thread>
#include <utility>

#include "compositor/frame_compositor.hpp"
#include "core/printable.hpp"
#include "core/user_error.hpp"
#include "hmz_output/image_sink.hpp"
#include "hmz_output/packing.hpp"
#include "player/calibration_controls.hpp"
#include "player/defect_session.hpp"
#include "player/interrupt.hpp"
#include "player/live_display.hpp"

namespace nelf {

namespace {

// How long a change stays on screen.
constexpr auto kMessageTime = std::chrono::milliseconds(2500);
// With nothing changing, the frame is presented again this often (a window that was covered
// shows it again) and the keys polled in between.
constexpr auto kIdlePresent = std::chrono::milliseconds(100);
constexpr auto kPoll = std::chrono::milliseconds(10);

std::unique_ptr<Display> open_display(const CalibrateSession& s) {
  return open_live_display({s.output, s.monitor, s.connector, "nelf calibrate (h: help)", s.gpu}, s.profile, s.signal);
}

// The pattern's views as an 8-bit frame (what the GL compositor samples them as), made again
// when the pattern or its geometry changes.
std::shared_ptr<const StereoVideoFrame> pattern_frame(TestPattern pattern, const PatternGeometry& geometry) {
  StereoPair views;
  try {
    views = make_test_pattern(pattern, geometry);
  } catch (const TestPatternError& e) {
    throw UserError(fmt::format("pattern {}: {}", test_pattern_name(pattern), e.what()), 2);
  }
  auto frame = std::make_shared<StereoVideoFrame>();
  frame->width = views.left.image.width();
  frame->height = views.left.image.height();
  frame->aspect = views.left.aspect();
  for (auto [image, bytes] :
       {std::pair{&views.left.image, &frame->left}, std::pair{&views.right.image, &frame->right}}) {
    const float* in = image->data();
    bytes->resize(static_cast<std::size_t>(image->width()) * image->height() * 4);
    for (std::size_t i = 0; i < bytes->size(); ++i)
      (*bytes)[i] = static_cast<std::uint8_t>(std::lround(std::clamp(in[i], 0.f, 1.f) * 255.f));
  }
  return frame;
}

class Session {
 public:
  explicit Session(const CalibrateSession& s)
      : settings_(s),
        display_(open_display(s)),
        controls_(s.profile, s.pattern, 16.0 / 9.0),
        compositor_(s.profile, s.compositor, packed_layout(s.signal, s.profile.display.resolution),
                    display_->context()) {
    upload_pattern();
  }

  void run() {
    InterruptGuard guard;
    fmt::print("nelf calibrate: {}; h shows the keys, q quits{}\n", display_->description(),
               settings_.save.empty() ? " (no --save: nothing is written)" : ", saving to " + settings_.save);
    for (const auto& line : CalibrationControls::help_lines()) fmt::print("  {}\n", line);
    std::fflush(stdout);
    show("h: keys   q: quit");
    // Whatever ends the session, the adjustments are not lost: a display that goes away (X server
    // gone, HDMI unplugged) still gets the profile saved before the error is reported.
    std::string lost;
    try {
      loop();
    } catch (const UserError&) {
      throw;
    } catch (const std::runtime_error& e) {
      lost = e.what();
    }
    if (!settings_.save.empty()) save();
    if (!lost.empty()) throw UserError(fmt::format("the display went away: {}", lost), 1);
    const auto& p = controls_.profile();
    for (Eye eye : {Eye::left, Eye::right}) {
      const auto& c = p.eye_calibration(eye);
      fmt::print("{}: shift {}, {} px, rotation {} deg, pitch scale {}\n", eye == Eye::left ? "left" : "right",
                 c.shift_px.x, c.shift_px.y, c.rotation_deg, c.pitch_scale);
    }
  }

 private:
  void loop() {
    auto last_present = std::chrono::steady_clock::now();
    bool dirty = true;
    while (!interrupt_requested.load() && !display_->close_requested()) {
      bool quit = false;
      // Keys arrive in batches (key repeat, fast typing): the compositor and the pattern are
      // rebuilt once per batch, for the last state.
      bool profile_changed = false, pattern_changed = false;
      for (const KeyPress& key : display_->poll_events()) {
        const CalibrationStep step = handle(key);
        if ((quit = step.quit)) break;
        profile_changed |= step.profile_changed;
        pattern_changed |= step.pattern_changed;
        dirty |= step.profile_changed || step.pattern_changed || !step.message.empty() || step.save || step.help;
      }
      if (quit) break;
      if (profile_changed) {
        // The mapping follows the profile: a new compositor (its programs come from Mesa's shader
        // cache or the driver's), and the pattern drawn again where its geometry changed.
        compositor_.set_profile(controls_.profile());
      }
      if (profile_changed || pattern_changed) upload_pattern();
      const auto now = std::chrono::steady_clock::now();
      if (!message_.empty() && now >= message_until_) {
        message_.clear();
        dirty = true;
      }
      const bool rendered = dirty;
      if (dirty) {
        render();
        dirty = false;
      }
      if (rendered || now - last_present >= kIdlePresent) {
        display_->present();
        last_present = std::chrono::steady_clock::now();
      } else {
        std::this_thread::sleep_for(kPoll);
      }
    }
  }

  // Applies one key; says on screen what it did, saves on w.
  CalibrationStep handle(const KeyPress& key) {
    const CalibrationStep step = controls_.apply(key);
    if (step.quit) return step;
    std::string message = step.message;
    if (step.save) {
      try {
        message = settings_.save.empty() ? "nothing saved: start with --save FILE.toml" : save();
      } catch (const UserError& e) {
        message = fmt::format("not saved: {}", e.what());  // e.g. the disk is full; keep going
        fmt::print(stderr, "nelf: {}\n", printable(message));
      }
    }
    if (step.help) {
      const auto& lines = CalibrationControls::help_lines();
      message = lines[help_line_++ % lines.size()];
    }
    if (!message.empty()) show(message);
    return step;
  }

  // Draws the pattern again when it or its geometry (screen size and distance, display pixel
  // footprint) changed; a shift or rotation alone leaves it as it is.
  void upload_pattern() {
    const PatternGeometry geometry = pattern_geometry(controls_.profile());
    if (uploaded_ && geometry == uploaded_->first && controls_.pattern() == uploaded_->second) return;
    pattern_ = pattern_frame(controls_.pattern(), geometry);
    uploaded_ = {geometry, controls_.pattern()};
  }

  void show(const std::string& message) {
    message_ = message;
    message_until_ = std::chrono::steady_clock::now() + kMessageTime;
  }

  std::string save() {
    save_calibrated_profile(controls_.profile(), settings_.save);
    const std::string line = fmt::format("saved {}", settings_.save);
    fmt::print("nelf calibrate: {}\n", line);
    std::fflush(stdout);
    return line;
  }

  void render() {
    display_->context()->make_current();
    compositor_.render(
        pattern_, {message_, false, false},
        PackedTarget::gl(display_->packed_framebuffer(), display_->packed_texture(), display_->packed_size()));
  }

  const CalibrateSession& settings_;
  std::unique_ptr<Display> display_;
  CalibrationControls controls_;
  FrameCompositor compositor_;
  std::shared_ptr<const StereoVideoFrame> pattern_;
  std::string message_;
  std::optional<std::pair<PatternGeometry, TestPattern>> uploaded_;
  std::chrono::steady_clock::time_point message_until_;
  std::size_t help_line_ = 0;
};

}  // namespace

void run_calibrate_session(const CalibrateSession& session) {
  if (session.defects) return run_defect_session(session);
  try {
    CalibrationControls check(session.profile, session.pattern, 16.0 / 9.0);
  } catch (const ProfileError& e) {
    throw UserError(e.what(), 2);
  }
  Session(session).run();
}

void save_calibrated_profile(const Profile& profile, const std::string& path) {
  // The saved file is a profile of its own, not the one it started from.
  Profile saved = profile;
  saved.name = calibrated_profile_name(path);
  // A defect map named relative to the profile stays found from the saved file's directory.
  if (!saved.correction.defect_map_path.empty()) {
    std::error_code ec;
    const auto directory = std::filesystem::absolute(std::filesystem::path(path), ec).parent_path();
    const auto relative =
        std::filesystem::relative(std::filesystem::absolute(saved.correction.defect_map_path, ec), directory, ec);
    if (!ec && !relative.empty()) saved.correction.defect_map = relative.string();
  }
  try {
    write_file_atomically(path, true, [&](const std::filesystem::path& temporary) {
      std::ofstream out(temporary, std::ios::binary);
      out << profile_to_toml(saved);
      out.close();
      if (!out) throw ImageWriteError(fmt::format("{}: cannot write the profile (disk full?)", path));
    });
  } catch (const ImageWriteError& e) {
    throw UserError(e.what(), 1);
  }
}

}  // namespace nelf
