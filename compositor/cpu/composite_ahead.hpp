#pragma once
// Compositing ahead for `nelf play` on the CPU path (issue #5's pacing goal). On software GL the
// player composites each frame from the composite tables on the CPU (compositor/cpu/composite_table).
// Done on the display's thread when the frame is due, that cost ~15 ms, but on two cores it now and
// then took 20–42 ms (the thread lost its core to the decoder, the X server and the audio) and the
// frame missed its refresh. Here a worker thread composites the next frames waiting in the queue
// into packed frames while the display's thread sleeps until its refresh, so that showing one
// costs that thread only the upload of the packed frame and present(); a slow composite is absorbed
// by the frame period's slack (41.7 ms at 24 fps) instead of delaying the refresh.
//
// A packed frame is handed out only for the frame and the very setup it was made with: the caller
// makes a new CompositeSetup for every change of what a frame would look like (tables, eye swap,
// calibration grid, eye positions, view geometry) and frames made with an older one are thrown
// away, never shown. Memory is bounded: at most `depth` frames ahead, depth + 1 packed frames.
#include <array>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <stop_token>
#include <thread>
#include <utility>
#include <vector>

#include "compositor/cpu/composite_table.hpp"
#include "core/frames.hpp"
#include "core/image.hpp"
#include "optics/defect_compensation.hpp"
#include "optics/depth.hpp"

namespace nelf {

// Everything a packed frame made from the tables depends on besides the frame itself. Shared
// read-only between the display's thread, which makes it, and the worker, except `tables`: their
// render() uses scratch buffers, so they are the worker's own copy, rendered only by the worker.
// Per eye, the defect compensation a packed frame's panel takes (optics/defect_compensation.hpp),
// made for the frame's channel order; null: nothing to hide on that eye.
using EyeDefectPlans = std::array<std::shared_ptr<const EyeDefectPlan>, 2>;

// Each eye's plan applied to its panel in `packed` (`bits` a channel, `stride` bytes a row), the
// panel's top-left corner at origins[e].
void compensate_packed_eyes(const EyeDefectPlans& plans,
                            const std::array<std::optional<std::pair<int, int>>, 2>& origins, std::uint8_t* packed,
                            std::size_t stride, int bits);

// The surfaces of the frames' disparities (per view), made once per frame and shared by the
// display's thread and the worker: building one (its unknown texels filled, its front bounds) cost
// about 0.6 ms a view, twice a frame when each thread made its own. Holds the last few frames'
// disparities, so a depth source does not write their maps again while they are here.
class FrameSurfaces {
 public:
  using Pair = std::array<std::shared_ptr<const DisparitySurface>, 2>;
  // The surfaces of `disparity` (left, right). Throws std::invalid_argument as DisparitySurface
  // does for maps that do not hold together (and keeps nothing for them).
  Pair get(const std::shared_ptr<const StereoDisparity>& disparity);

 private:
  static constexpr std::size_t kept_ = 6;  // the frames composited ahead and the one shown, and some
  std::mutex mutex_;
  std::vector<std::pair<std::shared_ptr<const StereoDisparity>, Pair>> recent_;  // oldest first
};

struct CompositeSetup {
  std::shared_ptr<std::array<std::optional<CompositeTable>, 2>> tables;  // per eye
  std::array<std::optional<std::pair<int, int>>, 2> origins;             // panels' top-left corners
  std::array<int, 2> packed{0, 0};                                       // packed frame size
  bool swap_eyes = false;                                                // eye e shows view e ^ swap
  std::shared_ptr<const std::array<Image, 2>> grid;                      // calibration cover per view, or none
  // The views the tables were made for (8-bit block means); other frames are not composited.
  int view_width = 0, view_height = 0;
  std::array<int, 2> block{1, 1};
  double aspect = 0.0;
  // The on-screen message over both views, after the grid (TextOverlay::cover), or none.
  std::shared_ptr<const Image> message;
  // The dead and stuck pixels hidden after compositing, per eye (plans for BGRA bytes), or none.
  EyeDefectPlans defects;
  // Frames that carry their depth are composited with it (the tables hold the depth-aware rays,
  // CompositeTable::has_depth), their surfaces from `surfaces`; a frame whose depth is unusable
  // shows the flat screen, as on the display's thread.
  bool depth = false;
  std::shared_ptr<FrameSurfaces> surfaces;
};

// The bytes a view is composited from: `view` itself, or, with a calibration `grid` or a `message`
// cover (either may be null), a copy in `scratch` with the grid and then the message drawn over it.
const std::uint8_t* covered_view(std::span<const std::uint8_t> view, const Image* grid, const Image* message,
                                 std::vector<std::uint8_t>& scratch);

// A packed frame made from the tables: BGRA8 (ChannelOrder::bgra: the display's packed texture is
// BGRA, so uploading and presenting it are copies), row 0 the top row, packed[0]·4 bytes a row; and
// the layout its pixels around the panels were made black for (the tables write every pixel of the
// panels, so the memory is made black again only when the panels move).
struct PackedFrameBytes {
  std::vector<std::uint8_t> pixels;
  std::array<int, 2> packed{0, 0};
  std::array<std::optional<std::pair<int, int>>, 2> origins;
};

// Both eyes through `tables` into `out` (made packed[0] × packed[1] and black around the panels
// first, when its layout is another): eye e renders views[e ^ swap_eyes] (8-bit block means,
// `view_stride` bytes a row) with its panel's top-left corner at origins[e], where its ray meets
// surfaces[e ^ swap_eyes] (that view's depth; null: the flat screen). What the worker and the
// display's thread both do with a frame on the CPU path.
void render_packed_frame(std::array<std::optional<CompositeTable>, 2>& tables,
                         const std::array<const std::uint8_t*, 2>& views, std::size_t view_stride, bool swap_eyes,
                         const std::array<std::optional<std::pair<int, int>>, 2>& origins, std::array<int, 2> packed,
                         PackedFrameBytes& out, const std::array<const DisparitySurface*, 2>& surfaces = {});

class CompositeAhead {
  using Bytes = PackedFrameBytes;

 public:
  using Frame = std::shared_ptr<const StereoVideoFrame>;

  // A packed frame (PackedFrameBytes' pixels: BGRA8, row 0 the top row, black around the panels).
  // Its memory goes back to the CompositeAhead it came from, which must outlive it.
  class Packed {
   public:
    Packed(Packed&& other) noexcept : owner_(std::exchange(other.owner_, nullptr)), bytes_(std::move(other.bytes_)) {}
    Packed& operator=(Packed&&) = delete;
    Packed(const Packed&) = delete;
    Packed& operator=(const Packed&) = delete;
    ~Packed();
    const std::uint8_t* data() const;
    std::size_t size() const;

   private:
    friend class CompositeAhead;
    Packed(CompositeAhead* owner, std::unique_ptr<Bytes> bytes);
    CompositeAhead* owner_;
    std::unique_ptr<Bytes> bytes_;
  };

  // depth: how many of the next frames are composited ahead (≥ 1).
  explicit CompositeAhead(std::size_t depth = 2);
  ~CompositeAhead();  // stops the worker (it finishes the frame in hand first)
  CompositeAhead(const CompositeAhead&) = delete;
  CompositeAhead& operator=(const CompositeAhead&) = delete;

  // The display's thread, every refresh: composite `frames` (the next to be shown, in the order
  // they will be; the first `depth` are taken) with `setup`, or nothing when `setup` is null (the
  // frames will not be shown from the tables). Frames made for other frames or with another setup
  // are thrown away.
  void want(std::shared_ptr<const CompositeSetup> setup, std::span<const Frame> frames);

  // The display's thread, when `frame` is to be shown with `setup`: its packed frame, waiting for
  // it while the worker is making it with that setup; nothing when it was not made (not wanted in
  // time, another setup, another view geometry, an error) — the caller composites it itself.
  // Either way the frame is no longer wanted.
  std::optional<Packed> take(const StereoVideoFrame& frame, const CompositeSetup& setup);

  // Packed frames in memory (the pool, finished frames, the one being made, those handed out).
  std::size_t buffers() const;
  // Waits (up to `timeout`) until the worker has nothing it can do (the player, before its clock
  // starts; tests); then how many of the wanted frames are made.
  std::size_t wait_until_idle(std::chrono::milliseconds timeout);

 private:
  struct Entry {
    Frame frame;
    std::unique_ptr<Bytes> packed;                    // once made
    std::shared_ptr<const CompositeSetup> made_with;  // the setup `packed` was made with
    bool failed = false;                              // not made (geometry, error): not tried again
  };
  void run(std::stop_token stop);
  bool has_work() const;
  std::unique_ptr<Bytes> acquire();
  void recycle(std::unique_ptr<Bytes> bytes);
  // false when `frame` does not have the views `setup` was made for.
  bool composite(const CompositeSetup& setup, const StereoVideoFrame& frame, Bytes& out);

  const std::size_t depth_;
  static constexpr int worker_nice_ = 10;
  mutable std::mutex mutex_;
  std::condition_variable_any wake_;  // the worker: want() (after present()), stop
  std::condition_variable done_;      // take(): the frame in hand is finished
  std::shared_ptr<const CompositeSetup> setup_;
  std::vector<Entry> wanted_;  // in showing order, ≤ depth_
  // The frame the worker is compositing and the setup it uses (take() waits for it).
  const StereoVideoFrame* in_hand_ = nullptr;
  const CompositeSetup* in_hand_setup_ = nullptr;
  std::vector<std::unique_ptr<Bytes>> pool_;
  std::size_t buffers_ = 0;
  // The worker's scratch: the views with the calibration grid and the message drawn over them.
  std::array<std::vector<std::uint8_t>, 2> views_;
  std::jthread worker_;  // last: stops before the members it uses go
};

}  // namespace nelf
