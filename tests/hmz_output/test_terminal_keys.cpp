// Terminal keys for --output kms: the byte parser, and raw mode on a pseudo-terminal (set while the
// guard lives, restored after it and by the signal-safe path).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <stdlib.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "hmz_output/terminal_keys.hpp"

namespace nelf {
namespace {

using Named = KeyPress::Named;

std::vector<KeyPress> parse(std::string_view bytes) {
  TerminalKeyParser parser;
  return parser.feed(bytes);
}

TEST(TerminalKeys, PlayerKeys) {
  const auto keys = parse(" +-[]scfq");
  ASSERT_EQ(keys.size(), 9u);
  EXPECT_TRUE(keys[0].is(Named::space));
  EXPECT_TRUE(keys[1].is(U'+'));
  EXPECT_TRUE(keys[2].is(U'-'));
  EXPECT_TRUE(keys[3].is(U'['));
  EXPECT_TRUE(keys[4].is(U']'));
  EXPECT_TRUE(keys[5].is(U's'));
  EXPECT_TRUE(keys[6].is(U'c'));
  EXPECT_TRUE(keys[7].is(U'f'));
  EXPECT_TRUE(keys[8].is(U'q'));
  for (const auto& k : keys) EXPECT_FALSE(k.ctrl || k.alt || k.shift);
}

TEST(TerminalKeys, ArrowsAndPagesInBothCursorModes) {
  const auto keys = parse("\x1b[A\x1b[B\x1b[C\x1b[D\x1bOA\x1bOD\x1b[5~\x1b[6~");
  ASSERT_EQ(keys.size(), 8u);
  EXPECT_TRUE(keys[0].is(Named::up));
  EXPECT_TRUE(keys[1].is(Named::down));
  EXPECT_TRUE(keys[2].is(Named::right));
  EXPECT_TRUE(keys[3].is(Named::left));
  EXPECT_TRUE(keys[4].is(Named::up));
  EXPECT_TRUE(keys[5].is(Named::left));
  EXPECT_TRUE(keys[6].is(Named::page_up));
  EXPECT_TRUE(keys[7].is(Named::page_down));
}

TEST(TerminalKeys, Modifiers) {
  const auto keys = parse("\x1b[1;5C\x1b[1;2A\x1b[1;3D\x1bq\x03");
  ASSERT_EQ(keys.size(), 5u);
  EXPECT_TRUE(keys[0].is(Named::right));
  EXPECT_TRUE(keys[0].ctrl);
  EXPECT_FALSE(keys[0].shift);
  EXPECT_TRUE(keys[1].is(Named::up));
  EXPECT_TRUE(keys[1].shift);
  EXPECT_TRUE(keys[2].is(Named::left));
  EXPECT_TRUE(keys[2].alt);
  EXPECT_TRUE(keys[3].is(U'q'));  // Alt+q
  EXPECT_TRUE(keys[3].alt);
  EXPECT_TRUE(keys[4].is(U'c'));  // Ctrl+C as a byte (when ISIG is off)
  EXPECT_TRUE(keys[4].ctrl);
}

TEST(TerminalKeys, EscapeAloneAndOtherNamedKeys) {
  auto keys = parse("\x1b");
  ASSERT_EQ(keys.size(), 1u);
  EXPECT_TRUE(keys[0].is(Named::escape));
  keys = parse("\x1b\x1b[A");
  ASSERT_EQ(keys.size(), 2u);
  EXPECT_TRUE(keys[0].is(Named::escape));
  EXPECT_TRUE(keys[1].is(Named::up));
  keys = parse("\r\t\x7f");
  ASSERT_EQ(keys.size(), 3u);
  EXPECT_TRUE(keys[0].is(Named::enter));
  EXPECT_TRUE(keys[1].is(Named::tab));
  EXPECT_TRUE(keys[2].is(Named::backspace));
}

TEST(TerminalKeys, UnknownSequencesAreSkippedWhole) {
  const auto keys = parse("\x1b[3~\x1b[15~\x1b[Hq");  // Delete, F5, Home
  ASSERT_EQ(keys.size(), 1u);
  EXPECT_TRUE(keys[0].is(U'q'));
}

TEST(TerminalKeys, SequencesSplitAcrossReads) {
  TerminalKeyParser parser;
  EXPECT_TRUE(parser.feed("\x1b[").empty());
  EXPECT_TRUE(parser.pending());
  EXPECT_TRUE(parser.feed("5").empty());
  auto keys = parser.feed("~x");
  ASSERT_EQ(keys.size(), 2u);
  EXPECT_TRUE(keys[0].is(Named::page_up));
  EXPECT_TRUE(keys[1].is(U'x'));
  EXPECT_FALSE(parser.pending());
  EXPECT_TRUE(parser.feed("\x1bO").empty());
  keys = parser.feed("B");
  ASSERT_EQ(keys.size(), 1u);
  EXPECT_TRUE(keys[0].is(Named::down));
  // UTF-8 split in the middle of a character.
  EXPECT_TRUE(parser.feed("\xc3").empty());
  keys = parser.feed("\xa9");
  ASSERT_EQ(keys.size(), 1u);
  EXPECT_TRUE(keys[0].is(U'\u00e9'));
}

TEST(TerminalKeys, Utf8AndInvalidBytes) {
  const auto keys = parse(
      "\xe2\x82\xac\x80\xff"
      "a");
  ASSERT_EQ(keys.size(), 2u);
  EXPECT_TRUE(keys[0].is(U'\u20ac'));
  EXPECT_TRUE(keys[1].is(U'a'));
}

// A pseudo-terminal pair: `master` writes what the user types, `slave` is the program's terminal.
struct Pty {
  int master = -1;
  int slave = -1;
  Pty() {
    master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) return;
    slave = open(ptsname(master), O_RDWR | O_NOCTTY);
  }
  ~Pty() {
    if (slave >= 0) close(slave);
    if (master >= 0) close(master);
  }
  termios settings() const {
    termios t{};
    tcgetattr(slave, &t);
    return t;
  }
};

TEST(TerminalKeys, RawModeIsRestoredByTheGuard) {
  Pty pty;
  ASSERT_GE(pty.slave, 0) << "no pseudo-terminal available";
  const termios before = pty.settings();
  ASSERT_TRUE(before.c_lflag & ICANON);
  ASSERT_TRUE(before.c_lflag & ECHO);
  {
    RawTerminal raw(pty.slave);
    ASSERT_TRUE(raw.active());
    const termios during = pty.settings();
    EXPECT_FALSE(during.c_lflag & ICANON);
    EXPECT_FALSE(during.c_lflag & ECHO);
    EXPECT_TRUE(during.c_lflag & ISIG);  // Ctrl+C still signals
    EXPECT_EQ(during.c_cc[VMIN], 0);
  }
  const termios after = pty.settings();
  EXPECT_EQ(after.c_lflag, before.c_lflag);
  EXPECT_EQ(after.c_iflag, before.c_iflag);
  EXPECT_EQ(after.c_cc[VMIN], before.c_cc[VMIN]);
  EXPECT_EQ(after.c_cc[VSUSP], before.c_cc[VSUSP]);
}

TEST(TerminalKeys, SignalPathRestoresWhileTheGuardLives) {
  Pty pty;
  ASSERT_GE(pty.slave, 0) << "no pseudo-terminal available";
  const termios before = pty.settings();
  RawTerminal raw(pty.slave);
  ASSERT_TRUE(raw.active());
  ASSERT_FALSE(pty.settings().c_lflag & ICANON);
  restore_terminal_from_signal();  // what a handler that exits at once calls
  EXPECT_EQ(pty.settings().c_lflag, before.c_lflag);
}

TEST(TerminalKeys, SignalPathIsDisarmedOnceTheGuardIsGone) {
  Pty pty;
  ASSERT_GE(pty.slave, 0) << "no pseudo-terminal available";
  { RawTerminal raw(pty.slave); }
  termios changed = pty.settings();
  changed.c_lflag &= static_cast<tcflag_t>(~ECHO);
  ASSERT_EQ(tcsetattr(pty.slave, TCSANOW, &changed), 0);
  restore_terminal_from_signal();  // must not bring back settings saved by a guard that is gone
  EXPECT_FALSE(pty.settings().c_lflag & ECHO);
}

TEST(TerminalKeys, NotATerminalReadsNothing) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  ASSERT_EQ(write(fds[1], "q", 1), 1);
  {
    TerminalKeys keys(fds[0]);
    EXPECT_FALSE(keys.active());
    EXPECT_TRUE(keys.read_available().empty());
  }
  close(fds[0]);
  close(fds[1]);
}

TEST(TerminalKeys, ReadsTypedKeysWithoutBlocking) {
  Pty pty;
  ASSERT_GE(pty.slave, 0) << "no pseudo-terminal available";
  TerminalKeys keys(pty.slave);
  ASSERT_TRUE(keys.active());
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(keys.read_available().empty());  // nothing typed: returns at once
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(200));

  const std::string typed = "q\x1b[A ";
  ASSERT_EQ(write(pty.master, typed.data(), typed.size()), static_cast<ssize_t>(typed.size()));
  std::vector<KeyPress> got;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (got.size() < 3 && std::chrono::steady_clock::now() < deadline) {
    for (const auto& k : keys.read_available()) got.push_back(k);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(got.size(), 3u);
  EXPECT_TRUE(got[0].is(U'q'));
  EXPECT_TRUE(got[1].is(Named::up));
  EXPECT_TRUE(got[2].is(Named::space));
  EXPECT_FALSE(keys.hung_up());
}

}  // namespace
}  // namespace nelf
