#include "inputs/glx_interposer/nelf_link.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace nelf::glx_interposer {

bool NelfLink::connect(bool stereo, std::uint32_t width, std::uint32_t height) {
  const char* path = std::getenv(protocol::kSocketVariable);
  if (!path || !*path || std::strlen(path) >= sizeof(sockaddr_un::sun_path)) return false;
  const std::int64_t now = monotonic_ns();
  if (now - last_try_ns_ < 500'000'000) return false;
  last_try_ns_ = now;
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strcpy(address.sun_path, path);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return false;
  }
  fd_ = fd;
  protocol::Message hello;
  hello.type = protocol::MessageType::hello;
  hello.stereo = stereo ? 1 : 0;
  hello.width = width;
  hello.height = height;
  hello.slot = static_cast<std::uint32_t>(::getpid());
  int memory = -1;
  if (width > 0 && height > 0) {
    bytes_ = protocol::shared_bytes(width, height);
    memory = memfd_create("nelf-glx-stereo", MFD_CLOEXEC | MFD_ALLOW_SEALING);
    if (memory < 0 || ftruncate(memory, static_cast<off_t>(bytes_)) != 0 ||
        fcntl(memory, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL) != 0) {
      if (memory >= 0) ::close(memory);
      close();
      return false;
    }
    void* mapped = mmap(nullptr, bytes_, PROT_READ | PROT_WRITE, MAP_SHARED, memory, 0);
    if (mapped == MAP_FAILED) {
      ::close(memory);
      close();
      return false;
    }
    shared_ = static_cast<unsigned char*>(mapped);
    width_ = width;
    height_ = height;
  }
  const bool sent = send(hello, memory);
  if (memory >= 0) ::close(memory);  // nelf holds its own descriptor now
  if (!sent) close();
  return sent;
}

unsigned char* NelfLink::begin_slot(std::uint64_t frame) {
  if (!shared_) return nullptr;
  unsigned char* slot = shared_ + (frame % protocol::kSlots) * protocol::slot_stride(width_, height_);
  auto* head = reinterpret_cast<protocol::SlotHeader*>(slot);
  std::atomic_ref<std::uint64_t>(head->sequence).fetch_add(1, std::memory_order_acq_rel);  // odd: writing
  return slot;
}

void NelfLink::end_slot(unsigned char* slot, std::uint64_t frame, std::int64_t swapped_ns) {
  auto* head = reinterpret_cast<protocol::SlotHeader*>(slot);
  head->frame = frame;
  head->swapped_ns = swapped_ns;
  std::atomic_ref<std::uint64_t>(head->sequence).fetch_add(1, std::memory_order_release);  // even: done
  protocol::Message message;
  message.type = protocol::MessageType::frame;
  message.slot = static_cast<std::uint32_t>(frame % protocol::kSlots);
  message.frame = frame;
  message.swapped_ns = swapped_ns;
  send(message, -1);
}

void NelfLink::read_messages() {
  protocol::Message message;
  while (fd_ >= 0 && ::recv(fd_, &message, sizeof message, MSG_DONTWAIT) == static_cast<ssize_t>(sizeof message)) {
    if (message.magic != protocol::kMagic) continue;
    if (message.type == protocol::MessageType::want_depth) depth_wanted_ = true;
    if (message.type == protocol::MessageType::refresh && message.period_ns > 0) {
      refresh_ns_ = message.refresh_ns;
      period_ns_ = message.period_ns;
      lead_ns_ = message.lead_ns;
    }
  }
}

void NelfLink::close() {
  depth_wanted_ = false;
  period_ns_ = 0;
  if (shared_) munmap(shared_, bytes_);
  shared_ = nullptr;
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool NelfLink::send(const protocol::Message& message, int attached_fd) {
  const int flags = MSG_NOSIGNAL | (attached_fd >= 0 ? 0 : MSG_DONTWAIT);
  const ssize_t n = protocol::send_message(fd_, message, attached_fd, flags);
  if (n == static_cast<ssize_t>(sizeof message)) return true;
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return true;
  close();
  return false;
}

}  // namespace nelf::glx_interposer
