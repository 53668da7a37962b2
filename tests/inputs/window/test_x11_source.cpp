// The x11: source on the test game's window (private Xvfb): every stereo layout the game draws is
// split into the views the game drew, frame after frame as the game presents them (read back from
// the frame stamps in both eyes), resizes are followed, a closed window ends the source, and each
// way of naming a window that finds none, or several, is one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/frame_stamp.hpp"
#include "core/user_error.hpp"
#include "inputs/source_drivers.hpp"
#include "support/source_requests.hpp"
#include "support/test_game.hpp"
#include "support/xvfb.hpp"

// Last: Xlib's macros (None, Bool, Status) would break the headers above.
#include <X11/Xlib.h>

namespace nelf {
namespace {

using namespace std::chrono_literals;

std::int64_t monotonic_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1000000000 + t.tv_nsec;
}

using test::quiet_request;

struct Stamps {
  FrameStamp left, right;
};

std::optional<Stamps> stamps_of(const StereoVideoFrame& f) {
  const auto left = read_frame_stamp(f.left.data(), f.width, f.height, f.bits);
  const auto right = read_frame_stamp(f.right.data(), f.width, f.height, f.bits);
  if (!left || !right) return std::nullopt;
  return Stamps{*left, *right};
}

class X11SourceTest : public ::testing::Test {
 protected:
  test::XvfbServer xvfb_{2600, 1600};
  test::ScopedDisplay display_env_{xvfb_.display_name()};
};

struct LayoutCase {
  const char* mode;
  std::vector<std::string> size;
  std::optional<StereoLayout> flag;
  int view_w, view_h;
  const char* layout;
};

TEST_F(X11SourceTest, EachLayoutTheGameDrawsGivesItsTwoViewsFrameAfterFrame) {
  const LayoutCase cases[] = {
      {"sbs", {"--size", "320x180"}, std::nullopt, 320, 180, "layout sbs (aspect)"},
      {"tab", {"--size", "320x180"}, std::nullopt, 320, 180, "layout tab (aspect)"},
      {"fp", {"--size", "1280x720"}, std::nullopt, 1280, 720, "layout fp (frame-size)"},
      {"sbs-half", {"--size", "320x180"}, StereoLayout::sbs_half, 160, 180, "layout sbs-half (flag)"},
  };
  for (const LayoutCase& c : cases) {
    SCOPED_TRACE(c.mode);
    const std::string title = std::string("layout game ") + c.mode;
    std::vector<std::string> args{"--mode", c.mode, "--fps", "30", "--title", title};
    args.insert(args.end(), c.size.begin(), c.size.end());
    test::TestGame game(args);
    auto source = open_source(quiet_request("x11:wait=10,window=" + title, c.flag));
    const SourceInfo info = source->info();
    EXPECT_TRUE(info.live);
    EXPECT_FALSE(info.seekable);
    EXPECT_FALSE(info.duration_s);
    EXPECT_FALSE(info.expected_frames);
    EXPECT_GT(info.frame_rate, 0.0);
    EXPECT_EQ(std::count(info.description.begin(), info.description.end(), '\n'), 0);
    try {
      source->seek(1.0);
      ADD_FAILURE() << "a window seeked";
    } catch (const UserError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
    EXPECT_NE(info.description.find(c.layout), std::string::npos) << info.description;
    EXPECT_EQ(info.view.width, c.view_w);
    EXPECT_EQ(info.view.height, c.view_h);
    std::optional<std::uint32_t> last_frame;
    double last_pts = -1;
    int stamped = 0, new_frames = 0;
    for (int i = 0; i < 12; ++i) {
      const auto frame = source->next();
      ASSERT_TRUE(frame);
      EXPECT_EQ(frame->width, c.view_w);
      EXPECT_EQ(frame->height, c.view_h);
      EXPECT_GT(frame->pts_s, last_pts);
      last_pts = frame->pts_s;
      const auto stamps = stamps_of(*frame);
      if (!stamps) continue;  // the window's first contents, before the game's first frame
      ++stamped;
      EXPECT_EQ(stamps->left, stamps->right) << "one game frame in both eyes";
      test::expect_game_background_below_the_bars(frame->left, frame->width, frame->height);
      test::expect_game_background_below_the_bars(frame->right, frame->width, frame->height);
      // A game frame may be read twice: the server draws a large frame in several requests, each
      // a change (the second read is of the whole frame); never an older one.
      if (last_frame) {
        EXPECT_GE(stamps->left.frame, *last_frame) << "frames in the order the game presented them";
        if (stamps->left.frame > *last_frame) ++new_frames;
      }
      last_frame = stamps->left.frame;
      const double age_s = (monotonic_ns() - stamps->left.present_ns) * 1e-9;
      EXPECT_GE(age_s, 0.0);
      EXPECT_LT(age_s, 1.0);
    }
    EXPECT_GE(stamped, 10);
    EXPECT_GE(new_frames, 7);
  }
}

TEST_F(X11SourceTest, ViewsComeAsTheBlockMeansTheCompositorAsksFor) {
  test::TestGame game({"--mode", "sbs", "--size", "640x360", "--title", "block game"});
  auto source = open_source(quiet_request("x11:wait=10,window=block game"));
  EXPECT_EQ(source->negotiate({{2, 3}}), (ViewFormat{{2, 3}}));  // 320x120 means of each view
  int stamped = 0;
  for (int i = 0; i < 8; ++i) {
    const auto f = source->next();
    ASSERT_TRUE(f);
    EXPECT_EQ(f->block, (std::array<int, 2>{2, 3}));
    EXPECT_EQ(f->width, 640);  // the full view's size, as every frame says it
    ASSERT_EQ(f->left.size(), std::size_t{320} * 120 * 4);
    ASSERT_EQ(f->right.size(), f->left.size());
    const auto left = read_frame_stamp(f->left.data(), 320, 120, 8);
    const auto right = read_frame_stamp(f->right.data(), 320, 120, 8);
    if (left && right) {
      ++stamped;
      EXPECT_EQ(*left, *right);
      test::expect_game_background_below_the_bars(f->left, 320, 120);
    }
  }
  EXPECT_GE(stamped, 6) << "the game's stamps read from the block means";
  EXPECT_EQ(source->negotiate({{1, 1}}), ViewFormat{});
  const auto whole = source->next();
  ASSERT_TRUE(whole);
  EXPECT_EQ(whole->left.size(), std::size_t{640} * 360 * 4);
}

TEST_F(X11SourceTest, SwappedEyesAreExchanged) {
  test::TestGame game({"--mode", "sbs", "--size", "320x180", "--title", "swap game"});
  SourceRequest r = quiet_request("x11:wait=10,window=swap game");
  r.swap_eyes = true;
  auto source = open_source(r);
  EXPECT_NE(source->info().description.find("layout sbs swapped"), std::string::npos) << source->info().description;
}

TEST_F(X11SourceTest, AResizedWindowIsScaledToItsFirstSize) {
  test::TestGame game({"--mode", "sbs", "--size", "320x180", "--title", "resize game"});
  auto source = open_source(quiet_request("x11:wait=10,window=resize game"));
  const std::string description = source->info().description;
  const std::size_t at = description.find("window 0x");
  ASSERT_NE(at, std::string::npos);
  const unsigned long id = std::stoul(description.substr(at + 9), nullptr, 16);
  ::Display* d = XOpenDisplay(nullptr);
  ASSERT_NE(d, nullptr);
  XResizeWindow(d, id, 960, 270);
  XSync(d, False);
  XCloseDisplay(d);
  int stamped_after = 0;
  for (int i = 0; i < 40 && stamped_after < 5; ++i) {
    const auto frame = source->next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->width, 320);
    EXPECT_EQ(frame->height, 180);
    if (i > 10 && stamps_of(*frame)) {
      ++stamped_after;
      test::expect_game_background_below_the_bars(frame->left, frame->width, frame->height);  // scaled
    }
  }
  EXPECT_EQ(stamped_after, 5) << "the game's frames still read after the resize";
}

TEST_F(X11SourceTest, TheSourceEndsWhenTheWindowCloses) {
  test::TestGame game({"--mode", "sbs", "--size", "320x180", "--title", "short game", "--frames", "20"});
  auto source = open_source(quiet_request("x11:wait=10,window=short game"));
  int frames = 0;
  const auto start = std::chrono::steady_clock::now();
  while (source->next()) ++frames;
  EXPECT_GE(frames, 2);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 10s);
  EXPECT_TRUE(game.wait_exit(5s));
  EXPECT_EQ(game.status(), 0);
}

TEST_F(X11SourceTest, InterruptEndsAWaitForAWindowThatNeverChanges) {
  ::Display* d = XOpenDisplay(nullptr);
  ASSERT_NE(d, nullptr);
  const Window w = XCreateSimpleWindow(d, DefaultRootWindow(d), 0, 0, 400, 100, 0, 0, 0x808080);
  XStoreName(d, w, "still window");
  XMapWindow(d, w);
  XSync(d, False);
  {
    auto source = open_source(quiet_request("x11:wait=5,window=still window", StereoLayout::sbs));
    ASSERT_TRUE(source->next());  // what it shows now
    std::atomic<bool> returned{false};
    std::optional<StereoVideoFrame> second;
    std::thread waiter([&] {
      second = source->next();
      returned = true;
    });
    std::this_thread::sleep_for(300ms);
    EXPECT_FALSE(returned) << "a window that does not change gives no new frame";
    const auto interrupted_at = std::chrono::steady_clock::now();
    source->interrupt();
    waiter.join();
    EXPECT_LT(std::chrono::steady_clock::now() - interrupted_at, 200ms);
    EXPECT_FALSE(second);
    EXPECT_FALSE(source->next());
  }
  XDestroyWindow(d, w);
  XCloseDisplay(d);
}

int status_of(const SourceRequest& r, std::string& message) {
  try {
    open_source(r);
  } catch (const UserError& e) {
    message = e.what();
    return e.status();
  }
  return 0;
}

TEST_F(X11SourceTest, SeveralMatchesAreListedToChooseOne) {
  test::TestGame a({"--mode", "sbs", "--size", "320x180", "--title", "twin game A"});
  test::TestGame b({"--mode", "sbs", "--size", "320x180", "--title", "twin game B"});
  // Both windows there first.
  open_source(quiet_request("x11:wait=10,window=twin game A"));
  open_source(quiet_request("x11:wait=10,window=twin game B"));
  std::string message;
  EXPECT_EQ(status_of(quiet_request("x11:window=twin game"), message), 2);
  EXPECT_NE(message.find("matches 2 windows"), std::string::npos) << message;
  EXPECT_NE(message.find("\"twin game A\" 640x180"), std::string::npos) << message;
  EXPECT_NE(message.find("\"twin game B\" 640x180"), std::string::npos) << message;
  EXPECT_NE(message.find("x11:window-id="), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

TEST_F(X11SourceTest, WhatFindsNoWindowIsOneLine) {
  std::string message;
  EXPECT_EQ(status_of(quiet_request("x11:window=no such game"), message), 1);
  EXPECT_NE(message.find("no window on display"), std::string::npos) << message;
  EXPECT_EQ(status_of(quiet_request("x11:window-id=0x7ffffff"), message), 1);
  EXPECT_NE(message.find("no window 0x7ffffff"), std::string::npos) << message;
  EXPECT_EQ(status_of(quiet_request("x11:display=:9999"), message), 1);
  EXPECT_NE(message.find("cannot open display :9999"), std::string::npos) << message;
  {
    test::ScopedDisplay none("");
    EXPECT_EQ(status_of(quiet_request("x11:"), message), 1);
    EXPECT_NE(message.find("DISPLAY is not set"), std::string::npos) << message;
  }
  EXPECT_EQ(status_of(quiet_request("x11:window=anything", StereoLayout::alt), message), 2);
  EXPECT_NE(message.find("layout alt needs a file"), std::string::npos) << message;
}

TEST_F(X11SourceTest, TheScreenIsASourceToo) {
  test::TestGame game({"--mode", "sbs", "--size", "320x180", "--title", "screen game"});
  open_source(quiet_request("x11:wait=10,window=screen game"));
  auto source = open_source(quiet_request("x11:"));
  EXPECT_EQ(source->info().view.width, 2600);
  EXPECT_EQ(source->info().view.height, 1600);  // 1.6:1: mono, with a warning
  int frames = 0;
  for (int i = 0; i < 5; ++i)
    if (source->next()) ++frames;
  EXPECT_EQ(frames, 5) << "the game changes the screen";
}

}  // namespace
}  // namespace nelf
