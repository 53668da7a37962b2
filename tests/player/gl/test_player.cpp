// The player engine on the offscreen output (an EGL context, no display server): a generated clip
// with distinct left/right content and a moving box, read back from the display's packed
// framebuffer after every new frame; keys typed by the test through the display.
#include <gtest/gtest.h>

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "compositor/gl/gl_compositor.hpp"
#include "hmz_output/display_drivers.hpp"
#include "hmz_output/packing.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/subtitle_track.hpp"
#include "player/frame_scheduler.hpp"
#include "player/player.hpp"
#include "player/stepped_clock.hpp"
#include "support/media.hpp"
#include "support/player_tests.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::grid_pixels;
using test::make_clip;
using test::Mean;
using test::mean_of;

// A display with keys the test types itself: they come with the player's next poll, so the frame
// rendered after the one a key was typed at is the first one the key may change.
class TypedKeysDisplay final : public Display {
 public:
  explicit TypedKeysDisplay(std::unique_ptr<Display> inner) : inner_(std::move(inner)) {}
  void type(KeyPress key) { typed_.push_back(key); }

  std::shared_ptr<gl::Context> context() const override { return inner_->context(); }
  GLuint packed_framebuffer() const override { return inner_->packed_framebuffer(); }
  GLuint packed_texture() const override { return inner_->packed_texture(); }
  std::array<int, 2> packed_size() const override { return inner_->packed_size(); }
  void present() override { inner_->present(); }
  double refresh_hz() const override { return inner_->refresh_hz(); }
  bool vsync() const override { return inner_->vsync(); }
  std::vector<KeyPress> poll_events() override {
    std::vector<KeyPress> keys = inner_->poll_events();
    keys.insert(keys.end(), typed_.begin(), typed_.end());
    typed_.clear();
    return keys;
  }
  bool close_requested() const override { return inner_->close_requested(); }
  std::string description() const override { return inner_->description(); }

 private:
  std::unique_ptr<Display> inner_;
  std::vector<KeyPress> typed_;
};

class PlayerTest : public ::testing::Test {
 protected:
  test::TempDir dir_;

  PlayerOptions silent_options() const { return test::silent_options(dir_); }
  // The offscreen output showing the packed frame of `options`' 160x90 panel.
  static std::unique_ptr<Display> open_display(const PlayerOptions& options) {
    return display_driver("offscreen").open_display(test::small_panel_display_options(options));
  }
  // Both eyes' panels of every frame `options` plays of `clip` on a stepped clock, by pts, with
  // `key` (if any) typed at the first frame.
  std::map<double, std::array<Image, 2>> panels_played(const std::filesystem::path& clip, PlayerOptions options,
                                                       std::optional<KeyPress> key = std::nullopt) const {
    const auto left = *eye_area(options.signal, Eye::left, 160, 90);
    const auto right = *eye_area(options.signal, Eye::right, 160, 90);
    std::map<double, std::array<Image, 2>> shown;
    options.clock = std::make_shared<playback::SteppedClock>();
    TypedKeysDisplay display(open_display(options));
    options.after_render = [&](const Display& d, double pts) {
      const auto panel = [&](const EyeArea& a) {
        return read_back(d.packed_framebuffer(), a.x + (a.width - 160) / 2, a.y + (a.height - 90) / 2, 160, 90);
      };
      shown[pts] = {panel(left), panel(right)};
      if (key) display.type(*std::exchange(key, std::nullopt));
    };
    auto source = test::open_input(clip);
    EXPECT_EQ(play(display, *source, options).end, PlayEnd::end_of_file);
    return shown;
  }
  // How many pixels of two 160x90 panels differ by more than `threshold` (summed over R, G, B).
  static int differing(const Image& a, const Image& b, float threshold) {
    int changed = 0;
    for (std::size_t i = 0; i < std::size_t{160} * 90; ++i) {
      const float* p = &a.data()[i * 4];
      const float* q = &b.data()[i * 4];
      if (std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) > threshold) ++changed;
    }
    return changed;
  }
};

TEST_F(PlayerTest, PlaysTheClipInThePackedLayoutWithEachEyesContentAndFramesAdvance) {
  const auto clip = make_clip(dir_);
  PlayerOptions options = silent_options();

  auto display = open_display(options);

  const auto left = *eye_area(options.signal, Eye::left, 160, 90);
  const auto right = *eye_area(options.signal, Eye::right, 160, 90);
  ASSERT_LT(left.y + left.height, right.y);  // frame packing: a gap between the eyes
  struct Seen {
    double pts;
    Mean left, right, gap, left_margin;
    std::vector<float> left_pixels;
  };
  std::vector<Seen> seen;
  options.after_render = [&](const Display& d, double pts) {
    const auto panel = [&](const EyeArea& a) {
      return read_back(d.packed_framebuffer(), a.x + (a.width - 160) / 2, a.y + (a.height - 90) / 2, 160, 90);
    };
    const Image l = panel(left);
    const Image r = panel(right);
    const Image gap = read_back(d.packed_framebuffer(), 0, left.y + left.height, 1280, right.y - left.y - left.height);
    const Image margin = read_back(d.packed_framebuffer(), left.x, left.y, 400, 200);  // eye area outside the panel
    seen.push_back({pts, mean_of(l), mean_of(r), mean_of(gap), mean_of(margin),
                    std::vector<float>(l.data(), l.data() + static_cast<std::size_t>(l.width()) * l.height() * 4)});
  };

  auto source = open_source(SourceRequest{clip.string(), "", std::nullopt, false, std::nullopt, true, false});
  const PlayResult result = play(*display, *source, options);
  EXPECT_EQ(result.end, PlayEnd::end_of_file);
  ASSERT_GE(seen.size(), 5u) << "too few frames rendered";
  EXPECT_EQ(result.counters.shown + result.counters.dropped, 60);
  EXPECT_EQ(static_cast<std::int64_t>(seen.size()), result.counters.shown);

  std::set<std::vector<float>> distinct;
  for (std::size_t i = 0; i < seen.size(); ++i) {
    const Seen& s = seen[i];
    SCOPED_TRACE("frame at " + std::to_string(s.pts));
    EXPECT_GT(s.left.r, s.left.b + 0.2);    // the left eye shows the red-ish view
    EXPECT_GT(s.right.b, s.right.r + 0.2);  // the right eye the blue-ish one
    EXPECT_LT(s.gap.max, 0.01);             // the frame-packing gap is black
    EXPECT_LT(s.left_margin.max, 0.01);     // outside the panel: black
    if (i > 0) {
      EXPECT_GT(s.pts, seen[i - 1].pts);
    }
    distinct.insert(s.left_pixels);
  }
  // The moving box: every rendered frame looks different.
  EXPECT_EQ(distinct.size(), seen.size());
  EXPECT_NEAR(seen.back().pts, 59 / 30.0, 0.5);
}

TEST_F(PlayerTest, SwapEyesPutsTheFirstStoredViewOnTheRight) {
  const auto clip = make_clip(dir_);
  PlayerOptions options = silent_options();
  auto display = open_display(options);
  const auto left = *eye_area(options.signal, Eye::left, 160, 90);
  std::vector<Mean> left_means;
  options.after_render = [&](const Display& d, double) {
    left_means.push_back(mean_of(read_back(d.packed_framebuffer(), left.x + 560, left.y + 315, 160, 90)));
  };
  std::atomic<bool> stop{false};
  auto source = open_source(SourceRequest{clip.string(), "", StereoLayout::sbs, true, std::nullopt, true, false});
  // Stop after a few frames: this test is about the routing only.
  auto original = options.after_render;
  options.after_render = [&](const Display& d, double pts) {
    original(d, pts);
    if (left_means.size() >= 3) stop = true;
  };
  const PlayResult result = play(*display, *source, options, &stop);
  EXPECT_EQ(result.end, PlayEnd::interrupted);
  ASSERT_FALSE(left_means.empty());
  for (const Mean& m : left_means) EXPECT_GT(m.b, m.r + 0.2);
}

// refuses every view format but whole views (as before the player asked for block means).
class RecordingSource final : public Source {
 public:
  RecordingSource(std::unique_ptr<Source> inner, bool allow_reduction)
      : inner_(std::move(inner)), allow_(allow_reduction) {}
  std::optional<StereoVideoFrame> next() override {
    auto f = inner_->next();
    if (f) blocks.push_back(f->block);
    return f;
  }
  SourceInfo info() const override { return inner_->info(); }
  void seek(double seconds) override { inner_->seek(seconds); }
  ViewFormat negotiate(const ViewFormat& wanted) override { return allow_ ? inner_->negotiate(wanted) : ViewFormat{}; }
  std::vector<std::array<int, 2>> blocks;

 private:
  std::unique_ptr<Source> inner_;
  bool allow_;
};

TEST_F(PlayerTest, PlaysFromTheCompositorsBlockMeansWithTheSameImageAsFromWholeViews) {
  const auto clip = make_clip(dir_);
  PlayerOptions options = silent_options();
  const auto wanted = stereo_prefilter_block(options.profile, options.compositor, 320, 180, 0.0);
  ASSERT_TRUE(wanted[0] > 1 || wanted[1] > 1) << "the test profile should make the compositor average blocks";
  auto display = open_display(options);
  const auto left = *eye_area(options.signal, Eye::left, 160, 90);
  const auto right = *eye_area(options.signal, Eye::right, 160, 90);

  // The first frame, played once from block means and once from whole views.
  std::vector<Image> shown;
  std::atomic<bool> stop{false};
  options.after_render = [&](const Display& d, double) {
    shown.push_back(read_back(d.packed_framebuffer(), 0, 0, d.packed_size()[0], d.packed_size()[1]));
    stop = true;
  };
  std::vector<std::array<int, 2>> blocks[2];
  for (bool reduce : {true, false}) {
    stop = false;
    RecordingSource source(
        open_source(SourceRequest{clip.string(), "", std::nullopt, false, std::nullopt, true, false}), reduce);
    play(*display, source, options, &stop);
    blocks[reduce ? 0 : 1] = source.blocks;
  }
  ASSERT_EQ(shown.size(), 2u);
  ASSERT_FALSE(blocks[0].empty());
  for (const auto& b : blocks[0]) EXPECT_EQ(b, wanted);
  for (const auto& b : blocks[1]) EXPECT_EQ(b, (std::array<int, 2>{1, 1}));
  // Same picture in both eyes' panels (rounding-level differences only).
  for (const EyeArea& a : {left, right}) {
    double sum = 0.0, worst = 0.0;
    const int x0 = a.x + (a.width - 160) / 2, y0 = a.y + (a.height - 90) / 2;
    for (int y = y0; y < y0 + 90; ++y)
      for (int x = x0; x < x0 + 160; ++x)
        for (int c = 0; c < 3; ++c) {
          const std::size_t i = (static_cast<std::size_t>(y) * shown[0].width() + x) * 4 + c;
          const double d = std::abs(shown[0].data()[i] - shown[1].data()[i]);
          sum += d;
          worst = std::max(worst, d);
        }
    EXPECT_LT(sum / (160.0 * 90 * 3), 0.01);
    EXPECT_LT(worst, 0.15);
  }
}

// Sets an environment variable for a scope, restoring what was there before.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (old_)
      setenv(name_.c_str(), old_->c_str(), 1);
    else
      unsetenv(name_.c_str());
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_;
  std::optional<std::string> old_;
};

TEST_F(PlayerTest, TheCompositeTableShowsWhatTheGlCompositorShowsAndMessagesStillShow) {
  // On software GL the player composites 8-bit block means on the CPU from composite tables and
  // uploads the packed frame; NELF_COMPOSITE picks either path. The same clip played both ways,
  // with 's' and 'c' pressed at 1 s: their message (2 s) is drawn with GL onto the view textures
  // in the GL run and into the views' bytes in the table run (TextOverlay::cover), eyes swapped
  // and the calibration grid drawn into the views' bytes too. Every frame both runs rendered (by
  // pts: a loaded machine may drop different ones) looks the same, text and grid included. The
  // table run's frames are mostly composited ahead, on a worker (compositor/cpu/composite_ahead).
  const auto clip = make_clip(dir_, 4);
  PlayerOptions options = silent_options();
  const auto wanted = stereo_prefilter_block(options.profile, options.compositor, 320, 180, 0.0);
  ASSERT_TRUE(wanted[0] > 1 || wanted[1] > 1) << "the table needs block means";
  TypedKeysDisplay display(open_display(options));
  const auto left = *eye_area(options.signal, Eye::left, 160, 90);
  const auto right = *eye_area(options.signal, Eye::right, 160, 90);
  const auto panel = [](const Display& d, const EyeArea& a) {
    return read_back(d.packed_framebuffer(), a.x + (a.width - 160) / 2, a.y + (a.height - 90) / 2, 160, 90);
  };
  struct Frame {
    Image left, right;
    Mean gap;
  };
  std::map<double, Frame> shown[2];  // [0]: table, [1]: gl
  for (int path : {0, 1}) {
    const ScopedEnv composite("NELF_COMPOSITE", path == 0 ? "table" : "gl");
    bool pressed = false;
    options.after_render = [&](const Display& d, double pts) {
      // A redraw of the same pts (the message's) replaces the frame.
      shown[path][pts] = Frame{
          panel(d, left), panel(d, right),
          mean_of(read_back(d.packed_framebuffer(), 0, left.y + left.height, 1280, right.y - left.y - left.height))};
      if (!pressed && pts >= 1.0) {
        display.type(KeyPress::of(U's'));
        display.type(KeyPress::of(U'c'));
        pressed = true;
      }
    };
    auto source = open_source(SourceRequest{clip.string(), "", std::nullopt, false, std::nullopt, true, false});
    const PlayResult result = play(display, *source, options);
    EXPECT_EQ(result.end, PlayEnd::end_of_file);
    ASSERT_TRUE(pressed);
    // The table run shows most frames as composited ahead on the worker (the frames compared
    // below are mostly those), the GL run none.
    if (path == 0) {
      EXPECT_GE(result.composited_ahead, 20);
    } else {
      EXPECT_EQ(result.composited_ahead, 0);
    }
  }
  // The keys arrive with some later poll: the first frame with the blue view on the left or the
  // grid is where each run took them (and said so).
  double keys_at[2] = {0.0, 0.0};
  for (int path : {0, 1}) {
    const auto changed = std::find_if(shown[path].begin(), shown[path].end(), [](const auto& f) {
      const Mean l = mean_of(f.second.left);
      return l.b > l.r || grid_pixels(f.second.left) > 0;
    });
    ASSERT_NE(changed, shown[path].end()) << "'s' and 'c' changed nothing";
    keys_at[path] = changed->first;
  }
  // Before the keys: the table; after them, while the message surely shows: GL with text in both
  // runs; once it has surely gone: the table, eyes swapped, grid on. Frames between the two runs'
  // keys (and a margin for 'c' coming a poll after 's'), or around the message's end, may differ
  // in what they show, and are skipped.
  const double first_key = std::min(keys_at[0], keys_at[1]);
  const double last_key = std::max(keys_at[0], keys_at[1]);
  int before = 0, message = 0, after = 0;
  for (const auto& [pts, table] : shown[0]) {
    const auto gl = shown[1].find(pts);
    if (gl == shown[1].end()) continue;
    if (pts < first_key)
      ++before;
    else if (pts >= last_key + 0.3 && pts < first_key + 1.5)
      ++message;
    else if (pts >= last_key + 2.5)
      ++after;
    else
      continue;
    SCOPED_TRACE("frame at " + std::to_string(pts));
    if (pts < first_key) {
      const Mean l = mean_of(table.left), r = mean_of(table.right);
      EXPECT_GT(l.r, l.b + 0.2);  // not black: each eye its own view
      EXPECT_GT(r.b, r.r + 0.2);
      EXPECT_EQ(grid_pixels(table.left) + grid_pixels(table.right), 0);
    } else {
      EXPECT_GT(grid_pixels(table.left), 500);  // the grid on the table path too
      EXPECT_GT(grid_pixels(table.right), 500);
      const Mean l = mean_of(table.left), r = mean_of(table.right);
      EXPECT_GT(r.r - r.b, l.r - l.b + 0.15);  // swapped: the red-ish view now on the right
    }
    EXPECT_LT(table.gap.max, 0.01);  // the frame-packing gap black on the CPU path too
    for (const auto& [a, b] : {std::pair{&table.left, &gl->second.left}, {&table.right, &gl->second.right}}) {
      double sum = 0.0, worst = 0.0;
      const std::size_t n = static_cast<std::size_t>(a->width()) * a->height();
      for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 4; ++c) {  // alpha too: the CPU path writes it opaque, as GL does
          const double d = std::abs(a->data()[i * 4 + c] - b->data()[i * 4 + c]);
          sum += d;
          worst = std::max(worst, d);
        }
      EXPECT_LT(sum / (4.0 * n), 1.0 / 255);  // the table agrees with GL to a code value or two
      EXPECT_LT(worst, 4.5 / 255);            // and the text box shows on both (far more than that)
    }
  }
  const std::string why = fmt::format("{} frames in the table run, {} in the GL run; keys taken at {} and {} s",
                                      shown[0].size(), shown[1].size(), keys_at[0], keys_at[1]);
  EXPECT_GE(before, 5) << why;
  EXPECT_GE(message, 5) << why;
  EXPECT_GE(after, 5) << why;
}

TEST_F(PlayerTest, NoFrameCompositedAheadShowsAStateAKeyHasChanged) {
  // On the CPU path a worker composites the next queued frames ahead (compositor/cpu/composite_ahead)
  // with the state of the moment; a key changes that state while such frames wait. Without
  // on-screen messages (while one shows, GL draws the frames) the table path goes on right after
  // the key, so a frame made before it would be seen at once. The clip played on the table path
  // and on GL, keys typed during both: 's' (swap eyes), 'c' (calibration grid, drawn into the
  // views), ']' (IPD: new tables for the same views), ← (seek back to the start). Every frame shown
  // after a key has its effect, and each frame both runs rendered in the same state (keys typed
  // before it, pts) looks the same. The GL run takes each key 0.3 s earlier, so that the table
  // run's frames right after its keys, where a stale frame would be, have GL frames to match.
  const auto clip = make_clip(dir_, 4);
  PlayerOptions options = silent_options();
  options.on_screen_messages = false;
  const auto wanted = stereo_prefilter_block(options.profile, options.compositor, 320, 180, 0.0);
  ASSERT_TRUE(wanted[0] > 1 || wanted[1] > 1) << "the table needs block means";
  TypedKeysDisplay display(open_display(options));
  const auto left = *eye_area(options.signal, Eye::left, 160, 90);
  const auto right = *eye_area(options.signal, Eye::right, 160, 90);
  const auto panel = [](const Display& d, const EyeArea& a) {
    return read_back(d.packed_framebuffer(), a.x + (a.width - 160) / 2, a.y + (a.height - 90) / 2, 160, 90);
  };
  const std::vector<std::pair<double, KeyPress>> keys = {{0.8, KeyPress::of(U's')},
                                                         {1.4, KeyPress::of(U'c')},
                                                         {2.0, KeyPress::of(U']')},
                                                         {2.6, KeyPress::of(KeyPress::Named::left)}};
  struct Frame {
    Image left, right;
  };
  // [0]: table, [1]: gl; by (keys typed before the frame was rendered, pts).
  std::map<std::pair<std::size_t, double>, Frame> shown[2];
  PlayResult results[2];
  for (int path : {0, 1}) {
    const ScopedEnv composite("NELF_COMPOSITE", path == 0 ? "table" : "gl");
    const double lead = path == 1 ? 0.3 : 0.0;
    std::size_t typed = 0;
    options.after_render = [&](const Display& d, double pts) {
      shown[path][{typed, pts}] = Frame{panel(d, left), panel(d, right)};
      if (typed < keys.size() && pts >= keys[typed].first - lead) display.type(keys[typed++].second);
    };
    auto source = open_source(SourceRequest{clip.string(), "", std::nullopt, false, std::nullopt, true, false});
    results[path] = play(display, *source, options);
    EXPECT_EQ(results[path].end, PlayEnd::end_of_file);
    ASSERT_EQ(typed, keys.size());
  }
  // Most frames of the table run came from the worker, none of the GL run's.
  EXPECT_GE(results[0].composited_ahead * 2, results[0].counters.shown)
      << results[0].composited_ahead << " of " << results[0].counters.shown;
  EXPECT_EQ(results[1].composited_ahead, 0);

  std::map<std::size_t, int> compared;
  int after_seek = 0;
  for (const auto& [key, table] : shown[0]) {
    const auto& [typed, pts] = key;
    SCOPED_TRACE(fmt::format("table frame at {} s after {} keys", pts, typed));
    const Mean l = mean_of(table.left), r = mean_of(table.right);
    if (typed == 0) {
      EXPECT_GT(l.r, l.b + 0.2);  // each eye its own view
      EXPECT_GT(r.b, r.r + 0.2);
    } else {
      EXPECT_GT(r.r - r.b, l.r - l.b + 0.15);  // swapped: the red-ish view on the right
    }
    if (typed >= 2) {
      EXPECT_GT(grid_pixels(table.left), 500);
      EXPECT_GT(grid_pixels(table.right), 500);
    } else {
      EXPECT_EQ(grid_pixels(table.left) + grid_pixels(table.right), 0);
    }
    if (typed == 4 && pts < keys[3].first - 0.5) ++after_seek;
    const auto gl = shown[1].find(key);
    if (gl == shown[1].end()) continue;
    ++compared[typed];
    for (const auto& [a, b] : {std::pair{&table.left, &gl->second.left}, {&table.right, &gl->second.right}}) {
      double sum = 0.0, worst = 0.0;
      const std::size_t n = static_cast<std::size_t>(a->width()) * a->height();
      for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 4; ++c) {
          const double d = std::abs(a->data()[i * 4 + c] - b->data()[i * 4 + c]);
          sum += d;
          worst = std::max(worst, d);
        }
      EXPECT_LT(sum / (4.0 * n), 1.0 / 255);
      EXPECT_LT(worst, 4.5 / 255);
    }
  }
  EXPECT_GE(after_seek, 20) << "the seek back did not show the start again";
  for (std::size_t typed = 0; typed <= keys.size(); ++typed)
    EXPECT_GE(compared[typed], 5) << "too few frames in the same state in both runs after " << typed << " keys";
}

// The subtitles play draws into the frames as they are decoded: a cue from 0.6 s to 1.4 s of the clip is
// in both eyes' panels while it shows and in neither before or after (the same clip played without
// it on the stepped clock is the reference). The views arrive as block means here (80x45), so the
// letters are a few pixels: a small difference counts.
TEST_F(PlayerTest, ASubtitleCueShowsInBothEyesForItsTimeOnly) {
  const auto clip = make_clip(dir_, 2);
  test::write_file(dir_ / "cue.srt", "1\n00:00:00,600 --> 00:00:01,400\nHELLO 3D WORLD\n\n");
  PlayerOptions options = silent_options();
  const auto without = panels_played(clip, options);
  options.subtitles = std::make_shared<SubtitleTrack>((dir_ / "cue.srt").string(), 0.0);
  const auto with = panels_played(clip, options);
  options.subtitles = std::make_shared<SubtitleTrack>((dir_ / "cue.srt").string(), 0.0);
  options.on_screen_messages = false;  // "subtitles off" would be over the frames compared
  const auto hidden_by_v = panels_played(clip, options, KeyPress::of(U'v'));
  int during = 0, outside = 0, hidden = 0;
  for (const auto* run : {&with, &hidden_by_v})
    for (const auto& [pts, eyes] : *run) {
      if (!without.count(pts) || std::abs(pts - 0.6) < 0.05 || std::abs(pts - 1.4) < 0.05) continue;
      const bool showing = run == &with && pts > 0.6 && pts < 1.4;
      for (std::size_t e : {0u, 1u}) {
        const int changed = differing(eyes[e], without.at(pts)[e], 0.05f);
        if (showing)
          EXPECT_GT(changed, 20) << "no subtitle at " << pts << " s in eye " << e;
        else
          EXPECT_EQ(changed, 0) << "a subtitle at " << pts << " s in eye " << e;
      }
      if (run == &hidden_by_v)
        ++hidden;
      else
        ++(showing ? during : outside);
    }
  EXPECT_GE(during, 15);
  EXPECT_GE(outside, 20);
  EXPECT_GE(hidden, 40);  // v at the first frame: none of the cue's frames shows it
}

// --sub-parallax auto while playing: over a textured surface 15 of the views' 320 pixels in front of
// the screen (estimated from the block means play decodes), the line is drawn where a fixed 5 %
// draws it (4.94 %: just in front), frame after frame, and not where 2 % does.
TEST_F(PlayerTest, AutoSubtitleDepthDrawsTheLineJustInFrontOfThePicture) {
  const auto clip = test::make_media(
      dir_ / "deep.mp4",
      "-f lavfi -i " +
          test::shell_quote("color=c=gray:s=352x180:r=30:d=1,format=rgb24,noise=alls=80:allf=t+u,gblur=sigma=0.8,"
                            "split[a][b];[a]crop=320:180:0:0[l];[b]crop=320:180:15:0[r];[l][r]hstack") +
          " -c:v libx264 -preset ultrafast -crf 12 -pix_fmt yuv420p");
  test::write_file(dir_ / "line.srt", "1\n00:00:00,000 --> 00:00:01,000\nHELLO 3D WORLD\n\n");
  PlayerOptions options = silent_options();
  const auto played = [&](SubtitleDepth depth) {
    options.subtitles = std::make_shared<SubtitleTrack>((dir_ / "line.srt").string(), 0.0);
    options.sub_depth = depth;
    return panels_played(clip, options);
  };
  const auto automatic = played({true, auto_sub_margin_percent});
  const auto five = played({false, 5.0});
  const auto two = played({false, 2.0});
  int compared = 0;
  for (const auto& [pts, eyes] : automatic) {
    if (!five.count(pts) || !two.count(pts)) continue;
    for (std::size_t e : {0u, 1u}) {
      EXPECT_EQ(differing(eyes[e], five.at(pts)[e], 0.0f), 0) << "not at 5 % at " << pts << " s in eye " << e;
      EXPECT_GT(differing(eyes[e], two.at(pts)[e], 0.05f), 5) << "at 2 % at " << pts << " s in eye " << e;
    }
    ++compared;
  }
  EXPECT_GE(compared, 20);
}

// j and J step through the subtitle tracks, off between the last and the first: j from the first of
// two shows the second's words from then on, J the none.
TEST_F(PlayerTest, JAndShiftJSwitchTheSubtitleTrackWhilePlaying) {
  const auto clip = make_clip(dir_, 2);
  test::write_file(dir_ / "one.srt", "1\n00:00:00,000 --> 00:00:02,000\nIIII\n\n");
  test::write_file(dir_ / "two.srt", "1\n00:00:00,000 --> 00:00:02,000\nWWWWWWWW WWWWWWWW\n\n");
  PlayerOptions options = silent_options();
  const auto without = panels_played(clip, options);
  options.on_screen_messages = false;  // "Subtitles: …" would be over the frames compared
  options.subtitle_tracks = {{(dir_ / "one.srt").string(), 1, "no language, subrip"},
                             {(dir_ / "two.srt").string(), 1, "no language, subrip"}};
  const auto first = [&] { return std::make_shared<SubtitleTrack>((dir_ / "one.srt").string(), 0.0); };
  options.subtitles = first();
  const auto one = panels_played(clip, options);
  options.subtitles = first();
  const auto two = panels_played(clip, options, KeyPress::of(U'j'));
  options.subtitles = first();
  const auto off = panels_played(clip, options, KeyPress::of(U'J'));
  int compared = 0;
  for (const auto& [pts, eyes] : one) {
    if (pts < 0.3 || !without.count(pts) || !two.count(pts) || !off.count(pts)) continue;
    for (std::size_t e : {0u, 1u}) {
      EXPECT_GT(differing(eyes[e], without.at(pts)[e], 0.05f), 20) << "track 1 not shown at " << pts;
      EXPECT_GT(differing(two.at(pts)[e], eyes[e], 0.05f), 20) << "still track 1 after j at " << pts;
      EXPECT_GT(differing(two.at(pts)[e], without.at(pts)[e], 0.05f), 20) << "no track 2 at " << pts;
      EXPECT_EQ(differing(off.at(pts)[e], without.at(pts)[e], 0.05f), 0) << "subtitles after J at " << pts;
    }
    ++compared;
  }
  EXPECT_GE(compared, 30);
}

// On the tests' stepped clock the play loop's decisions follow from the timestamps and the refresh
// rate alone: a 24 fps clip on the 60 Hz signal shows every frame, none repeated or dropped, each
// at the refresh FrameScheduler chooses for it (the 2, 3, 2, 3 … cadence), and the frame log says
// so row by row, its clock one refresh period further each refresh.
// O keeps the time line and seek bar on: the same clip on the stepped clock with and without it
// differs, in both eyes' panels, at every frame from half a second on.
TEST_F(PlayerTest, KeyOShowsTheTimeLineAndSeekBarInBothEyes) {
  const auto clip = make_clip(dir_, 2);
  const PlayerOptions options = silent_options();
  const auto without = panels_played(clip, options);
  const auto with = panels_played(clip, options, KeyPress::of(U'O'));
  int compared = 0;
  for (const auto& [pts, eyes] : with) {
    if (pts < 0.5 || !without.count(pts)) continue;
    for (std::size_t e : {0u, 1u})
      EXPECT_GT(differing(eyes[e], without.at(pts)[e], 0.3f), 100) << "no time line at " << pts << " s in eye " << e;
    ++compared;
  }
  EXPECT_GE(compared, 30);
}

TEST_F(PlayerTest, OnASteppedClockEachFrameIsShownAtTheRefreshTheSchedulerChooses) {
  const auto clip = test::make_media(dir_ / "24fps.mp4", test::two_colour_input(320, 180, false, 48, 24) + test::h264);
  PlayerOptions options = silent_options();
  options.clock = std::make_shared<playback::SteppedClock>();
  options.log_frames = (dir_ / "frames.csv").string();
  auto display = open_display(options);
  auto source = test::open_input(clip);
  ASSERT_NEAR(source->info().frame_rate, 24.0, 1e-9);
  const PlayResult result = play(*display, *source, options);
  EXPECT_EQ(result.end, PlayEnd::end_of_file);
  EXPECT_EQ(result.counters.shown, 48);
  EXPECT_EQ(result.counters.repeated, 0);
  EXPECT_EQ(result.counters.dropped, 0);

  // The prediction: refresh k is seen at k refresh periods (the clock starts with the first frame
  // on screen), the decoder never late.
  const double period = 1.0 / display->refresh_hz();
  FrameScheduler scheduler(period, 1.0 / 24);
  std::vector<double> pending;
  for (int n = 0; n < 48; ++n) pending.push_back(n / 24.0);
  std::vector<std::string> expected;
  for (std::int64_t k = 0;; ++k) {
    const std::size_t queued = std::min<std::size_t>(pending.size(), 6);
    const FrameDecision d =
        scheduler.decide(static_cast<double>(k) * period, std::span(pending).first(queued), pending.size() <= 6);
    if (d.finished) break;
    ASSERT_LT(k, 1000) << "the prediction never ends";
    if (d.show_front) {
      expected.push_back(fmt::format("{},shown,{:.6f},{:.6f}", k, pending[d.drop], static_cast<double>(k) * period));
      pending.erase(pending.begin(), pending.begin() + static_cast<std::ptrdiff_t>(d.drop) + 1);
    } else if (d.repeat) {
      expected.push_back(fmt::format("{},repeated", k));
    }
  }
  EXPECT_EQ(scheduler.counters().shown, 48);
  ASSERT_EQ(expected.size(), 48u);
  // Frame n is on screen from refresh ceil(2.5 n - 0.5): 0, 2, 5, 7, 10, …
  EXPECT_EQ(expected[1].substr(0, 2), "2,");
  EXPECT_EQ(expected[2].substr(0, 2), "5,");
  EXPECT_EQ(expected[3].substr(0, 2), "7,");

  std::vector<std::string> logged;
  std::istringstream log(test::read_file(dir_ / "frames.csv"));
  std::string line;
  std::getline(log, line);  // the header
  while (std::getline(log, line)) {
    // refresh,event,pts_s,clock_s: the columns the decisions are made of.
    std::size_t end = 0;
    for (int comma = 0; comma < 4; ++comma) end = line.find(',', end) + 1;
    logged.push_back(line.substr(0, end - 1));
  }
  EXPECT_EQ(logged, expected);
}

}  // namespace
}  // namespace nelf
