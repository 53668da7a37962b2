// The x11: input's spec: what each key means and the one line for each bad one.
#include <gtest/gtest.h>

#include "core/user_error.hpp"
#include "inputs/x11_capture.hpp"

namespace nelf {
namespace {

TEST(X11CaptureSpec, NothingNamesTheScreen) {
  EXPECT_TRUE(is_x11_capture_spec("x11:"));
  EXPECT_TRUE(is_x11_capture_spec("x11"));
  EXPECT_FALSE(is_x11_capture_spec("x11.mkv"));
  const X11CaptureSpec spec = parse_x11_capture_spec("x11:");
  EXPECT_FALSE(spec.title || spec.window_id || spec.pid);
  EXPECT_EQ(spec.display, "");
  EXPECT_DOUBLE_EQ(spec.fps, 60.0);
  EXPECT_DOUBLE_EQ(spec.wait_s, 0.0);
}

TEST(X11CaptureSpec, WindowTakesTheRestCommasIncluded) {
  const X11CaptureSpec spec = parse_x11_capture_spec("x11:display=:3,fps=30,wait=2.5,window=Doom 3, BFG");
  EXPECT_EQ(spec.display, ":3");
  EXPECT_DOUBLE_EQ(spec.fps, 30.0);
  EXPECT_DOUBLE_EQ(spec.wait_s, 2.5);
  ASSERT_TRUE(spec.title);
  EXPECT_EQ(*spec.title, "Doom 3, BFG");
}

TEST(X11CaptureSpec, WindowIdsInHexOrDecimal) {
  EXPECT_EQ(parse_x11_capture_spec("x11:window-id=0x1e00002").window_id, 0x1e00002ul);
  EXPECT_EQ(parse_x11_capture_spec("x11:window-id=31457282").window_id, 31457282ul);
}

TEST(X11CaptureSpec, AProcessWindowIsWaitedFor) {
  const X11CaptureSpec spec = parse_x11_capture_spec("x11:pid=1234");
  EXPECT_EQ(spec.pid, 1234);
  EXPECT_DOUBLE_EQ(spec.wait_s, 60.0);
  EXPECT_DOUBLE_EQ(parse_x11_capture_spec("x11:wait=0,pid=1234").wait_s, 0.0);
}

TEST(X11CaptureSpec, BadKeysAndValuesAreOneLineWithStatus2) {
  const std::pair<const char*, const char*> cases[] = {
      {"x11:windw=a", "unknown key windw"},
      {"x11:window=", "is not a title"},
      {"x11:window-id=zz", "is not a window id"},
      {"x11:window-id=0", "is not a window id"},
      {"x11:pid=-4", "is not a process id"},
      {"x11:fps=0", "from 1 to 1000"},
      {"x11:fps=nan", "from 1 to 1000"},
      {"x11:wait=-1", "from 0 to 3600"},
      {"x11:display=", "is not an X display"},
      {"x11:fps", "expected key=value"},
      {"x11:window-id=0x10,pid=3", "name the window one way"},
  };
  for (const auto& [spec, expected] : cases) {
    try {
      parse_x11_capture_spec(spec);
      ADD_FAILURE() << spec << " was accepted";
    } catch (const UserError& e) {
      EXPECT_EQ(e.status(), 2) << spec;
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << spec << ": " << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << spec;
    }
  }
}

}  // namespace
}  // namespace nelf
