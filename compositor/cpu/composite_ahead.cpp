#include "compositor/cpu/composite_ahead.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>

#include "compositor/overlays/calibration_overlay.hpp"
#include "optics/depth.hpp"

namespace nelf {

CompositeAhead::Packed::Packed(CompositeAhead* owner, std::unique_ptr<Bytes> bytes)
    : owner_(owner), bytes_(std::move(bytes)) {}
CompositeAhead::Packed::~Packed() {
  if (owner_ && bytes_) owner_->recycle(std::move(bytes_));
}
const std::uint8_t* CompositeAhead::Packed::data() const { return bytes_->pixels.data(); }
std::size_t CompositeAhead::Packed::size() const { return bytes_->pixels.size(); }

CompositeAhead::CompositeAhead(std::size_t depth) : depth_(std::max<std::size_t>(depth, 1)) {
  worker_ = std::jthread([this](std::stop_token stop) { run(stop); });
}

CompositeAhead::~CompositeAhead() {
  // The worker's wait wakes on the stop request; a frame in hand is finished first (tens of ms).
  worker_.request_stop();
  worker_.join();
}

void CompositeAhead::want(std::shared_ptr<const CompositeSetup> setup, std::span<const Frame> frames) {
  std::lock_guard lock(mutex_);
  setup_ = std::move(setup);
  std::vector<Entry> next;
  if (setup_) {
    for (std::size_t i = 0; i < std::min(depth_, frames.size()); ++i) {
      const auto old = std::find_if(wanted_.begin(), wanted_.end(),
                                    [&](const Entry& e) { return e.frame.get() == frames[i].get(); });
      if (old == wanted_.end()) {
        next.push_back(Entry{frames[i], nullptr, nullptr, false});
        continue;
      }
      Entry e = std::move(*old);
      if (e.made_with != setup_) {  // made for what was on screen before: make it again
        if (e.packed) pool_.push_back(std::move(e.packed));
        e.made_with.reset();
        e.failed = false;
      }
      next.push_back(std::move(e));
    }
  }
  for (Entry& e : wanted_)  // those not moved into `next`: no longer wanted
    if (e.packed) pool_.push_back(std::move(e.packed));
  wanted_ = std::move(next);
  wake_.notify_all();
}

std::optional<CompositeAhead::Packed> CompositeAhead::take(const StereoVideoFrame& frame, const CompositeSetup& setup) {
  std::unique_lock lock(mutex_);
  // Being made with this setup: waiting costs less than making it a second time beside the worker.
  done_.wait(lock, [&] { return in_hand_ != &frame || in_hand_setup_ != &setup; });
  const auto found =
      std::find_if(wanted_.begin(), wanted_.end(), [&](const Entry& e) { return e.frame.get() == &frame; });
  if (found == wanted_.end()) return std::nullopt;
  std::optional<Packed> out;
  if (found->packed && found->made_with.get() == &setup) out.emplace(Packed(this, std::move(found->packed)));
  // Frames are shown in order: those wanted before this one were dropped unshown.
  for (auto e = wanted_.begin(); e != found + 1; ++e)
    if (e->packed) pool_.push_back(std::move(e->packed));
  wanted_.erase(wanted_.begin(), found + 1);
  // The worker is not woken here, nor when the packed frame comes back: the display's thread is
  // about to present, and the next want() (after present()) wakes it.
  return out;
}

std::size_t CompositeAhead::buffers() const {
  std::lock_guard lock(mutex_);
  return buffers_;
}

std::size_t CompositeAhead::wait_until_idle(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  done_.wait_for(lock, timeout, [&] { return !in_hand_ && !has_work(); });
  return static_cast<std::size_t>(
      std::count_if(wanted_.begin(), wanted_.end(), [](const Entry& e) { return e.packed != nullptr; }));
}

bool CompositeAhead::has_work() const {
  if (!setup_ || (pool_.empty() && buffers_ > depth_)) return false;
  return std::any_of(wanted_.begin(), wanted_.end(), [](const Entry& e) { return !e.packed && !e.failed; });
}

std::unique_ptr<CompositeAhead::Bytes> CompositeAhead::acquire() {
  if (!pool_.empty()) {
    auto bytes = std::move(pool_.back());
    pool_.pop_back();
    return bytes;
  }
  ++buffers_;
  return std::make_unique<Bytes>();
}

void CompositeAhead::recycle(std::unique_ptr<Bytes> bytes) {
  std::lock_guard lock(mutex_);
  pool_.push_back(std::move(bytes));
}

void CompositeAhead::run(std::stop_token stop) {
  // Below the display's thread and the X server: the worker has a frame period of slack, present()
  // has none. At the same priority, compositing the next frame while the display's thread presented
  // made present() (mostly the X server's swap) take ~28 ms instead of ~10 ms on two cores, more than
  // the compositing it saved. Linux: the nice value is per thread, and render_packed_eyes' second
  // thread inherits it. Failing to lower it is not an error.
  setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), worker_nice_);
  std::unique_lock lock(mutex_);
  while (wake_.wait(lock, stop, [&] { return has_work(); })) {
    const auto next =
        std::find_if(wanted_.begin(), wanted_.end(), [](const Entry& e) { return !e.packed && !e.failed; });
    const Frame frame = next->frame;  // kept alive while in hand, whatever want() does meanwhile
    const std::shared_ptr<const CompositeSetup> setup = setup_;
    auto bytes = acquire();
    in_hand_ = frame.get();
    in_hand_setup_ = setup.get();
    lock.unlock();
    bool made = false;
    try {
      made = composite(*setup, *frame, *bytes);
    } catch (const std::exception&) {
      made = false;  // e.g. out of memory: the display's thread composites it itself
    }
    lock.lock();
    in_hand_ = nullptr;
    in_hand_setup_ = nullptr;
    const auto entry = std::find_if(wanted_.begin(), wanted_.end(), [&](const Entry& e) { return e.frame == frame; });
    // Kept only when still wanted with the setup it was made with; want() or take() may have
    // changed either while it was being made.
    if (entry != wanted_.end() && setup_ == setup && !entry->packed) {
      if (made) {
        entry->packed = std::move(bytes);
        entry->made_with = setup;
      } else {
        entry->failed = true;
      }
    }
    if (bytes) pool_.push_back(std::move(bytes));
    done_.notify_all();
  }
}

bool CompositeAhead::composite(const CompositeSetup& setup, const StereoVideoFrame& frame, Bytes& out) {
  const int texture_w = setup.view_width / std::max(setup.block[0], 1);
  const int texture_h = setup.view_height / std::max(setup.block[1], 1);
  const std::size_t view_size = static_cast<std::size_t>(texture_w) * texture_h * 4;
  // Frames decoded for other views (a new block after an optics key, a new stream geometry) wait
  // for the display's thread, which makes the tables for them.
  if (!setup.tables || frame.bits != 8 || frame.width != setup.view_width || frame.height != setup.view_height ||
      frame.block != setup.block || frame.aspect != setup.aspect || frame.left.size() != view_size ||
      frame.right.size() != view_size)
    return false;
  std::array<const std::uint8_t*, 2> views{};
  for (std::size_t i = 0; i < 2; ++i)
    views[i] = covered_view(i == 0 ? frame.left : frame.right, setup.grid ? &(*setup.grid)[i] : nullptr,
                            setup.message.get(), views_[i]);
  // The frame's depth as the display's thread takes it (FrameCompositor::update_depth): unusable
  // depth is the flat screen.
  FrameSurfaces::Pair surfaces;
  if (setup.depth && setup.surfaces && frame.disparity) {
    try {
      surfaces = setup.surfaces->get(frame.disparity);
    } catch (const std::invalid_argument&) {
      surfaces = {};
    }
  }
  render_packed_frame(*setup.tables, views, static_cast<std::size_t>(texture_w) * 4, setup.swap_eyes, setup.origins,
                      setup.packed, out, {surfaces[0].get(), surfaces[1].get()});
  compensate_packed_eyes(setup.defects, setup.origins, out.pixels.data(), static_cast<std::size_t>(setup.packed[0]) * 4,
                         8);
  return true;
}

FrameSurfaces::Pair FrameSurfaces::get(const std::shared_ptr<const StereoDisparity>& disparity) {
  const auto find = [&] {
    return std::find_if(recent_.begin(), recent_.end(), [&](const auto& entry) { return entry.first == disparity; });
  };
  {
    std::lock_guard lock(mutex_);
    if (const auto found = find(); found != recent_.end()) return found->second;
  }
  // Made outside the lock (the other thread goes on meanwhile); if it made them too, its are kept.
  Pair made{std::make_shared<const DisparitySurface>(disparity->left),
            std::make_shared<const DisparitySurface>(disparity->right)};
  std::lock_guard lock(mutex_);
  if (const auto found = find(); found != recent_.end()) return found->second;
  if (recent_.size() >= kept_) recent_.erase(recent_.begin());
  recent_.emplace_back(disparity, made);
  return made;
}

void compensate_packed_eyes(const EyeDefectPlans& plans,
                            const std::array<std::optional<std::pair<int, int>>, 2>& origins, std::uint8_t* packed,
                            std::size_t stride, int bits) {
  for (std::size_t e = 0; e < 2; ++e) {
    if (!plans[e] || !origins[e]) continue;
    const auto [x, y] = *origins[e];
    compensate_defects(
        *plans[e], packed + static_cast<std::size_t>(y) * stride + static_cast<std::size_t>(x) * bytes_per_pixel(bits),
        bits, stride);
  }
}

const std::uint8_t* covered_view(std::span<const std::uint8_t> view, const Image* grid, const Image* message,
                                 std::vector<std::uint8_t>& scratch) {
  if (!grid && !message) return view.data();
  scratch.assign(view.begin(), view.end());
  if (grid) draw_over(scratch, *grid, 8);
  if (message) draw_over(scratch, *message, 8);
  return scratch.data();
}

void render_packed_frame(std::array<std::optional<CompositeTable>, 2>& tables,
                         const std::array<const std::uint8_t*, 2>& views, std::size_t view_stride, bool swap_eyes,
                         const std::array<std::optional<std::pair<int, int>>, 2>& origins, std::array<int, 2> packed,
                         PackedFrameBytes& out, const std::array<const DisparitySurface*, 2>& surfaces) {
  const std::size_t stride = static_cast<std::size_t>(packed[0]) * 4;
  const std::size_t size = stride * static_cast<std::size_t>(packed[1]);
  if (out.pixels.size() != size || out.packed != packed || out.origins != origins) {
    out.pixels.resize(size);
    fill_opaque_black(out.pixels);  // the same bytes in BGRA
    out.packed = packed;
    out.origins = origins;
  }
  const int swap = swap_eyes ? 1 : 0;
  render_packed_eyes(tables, {views[swap], views[1 - swap]}, view_stride, origins, out.pixels.data(), stride,
                     ChannelOrder::bgra, {surfaces[swap], surfaces[1 - swap]});
}

}  // namespace nelf
