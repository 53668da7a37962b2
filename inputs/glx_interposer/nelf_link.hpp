#pragma once
// The interposer's link to nelf (inputs/glx_stereo_protocol.hpp): a stream socket, the shared slots
// the eyes are written into, and what nelf says back (the depth it wants, its refreshes).
#include <cstddef>
#include <cstdint>
#include <ctime>

#include "inputs/glx_stereo_protocol.hpp"

namespace nelf::glx_interposer {

namespace protocol = nelf::glx_stereo;

inline std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

// The link to nelf: a stream socket and the shared slots the eyes are written into.
class NelfLink {
 public:
  NelfLink() = default;
  NelfLink(const NelfLink&) = delete;  // it owns the socket and the mapping
  NelfLink& operator=(const NelfLink&) = delete;
  ~NelfLink() { close(); }

  bool connected() const { return fd_ >= 0; }

  // Connects and says hello; with a size, the link gets shared memory for eyes of width × height
  // (stereo) or for the window's picture of that size (mono). At most twice a second, so that a
  // game without nelf listening loses nothing.
  bool connect(bool stereo, std::uint32_t width, std::uint32_t height);

  // The slot for `frame`, marked as being written; nullptr when the link has no shared memory.
  unsigned char* begin_slot(std::uint64_t frame);

  void end_slot(unsigned char* slot, std::uint64_t frame, std::int64_t swapped_ns);

  // What nelf said since the last call, read without waiting: whether it wants the depth buffers
  // (it composites with the game's depth; once asked, always), and its newest refresh.
  void read_messages();
  bool depth_wanted() const { return depth_wanted_; }
  bool linked_for_frames() const { return fd_ >= 0 && shared_ != nullptr; }

  // When a swap made at `now` returns (protocol::vsync_returns_ns); 0: at once.
  std::int64_t swap_returns_ns(std::int64_t now, int interval, std::int64_t game_ns,
                               std::int64_t last_return_ns) const {
    return protocol::vsync_returns_ns({refresh_ns_, period_ns_, lead_ns_}, now, interval, game_ns, last_return_ns);
  }

  void close();

 private:
  // Never blocks the game: a message nelf has no room for is dropped (nelf reads the newest frame
  // anyway); a link nelf closed is closed here too.
  bool send(const protocol::Message& message, int attached_fd);

  int fd_ = -1;
  bool depth_wanted_ = false;
  std::int64_t refresh_ns_ = 0, period_ns_ = 0;  // nelf's newest refresh, and its period (0: none said)
  std::int64_t lead_ns_ = 0;
  unsigned char* shared_ = nullptr;
  std::size_t bytes_ = 0;
  std::uint32_t width_ = 0, height_ = 0;
  std::int64_t last_try_ns_ = -1'000'000'000'000LL;
};

}  // namespace nelf::glx_interposer
