#pragma once
// What the quad-buffer interposer (inputs/glx_interposer/, loaded into a game) and nelf's
// `glx-stereo:` source say to each other over a Unix stream socket, and how the eyes lie in the
// shared memory it passes. Plain C++ without nelf's other headers: the interposer includes it too.
//
// The game's side connects to $NELF_GLX_STEREO_SOCKET at its first buffer swap and sends a hello
// with a memfd of kSlots frame slots attached (SCM_RIGHTS; sealed at its size, so that nelf's reads
// can never fault on pages the game took away: nelf refuses a memfd that could shrink): stereo (it
// drew into GL_BACK_RIGHT, so the interposer keeps each eye's back buffer; a slot holds both eyes),
// or mono, for a game that draws one picture (after a few swaps without a right buffer; a slot
// holds the window's picture where a left eye goes, and nelf splits it by its layout). A new
// window, or a new size, is a new link. Then one frame message per swap, naming the slot just
// written. nelf may answer once with want_depth (it composites with the game's depth, `--depth
// auto`): from then on each slot also holds both eyes' depth buffers. While nelf shows the frames
// on a display that refreshes at a fixed rate (play, run) it sends a refresh message at each
// refresh: its time, the period, and how long before a refresh a swapped frame must be to be in it
// (nelf's read of the last frames, and a margin). A game that asks for a swap interval of N
// (glXSwapInterval*, 1 when it never asks, as GLX has it) then has each buffer swap return so that
// its next frame, drawn in the time its last one took, is swapped that long before a refresh, N
// refreshes on: it is shown at the first refresh it can be, as vsync does on a monitor, and no
// later; while nelf says no refresh, at 60 Hz (vsync_returns_ns). The slots are written in turn and
// guarded by a sequence number (odd while written), so that a reader that fell behind notices a
// slot overwritten under it instead of showing a torn frame; the game never waits for nelf.
#include <sys/socket.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace nelf::glx_stereo {

inline constexpr std::uint32_t kMagic = 0x4e4c4636;  // "NLF6"
// The largest eye (or picture) side a hello may give, in pixels: GL's usual largest texture, and a
// bound that keeps the shared memory's size well within size_t.
inline constexpr std::uint32_t kMaxSide = 16384;
inline constexpr int kSlots = 3;
inline constexpr const char* kSocketVariable = "NELF_GLX_STEREO_SOCKET";

enum class MessageType : std::uint32_t { hello = 1, frame = 2, want_depth = 3, refresh = 4 };

struct Message {
  std::uint32_t magic = kMagic;
  MessageType type = MessageType::hello;
  std::uint32_t stereo = 0;  // hello: 1 when the game draws both eyes
  std::uint32_t width = 0;   // hello: each eye's size in pixels
  std::uint32_t height = 0;
  std::uint32_t slot = 0;       // frame: the slot just written; hello: the game's process id
  std::uint64_t frame = 0;      // frame: the game's swap count, from 0
  std::int64_t swapped_ns = 0;  // frame: CLOCK_MONOTONIC when the game asked to swap
  std::int64_t refresh_ns = 0;  // refresh: CLOCK_MONOTONIC when one of nelf's refreshes began
  std::int64_t period_ns = 0;   // refresh: the time from one to the next
  std::int64_t lead_ns = 0;     // refresh: a frame swapped this long before a refresh is shown in it
};
static_assert(sizeof(Message) == 64);

// The head of each slot; the left eye's RGBA (or, when `bgrx` is 1, BGRX) rows follow at
// kSlotHeader, then the right eye's, each width × height × 4 bytes, then, when `depth` is 1, the
// left and the right eye's depth buffers as floats (0..1) of width × height × 4 bytes each; rows
// bottom-up (as glReadPixels gives them).
struct SlotHeader {
  std::uint64_t sequence;  // odd while the game writes the slot; atomic_ref'd on both sides
  std::uint64_t frame;
  std::int64_t swapped_ns;
  std::uint32_t depth;  // 1: the depth buffers follow the colour
  std::uint32_t bgrx;   // 1: the colour bytes are B, G, R and one not read (a window's back buffer, as stored)
};
inline constexpr std::size_t kSlotHeader = 64;

inline std::size_t eye_bytes(std::uint32_t width, std::uint32_t height) {
  return static_cast<std::size_t>(width) * height * 4;
}
// Where eye `i`'s depth buffer starts in a slot.
inline std::size_t depth_offset(std::uint32_t width, std::uint32_t height, int i) {
  return kSlotHeader + (2 + static_cast<std::size_t>(i)) * eye_bytes(width, height);
}
// Slots start on page boundaries, with room for the depth buffers (pages that are never written
// cost no memory).
inline std::size_t slot_stride(std::uint32_t width, std::uint32_t height) {
  const std::size_t bytes = kSlotHeader + 4 * eye_bytes(width, height);
  return (bytes + 4095) / 4096 * 4096;
}
inline std::size_t shared_bytes(std::uint32_t width, std::uint32_t height) {
  return kSlots * slot_stride(width, height);
}

// Sends `message` on `link` with `attached` (a descriptor, or < 0 for none) as SCM_RIGHTS, as the
// hello's frame memory travels; sendmsg's result.
inline ssize_t send_message(int link, const Message& message, int attached, int flags) {
  iovec io{const_cast<Message*>(&message), sizeof message};
  msghdr header{};
  header.msg_iov = &io;
  header.msg_iovlen = 1;
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))] = {};
  if (attached >= 0) {
    header.msg_control = control;
    header.msg_controllen = sizeof control;
    cmsghdr* c = CMSG_FIRSTHDR(&header);
    c->cmsg_level = SOL_SOCKET;
    c->cmsg_type = SCM_RIGHTS;
    c->cmsg_len = CMSG_LEN(sizeof(int));
    std::memcpy(CMSG_DATA(c), &attached, sizeof(int));
  }
  return ::sendmsg(link, &header, flags);
}

// nelf's refreshes as its refresh messages said them (period 0: none said).
struct RefreshTiming {
  std::int64_t refresh_ns = 0, period_ns = 0, lead_ns = 0;
};

// When a game's buffer swap made at `now` returns, with swap interval `interval`, for a game that
// took `game_ns` to draw its last frame: so that its next frame is swapped `lead_ns` before the
// first refresh it can reach, interval − 1 refreshes on. 0 (at once) for interval 0, or when no
// refresh was said in the half second before `now` (convert, or a display that stopped).
inline std::int64_t swap_returns_ns(const RefreshTiming& t, std::int64_t now, int interval, std::int64_t game_ns) {
  if (interval <= 0 || t.period_ns <= 0 || now - t.refresh_ns > 500'000'000) return 0;
  const std::int64_t early =
      std::clamp<std::int64_t>(t.lead_ns, 0, t.period_ns) + std::clamp<std::int64_t>(game_ns, 0, t.period_ns);
  const std::int64_t since = now + early - t.refresh_ns;  // the refresh reached: the first at or after now + early
  const std::int64_t refreshes = since <= 0 ? 0 : (since + t.period_ns - 1) / t.period_ns;
  return t.refresh_ns + (refreshes + interval - 1) * t.period_ns - early;
}

// The period a vsync game is paced at while nelf says no refresh (play starting; convert has none):
// a 60 Hz display's.
inline constexpr std::int64_t kUntoldPeriodNs = 16'666'667;

// When the interposer returns the swap: swap_returns_ns while nelf says its refreshes; otherwise
// `interval` untold periods after the last swap returned (`last_return_ns`, 0: none yet, at once);
// 0 (at once) for interval 0.
inline std::int64_t vsync_returns_ns(const RefreshTiming& t, std::int64_t now, int interval, std::int64_t game_ns,
                                     std::int64_t last_return_ns) {
  if (interval <= 0) return 0;
  if (const std::int64_t at = swap_returns_ns(t, now, interval, game_ns)) return at;
  return last_return_ns != 0 ? std::max(now, last_return_ns + interval * kUntoldPeriodNs) : 0;
}

}  // namespace nelf::glx_stereo
