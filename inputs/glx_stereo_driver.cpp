// The glx-stereo driver: a quad-buffer game's eyes, or the picture of a game that draws one, as a live
// stereo source (glx_stereo_source.hpp).
// Each frame is the newest the game swapped: older ones still in the socket are skipped, as a live
// window's are, and a slot the game overwrote while it was copied is dropped and counted.
#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "core/module_path.hpp"
#include "core/printable.hpp"
#include "core/unix_socket.hpp"
#include "core/user_error.hpp"
#include "inputs/game_depth.hpp"
#include "inputs/glx_stereo_protocol.hpp"
#include "inputs/glx_stereo_source.hpp"
#include "inputs/source.hpp"
#include "inputs/stereo_layout.hpp"
#include "inputs/view_bytes.hpp"
#include "inputs/view_regions.hpp"

namespace nelf {

namespace protocol = glx_stereo;

bool is_glx_stereo_spec(std::string_view input) { return input.starts_with("glx-stereo:"); }

GlxStereoSpec parse_glx_stereo_spec(const std::string& input) {
  GlxStereoSpec spec;
  std::string_view rest = std::string_view(input).substr(std::strlen("glx-stereo:"));
  // A path may hold commas: socket= takes the rest of the spec, so it comes last.
  while (!rest.empty()) {
    const std::size_t eq = rest.find('=');
    if (eq == std::string_view::npos) throw UserError(fmt::format("{}: expected key=value (wait=, socket=)", input), 2);
    const std::string_view key = rest.substr(0, eq);
    if (key == "socket") {
      spec.socket = std::string(rest.substr(eq + 1));
      break;
    }
    const std::size_t comma = rest.find(',', eq);
    const std::string value(
        rest.substr(eq + 1, comma == std::string_view::npos ? std::string_view::npos : comma - eq - 1));
    rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
    if (key != "wait") throw UserError(fmt::format("{}: unknown key {} (wait=, socket=)", input, key), 2);
    char* end = nullptr;
    spec.wait_s = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !(spec.wait_s > 0 && spec.wait_s <= 3600))
      throw UserError(fmt::format("{}: wait= must be a time from 0 to 3600 seconds, got '{}'", input, value), 2);
  }
  if (spec.socket.empty()) throw UserError(fmt::format("{}: socket=PATH is missing", input), 2);
  return spec;
}

std::string glx_stereo_library_path() {
  return find_module("NELF_GLX_STEREO_LIBRARY", "nelf-glx-stereo.so", NELF_GLX_STEREO_INSTALLED, NELF_GLX_STEREO_BUILT)
      .string();
}

namespace drivers {
namespace {

// One message, with the descriptor it carries (the hello's shared memory), or nothing when the
// game closed the link.
struct Received {
  protocol::Message message;
  UniqueFd attached;
};

std::optional<Received> receive(int fd, bool wait) {
  Received r;
  iovec io{&r.message, sizeof r.message};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))] = {};
  msghdr header{};
  header.msg_iov = &io;
  header.msg_iovlen = 1;
  header.msg_control = control;
  header.msg_controllen = sizeof control;
  const ssize_t n = ::recvmsg(fd, &header, MSG_CMSG_CLOEXEC | (wait ? MSG_WAITALL : MSG_DONTWAIT));
  for (cmsghdr* c = CMSG_FIRSTHDR(&header); c; c = CMSG_NXTHDR(&header, c))
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_RIGHTS) {
      int attached = -1;
      std::memcpy(&attached, CMSG_DATA(c), sizeof attached);
      r.attached = UniqueFd(attached);
    }
  if (n != static_cast<ssize_t>(sizeof r.message) || r.message.magic != protocol::kMagic) return std::nullopt;
  return r;
}

// Why the frame memory a hello attached cannot be read safely, or nothing. It must hold the frames
// the hello announces and be sealed against shrinking: a read of a page the game truncated away
// would kill nelf with SIGBUS instead of failing.
std::optional<std::string> frame_memory_problem(const Received& hello) {
  const std::uint32_t w = hello.message.width, h = hello.message.height;
  if (w == 0 || h == 0 || w > protocol::kMaxSide || h > protocol::kMaxSide)
    return fmt::format("the game's interposer announces {}x{} frames (each side 1 to {})", w, h, protocol::kMaxSide);
  if (hello.attached.get() < 0) return std::string("the game's interposer attached no frame memory");
  const std::size_t needed = protocol::shared_bytes(w, h);
  struct stat status {};
  if (::fstat(hello.attached.get(), &status) != 0 || static_cast<std::uint64_t>(status.st_size) < needed)
    return fmt::format("the game's frame memory holds {} bytes where its {}x{} frames need {} (another nelf version?)",
                       static_cast<long long>(status.st_size), w, h, needed);
  const int seals = ::fcntl(hello.attached.get(), F_GET_SEALS);
  if (seals < 0 || (seals & F_SEAL_SHRINK) == 0)
    return std::string("the game's frame memory is not sealed against shrinking (another nelf version?)");
  return std::nullopt;
}

struct Unmap {
  std::size_t bytes = 0;
  void operator()(unsigned char* p) const { munmap(p, bytes); }
};

class GlxStereoSource final : public Source {
 public:
  explicit GlxStereoSource(const SourceRequest& r)
      : input_(r.input), spec_(parse_glx_stereo_spec(r.input)), swap_(r.swap_eyes), quiet_(r.quiet) {
    const UniqueFd listener = listen_on_unix_socket(spec_.socket, input_);
    struct RemoveSocket {
      std::string path;
      ~RemoveSocket() { ::unlink(path.c_str()); }
    } remove{spec_.socket};
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(spec_.wait_s);
    while (link_.get() < 0) {
      if (r.stop && r.stop->load()) throw UserError("interrupted while waiting for the game's first frame", 130);
      if (std::chrono::steady_clock::now() > until)
        throw GameDidNotSwap(
            fmt::format("{}: no OpenGL game swapped a frame in {:g} s", printable(input_), spec_.wait_s), 1);
      pollfd p{listener.get(), POLLIN, 0};
      if (::poll(&p, 1, 100) > 0) link_ = UniqueFd(::accept4(listener.get(), nullptr, nullptr, SOCK_CLOEXEC));
    }
    const timeval patience{5, 0};  // the interposer says hello as it connects
    ::setsockopt(link_.get(), SOL_SOCKET, SO_RCVTIMEO, &patience, sizeof patience);
    std::optional<Received> hello = receive(link_.get(), true);
    if (!hello || hello->message.type != protocol::MessageType::hello)
      throw UserError(fmt::format("{}: the game's interposer said something else than hello (another nelf version?)",
                                  printable(input_)),
                      1);
    if (const auto problem = frame_memory_problem(*hello))
      throw UserError(fmt::format("{}: {}", printable(input_), *problem), 1);
    picture_ = !hello->message.stereo;
    width_ = static_cast<int>(hello->message.width);
    height_ = static_cast<int>(hello->message.height);
    const std::size_t bytes = protocol::shared_bytes(hello->message.width, hello->message.height);
    void* mapped = mmap(nullptr, bytes, PROT_READ, MAP_SHARED, hello->attached.get(), 0);
    if (mapped == MAP_FAILED) throw UserError(fmt::format("{}: cannot map the game's frames", printable(input_)), 1);
    shared_ = std::unique_ptr<unsigned char, Unmap>(static_cast<unsigned char*>(mapped), Unmap{bytes});
    if (picture_) {
      // Its two views are where its layout puts them, as in a captured window.
      const LivePictureViews views = live_picture_views(input_, r.layout, r.swap_eyes, width_, height_, r.quiet);
      const LayoutDecision& decision = views.decision;
      regions_ = views.regions;
      description_ = fmt::format(
          "{}: the window of an OpenGL game (process {}), {}x{} read at each swap, two {}x{} "
          "views, layout {}{} ({}), live",
          input_, hello->message.slot, width_, height_, regions_.left.width, regions_.left.height,
          to_string(decision.layout), decision.swap_eyes ? " swapped" : "", to_string(decision.rule));
    } else {
      regions_.left = regions_.right = {0, 0, width_, height_};
      regions_.display_aspect = static_cast<double>(width_) / height_;
      if (r.layout && !r.quiet)
        fmt::print(stderr,
                   "nelf: {}: the game gives each eye on its own; --layout {} is for a game that draws one "
                   "picture\n",
                   printable(input_), to_string(*r.layout));
      description_ = fmt::format("{}: a quad-buffer OpenGL game, two {}x{} eyes{}, live", input_, width_, height_,
                                 swap_ ? " swapped" : "");
    }
    if (r.known_depth && !picture_) {
      protocol::Message want;
      want.type = protocol::MessageType::want_depth;
      depth_ = ::send(link_.get(), &want, sizeof want, MSG_NOSIGNAL) == static_cast<ssize_t>(sizeof want);
    }
    origin_ = std::chrono::steady_clock::now();
    if (!r.quiet) fmt::print(stderr, "nelf: {}\n", printable(description_));
  }

  SourceInfo info() const override {
    SourceInfo info;
    info.frame_rate = 60;  // what a game aims at; play measures the game's own period as it goes
    info.live = true;
    info.description = description_;
    info.view = {regions_.left.width, regions_.left.height, regions_.display_aspect};
    return info;
  }

  std::optional<StereoVideoFrame> next() override {
    for (;;) {
      // The newest frame the game swapped: wait for one, then take the ones already sent after it
      // (those before it are late already).
      std::optional<protocol::Message> newest;
      for (;;) {
        if (interrupted_) return std::nullopt;
        pollfd p{link_.get(), POLLIN, 0};
        if (::poll(&p, 1, newest ? 0 : 50) <= 0) {
          if (newest) break;
          continue;
        }
        std::optional<Received> r = receive(link_.get(), false);
        if (!r) {
          if (newest) break;
          return std::nullopt;  // the game ended, or its window changed size (a new link follows)
        }
        if (r->message.type == protocol::MessageType::frame && r->message.slot < protocol::kSlots) newest = r->message;
      }
      // Overwritten while copied: the game drew faster than nelf reads, and its next frame is newer
      // anyway. Not a lost frame (the play summary's "lost to decode errors"), any more than the
      // older frames passed over above: like every live source, this one shows the newest.
      if (std::optional<StereoVideoFrame> frame = copy(*newest)) {
        note_lead(frame->captured_ns - newest->swapped_ns);
        return frame;
      }
    }
  }

  void interrupt() override { interrupted_ = true; }

  // Passed on to the interposer (protocol: refresh); a message the game has no room for is dropped,
  // the next refresh says the same.
  void refresh_at(std::int64_t refresh_ns, std::int64_t period_ns) override {
    protocol::Message message;
    message.type = protocol::MessageType::refresh;
    message.refresh_ns = refresh_ns;
    message.period_ns = period_ns;
    message.lead_ns = lead_ns_.load();
    ::send(link_.get(), &message, sizeof message, MSG_NOSIGNAL | MSG_DONTWAIT);
  }

  ViewFormat negotiate(const ViewFormat& wanted) override {
    const auto& [bx, by] = wanted.block;
    const bool fits = bx >= 1 && by >= 1 && bx <= regions_.left.width && by <= regions_.left.height;
    block_ = fits ? wanted.block : std::array<int, 2>{1, 1};
    return {block_};
  }

 private:
  // How long before a refresh the game must swap a frame for nelf to have read it (refresh_at):
  // the longest of the last 16 frames' swap-to-read times, and a millisecond.
  void note_lead(std::int64_t swap_to_read_ns) {
    recent_[recent_count_++ % recent_.size()] = std::max<std::int64_t>(swap_to_read_ns, 0);
    const std::size_t n = std::min(recent_count_, recent_.size());
    lead_ns_ = *std::max_element(recent_.begin(), recent_.begin() + static_cast<std::ptrdiff_t>(n)) + 1'000'000;
  }

  std::optional<StereoVideoFrame> copy(const protocol::Message& message) {
    const auto w = static_cast<std::uint32_t>(width_), h = static_cast<std::uint32_t>(height_);
    unsigned char* slot = shared_.get() + message.slot * protocol::slot_stride(w, h);
    auto* head = reinterpret_cast<protocol::SlotHeader*>(slot);
    const std::uint64_t before = std::atomic_ref<std::uint64_t>(head->sequence).load(std::memory_order_acquire);
    if (before % 2 != 0 || head->frame != message.frame) return std::nullopt;
    const std::size_t eye = protocol::eye_bytes(w, h);
    const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(w) * 4;
    // GL's rows are bottom-up: a region's top row is its last one. A picture's views are regions
    // of its one image; a quad-buffer game's eyes each a whole image of their own.
    const ByteOrder order = head->bgrx == 1 ? ByteOrder::bgrx : ByteOrder::rgba;
    const auto view = [&](int i, const PixelRect& region) {
      const unsigned char* rows = slot + protocol::kSlotHeader + static_cast<std::size_t>(i) * eye;
      return rgba8_block_means(rows + (height_ - 1 - region.y) * stride + static_cast<std::ptrdiff_t>(region.x) * 4,
                               -stride, region.width, region.height, block_, order);
    };
    StereoVideoFrame frame;
    frame.bits = 8;
    if (picture_) {
      frame.left = view(0, regions_.left);
      frame.right = view(0, regions_.right);
    } else {
      frame.left = view(swap_ ? 1 : 0, regions_.left);
      frame.right = view(swap_ ? 0 : 1, regions_.right);
    }
    if (depth_ && head->depth == 1) frame.disparity = disparity(slot);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (std::atomic_ref<std::uint64_t>(head->sequence).load(std::memory_order_relaxed) != before) return std::nullopt;
    frame.width = regions_.left.width;
    frame.height = regions_.left.height;
    frame.block = block_;
    frame.aspect = regions_.display_aspect;
    const auto now = std::chrono::steady_clock::now();
    frame.pts_s = std::chrono::duration<double>(now - origin_).count();
    frame.captured_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch()).count();
    return frame;
  }

  // Both eyes' disparity from their depth buffers in `slot`; null (and said once) when the buffers
  // cannot give it: the estimate from the views stands in then (`--depth auto`).
  std::shared_ptr<const StereoDisparity> disparity(const unsigned char* slot) {
    const auto w = static_cast<std::uint32_t>(width_), h = static_cast<std::uint32_t>(height_);
    const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(w) * 4;
    GameEyes eyes;
    eyes.width = width_;
    eyes.height = height_;
    for (int i = 0; i < 2; ++i) {
      const int from = swap_ ? 1 - i : i;
      // GL's rows are bottom-up: the top row is the last one.
      eyes.colour[i] = {slot + protocol::kSlotHeader + static_cast<std::size_t>(from) * protocol::eye_bytes(w, h) +
                            (height_ - 1) * stride,
                        -stride};
      const auto* depth = reinterpret_cast<const float*>(slot + protocol::depth_offset(w, h, from));
      eyes.depth[i] = {depth + static_cast<std::ptrdiff_t>(height_ - 1) * width_, -static_cast<std::ptrdiff_t>(width_)};
    }
    std::shared_ptr<const StereoDisparity> out = relation_.disparity(eyes, block_);
    const GameDepthGap gap = relation_.gap();
    // Each reason once, however the frames alternate between them.
    bool& said = gap == GameDepthGap::empty_buffers ? said_empty_ : said_too_few_;
    if (!out && !quiet_ && !said) {
      said = true;
      fmt::print(stderr, "nelf: {}: {}; its depth is estimated from the views meanwhile\n", printable(input_),
                 gap == GameDepthGap::empty_buffers
                     ? "the game's depth buffers are empty (it draws without depth, or into framebuffers of its own)"
                     : "too few points of the game's views match yet to relate its depth buffers to them");
    }
    if (out && !said_depth_ && !quiet_) {
      said_depth_ = true;
      const DepthToDisparity line = *relation_.relation();
      fmt::print(stderr,
                 "nelf: {}: depth from the game's depth buffers (disparity {:.2f} px + {:.2f} px x depth value)\n",
                 printable(input_), line.offset, line.slope);
    }
    return out;
  }

  std::string input_;
  GlxStereoSpec spec_;
  bool swap_ = false;
  bool quiet_ = false;
  bool depth_ = false;  // the interposer was asked for the depth buffers
  GameDepthRelation relation_;
  bool said_empty_ = false, said_too_few_ = false;
  bool said_depth_ = false;
  UniqueFd link_;
  std::unique_ptr<unsigned char, Unmap> shared_;
  int width_ = 0, height_ = 0;  // each eye's, or the picture's
  bool picture_ = false;        // a game that draws one picture: its window's, split by its layout
  ViewRegions regions_;         // where the views are (a quad-buffer game's: each eye whole)
  std::chrono::steady_clock::time_point origin_;
  std::string description_;
  std::atomic<bool> interrupted_{false};
  std::array<int, 2> block_{1, 1};
  std::array<std::int64_t, 16> recent_{};  // note_lead: the last frames' swap-to-read times
  std::size_t recent_count_ = 0;
  std::atomic<std::int64_t> lead_ns_{0};  // written by next()'s thread, read by refresh_at()'s
};

}  // namespace

bool accepts_glx_stereo(const SourceRequest& request) { return is_glx_stereo_spec(request.input); }

std::unique_ptr<Source> open_glx_stereo(const SourceRequest& request) {
  if (request.layout == StereoLayout::alt || request.layout == StereoLayout::pair)
    throw UserError(fmt::format("layout {} needs a file; a game's picture shows both views in one frame",
                                to_string(*request.layout)),
                    2);
  return std::make_unique<GlxStereoSource>(request);
}

}  // namespace drivers
}  // namespace nelf
