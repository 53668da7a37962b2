#include "player/defect_session.hpp"

#include <fmt/format.h>

#include <chrono>
#include <memory>
#include <thread>

#include "compositor/panel_frame.hpp"
#include "core/printable.hpp"
#include "core/user_error.hpp"
#include "hmz_output/packing.hpp"
#include "player/defect_marking.hpp"
#include "player/interrupt.hpp"
#include "player/live_display.hpp"

namespace nelf {

namespace {

// As calibrate's: how long a message stays on screen, how often an unchanged frame is presented
// again (a window that was covered shows it again), how often the keys are polled in between.
constexpr auto kMessageTime = std::chrono::milliseconds(2500);
constexpr auto kIdlePresent = std::chrono::milliseconds(100);
constexpr auto kPoll = std::chrono::milliseconds(10);

DefectMap starting_map(const Profile& profile) {
  return profile.correction.defects ? *profile.correction.defects : DefectMap{};
}

class DefectSession {
 public:
  explicit DefectSession(const CalibrateSession& s)
      : settings_(s),
        where_(defect_map_save(s.profile, s.save)),
        display_(open_live_display({s.output, s.monitor, s.connector, "nelf calibrate --defects (h: help)", s.gpu},
                                   s.profile, s.signal)),
        layout_(packed_layout(s.signal, s.profile.display.resolution)),
        marking_(s.profile.display.resolution, starting_map(s.profile), *s.defects) {}

  void run() {
    InterruptGuard guard;
    std::string saving = " (nothing is written: the profile names no correction.defect_map and there is no --save)";
    if (!where_.map.empty())
      saving =
          fmt::format(", saving the defect map to {}{}", where_.map.string(),
                      where_.profile.empty() ? "" : fmt::format(" and the profile naming it to {}", where_.profile));
    fmt::print("nelf calibrate --defects: {}, {}x{} panels without the lens mapping; h shows the keys, q quits{}\n",
               display_->description(), settings_.profile.display.resolution[0],
               settings_.profile.display.resolution[1], saving);
    for (const auto& line : DefectMarking::help_lines()) fmt::print("  {}\n", line);
    std::fflush(stdout);
    show("h: keys   q: quit");
    // Whatever ends the session, the marks are not lost: a display that goes away still gets the
    // map saved before the error is reported.
    std::string lost;
    try {
      loop();
    } catch (const UserError&) {
      throw;
    } catch (const std::runtime_error& e) {
      lost = e.what();
    }
    if (!where_.map.empty()) save();
    if (!lost.empty()) throw UserError(fmt::format("the display went away: {}", lost), 1);
    std::size_t left = 0;
    for (const PixelDefect& d : marking_.map().defects) left += d.eye == Eye::left;
    fmt::print("defects: {} left, {} right\n", left, marking_.map().defects.size() - left);
  }

 private:
  void loop() {
    auto last_present = std::chrono::steady_clock::now();
    bool dirty = true;
    while (!interrupt_requested.load() && !display_->close_requested()) {
      bool quit = false;
      // Keys arrive in batches (key repeat): the panels are drawn once per batch.
      for (const KeyPress& key : display_->poll_events()) {
        const DefectStep step = handle(key);
        if ((quit = step.quit)) break;
        dirty |= step.changed || !step.message.empty() || step.save || step.help;
      }
      if (quit) break;
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

  // Applies one key; says on screen what it did (and in the terminal what it marked), saves on w.
  DefectStep handle(const KeyPress& key) {
    const DefectStep step = marking_.apply(key);
    if (step.quit) return step;
    std::string message = step.message;
    if (step.marked) {
      fmt::print("nelf calibrate: {}\n", message);
      std::fflush(stdout);
    }
    if (step.save) {
      try {
        message =
            where_.map.empty() ? "nothing saved: the profile names no defect map; start with --save FILE.toml" : save();
      } catch (const UserError& e) {
        message = fmt::format("not saved: {}", e.what());  // e.g. the disk is full; keep going
        fmt::print(stderr, "nelf: {}\n", printable(message));
      }
    }
    if (step.help) {
      const auto& lines = DefectMarking::help_lines();
      message = lines[help_line_++ % lines.size()];
    }
    if (!message.empty()) show(message);
    return step;
  }

  void show(const std::string& message) {
    message_ = message;
    message_until_ = std::chrono::steady_clock::now() + kMessageTime;
  }

  std::string save() {
    const std::string line = save_defect_map(settings_.profile, marking_.map(), where_);
    fmt::print("nelf calibrate: {}\n", line);
    std::fflush(stdout);
    return line;
  }

  void render() {
    std::string text = marking_.status_line();
    if (!message_.empty()) text += "   " + message_;
    EyeImages panels;
    try {
      panels = {marking_.panel_image(Eye::left, text), marking_.panel_image(Eye::right, text)};
    } catch (const std::runtime_error& e) {
      throw UserError(e.what(), 1);  // no font for the status line: not the display going away
    }
    display_->context()->make_current();
    render_panel_frame(
        layout_, panels,
        PackedTarget::gl(display_->packed_framebuffer(), display_->packed_texture(), display_->packed_size()));
  }

  const CalibrateSession& settings_;
  const DefectMapSave where_;
  std::unique_ptr<Display> display_;
  PackedLayout layout_;
  DefectMarking marking_;
  std::string message_;
  std::chrono::steady_clock::time_point message_until_;
  std::size_t help_line_ = 0;
};

}  // namespace

void run_defect_session(const CalibrateSession& session) {
  if (!session.defects) throw std::logic_error("run_defect_session without a field");
  DefectSession(session).run();
}

}  // namespace nelf
