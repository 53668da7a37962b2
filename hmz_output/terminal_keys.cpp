#include "hmz_output/terminal_keys.hpp"

#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <optional>

namespace nelf {
namespace {

using Named = KeyPress::Named;

// The key of a single byte below 0x80, if it is one.
std::optional<KeyPress> single_byte_key(unsigned char b) {
  switch (b) {
    case ' ':
      return KeyPress::of(Named::space);
    case '\r':
    case '\n':
      return KeyPress::of(Named::enter);
    case '\t':
      return KeyPress::of(Named::tab);
    case 0x7f:
    case 0x08:
      return KeyPress::of(Named::backspace);
    default:
      break;
  }
  if (b >= 0x21 && b <= 0x7e) return KeyPress::of(static_cast<char32_t>(b));
  if (b >= 0x01 && b <= 0x1a) {  // Ctrl+A .. Ctrl+Z (the ones not named above)
    KeyPress k = KeyPress::of(static_cast<char32_t>('a' + b - 1));
    k.ctrl = true;
    return k;
  }
  return std::nullopt;
}

// Length of the UTF-8 sequence a lead byte starts (0: not a lead byte).
int utf8_length(unsigned char b) {
  if (b >= 0xc2 && b <= 0xdf) return 2;
  if (b >= 0xe0 && b <= 0xef) return 3;
  if (b >= 0xf0 && b <= 0xf4) return 4;
  return 0;
}

// The xterm modifier parameter (1 + bits: 1 shift, 2 alt, 4 ctrl) applied to a key.
KeyPress with_modifier(KeyPress k, int parameter) {
  if (parameter > 1) {
    const int bits = parameter - 1;
    k.shift = (bits & 1) != 0;
    k.alt = (bits & 2) != 0;
    k.ctrl = (bits & 4) != 0;
  }
  return k;
}

std::optional<Named> arrow(char final_byte) {
  switch (final_byte) {
    case 'A':
      return Named::up;
    case 'B':
      return Named::down;
    case 'C':
      return Named::right;
    case 'D':
      return Named::left;
    default:
      return std::nullopt;
  }
}

// The state RawTerminal leaves for restore_terminal_from_signal(): written before `armed` is set,
// read only while it is.
termios signal_saved_settings{};
int signal_saved_fd = -1;
volatile std::sig_atomic_t signal_armed = 0;

}  // namespace

std::vector<KeyPress> TerminalKeyParser::feed(std::string_view input) {
  std::string bytes = std::move(pending_);
  pending_.clear();
  bytes.append(input);
  std::vector<KeyPress> keys;
  const std::size_t n = bytes.size();
  std::size_t i = 0;
  const auto at = [&](std::size_t k) { return static_cast<unsigned char>(bytes[k]); };
  while (i < n) {
    const unsigned char b = at(i);
    if (b == 0x1b) {
      if (i + 1 == n) {  // a lone ESC at the end of a read is the Esc key
        keys.push_back(KeyPress::of(Named::escape));
        ++i;
        continue;
      }
      const unsigned char next = at(i + 1);
      if (next == '[') {  // CSI: parameters (digits, ';') then one final byte 0x40..0x7e
        std::size_t j = i + 2;
        while (j < n && at(j) >= 0x20 && at(j) <= 0x3f) ++j;
        if (j == n) {
          pending_ = bytes.substr(i);
          break;
        }
        const char final_byte = bytes[j];
        std::vector<int> params;
        int value = 0;
        bool digits = false;
        for (std::size_t k = i + 2; k < j; ++k) {
          if (bytes[k] >= '0' && bytes[k] <= '9') {
            value = std::min(value * 10 + (bytes[k] - '0'), 10000);
            digits = true;
          } else if (bytes[k] == ';') {
            params.push_back(digits ? value : 1);
            value = 0;
            digits = false;
          }
        }
        params.push_back(digits ? value : 1);
        const int modifier = params.size() > 1 ? params[1] : 1;
        if (const auto a = arrow(final_byte)) {
          keys.push_back(with_modifier(KeyPress::of(*a), modifier));
        } else if (final_byte == '~' && (params[0] == 5 || params[0] == 6)) {
          keys.push_back(with_modifier(KeyPress::of(params[0] == 5 ? Named::page_up : Named::page_down), modifier));
        }  // other sequences (Home, Delete, F-keys, ...) mean nothing here: skipped whole
        i = j + 1;
        continue;
      }
      if (next == 'O') {  // SS3: arrows in application cursor mode
        if (i + 2 == n) {
          pending_ = bytes.substr(i);
          break;
        }
        if (const auto a = arrow(bytes[i + 2])) keys.push_back(KeyPress::of(*a));
        i += 3;
        continue;
      }
      if (next >= 0x20 && next <= 0x7e) {  // Alt+key arrives as ESC key
        KeyPress k = *single_byte_key(next);
        k.alt = true;
        keys.push_back(k);
        i += 2;
        continue;
      }
      keys.push_back(KeyPress::of(Named::escape));  // ESC followed by ESC or a control byte
      ++i;
      continue;
    }
    if (b < 0x80) {
      if (const auto k = single_byte_key(b)) keys.push_back(*k);
      ++i;
      continue;
    }
    const int length = utf8_length(b);
    if (length == 0) {  // a stray continuation or invalid byte
      ++i;
      continue;
    }
    if (i + static_cast<std::size_t>(length) > n) {
      pending_ = bytes.substr(i);
      break;
    }
    char32_t c = b & (length == 2 ? 0x1f : length == 3 ? 0x0f : 0x07);
    bool valid = true;
    for (int k = 1; k < length; ++k) {
      const unsigned char cont = at(i + static_cast<std::size_t>(k));
      if ((cont & 0xc0) != 0x80) {
        valid = false;
        break;
      }
      c = (c << 6) | (cont & 0x3f);
    }
    if (!valid) {
      ++i;
      continue;
    }
    keys.push_back(KeyPress::of(c));
    i += static_cast<std::size_t>(length);
  }
  return keys;
}

RawTerminal::RawTerminal(int fd) : fd_(fd) {
  if (!isatty(fd_) || tcgetattr(fd_, &saved_) != 0) return;
  termios raw = saved_;
  raw.c_lflag &= static_cast<tcflag_t>(~(ICANON | ECHO | ECHONL | IEXTEN));
  raw.c_iflag &= static_cast<tcflag_t>(~(IXON | ICRNL | INLCR | IGNCR));
  raw.c_cc[VMIN] = 0;  // read() returns at once with what is there
  raw.c_cc[VTIME] = 0;
  raw.c_cc[VSUSP] = _POSIX_VDISABLE;
  if (tcsetattr(fd_, TCSANOW, &raw) != 0) return;
  active_ = true;
  if (!signal_armed) {  // the first (outermost) raw terminal is the one a signal restores
    signal_saved_settings = saved_;
    signal_saved_fd = fd_;
    signal_armed = 1;
  }
}

RawTerminal::~RawTerminal() {
  if (!active_) return;
  if (signal_armed && signal_saved_fd == fd_) signal_armed = 0;
  tcsetattr(fd_, TCSANOW, &saved_);
}

void restore_terminal_from_signal() noexcept {
  if (signal_armed) tcsetattr(signal_saved_fd, TCSANOW, &signal_saved_settings);
}

TerminalKeys::TerminalKeys(int fd) : fd_(fd), raw_(fd) {}

std::vector<KeyPress> TerminalKeys::read_available() {
  std::vector<KeyPress> keys;
  if (!raw_.active() || hung_up_) return keys;
  for (;;) {
    pollfd p{fd_, POLLIN, 0};
    const int ready = poll(&p, 1, 0);
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) break;
    if (p.revents & (POLLHUP | POLLERR | POLLNVAL)) {
      hung_up_ = true;
      break;
    }
    char buffer[256];
    const ssize_t got = read(fd_, buffer, sizeof buffer);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) {  // readable but nothing to read: end of file
      hung_up_ = true;
      break;
    }
    for (const KeyPress& k : parser_.feed(std::string_view(buffer, static_cast<std::size_t>(got)))) keys.push_back(k);
  }
  return keys;
}

}  // namespace nelf
