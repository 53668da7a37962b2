#include "player/player.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "compositor/cpu/composite_ahead.hpp"
#include "compositor/cpu/composite_table_cache.hpp"
#include "compositor/gl/gl_compositor.hpp"
#include "compositor/overlays/calibration_overlay.hpp"
#include "compositor/overlays/text_overlay.hpp"
#include "core/gl/objects.hpp"
#include "core/image_library.hpp"
#include "core/user_error.hpp"
#include "hmz_output/audio_output.hpp"
#include "hmz_output/packing.hpp"
#include "inputs/audio_source.hpp"
#include "inputs/test_patterns.hpp"
#include "player/key_bindings.hpp"

namespace nelf {

namespace {

using Steady = std::chrono::steady_clock;
double seconds_since(Steady::time_point t) { return std::chrono::duration<double>(Steady::now() - t).count(); }

// Decoded frames waiting for their refresh. The decode thread fills it up to `capacity`; a seek
// empties it and bumps the generation so that a frame decoded before the seek is never queued.
// Frames are shared read-only from here on: the compositing-ahead worker reads the next ones while
// they wait (CompositeAhead).
class FrameQueue {
 public:
  using Frame = CompositeAhead::Frame;

  explicit FrameQueue(std::size_t capacity) : capacity_(capacity) {}

  // Decode thread: waits for room (or a seek, a new reduction, or stop). Returns the seek target
  // and the reduction if one is pending.
  struct Work {
    std::optional<double> seek_to;
    std::optional<ViewBlockChooser> reduce;
    std::uint64_t generation = 0;
    bool stop = false;
  };
  Work wait_for_work() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return stop_ || seek_to_ || reduce_ || (!end_ && items_.size() < capacity_); });
    Work work{std::exchange(seek_to_, std::nullopt), std::exchange(reduce_, std::nullopt), generation_, stop_};
    return work;
  }
  void push(StereoVideoFrame frame, std::uint64_t generation) {
    std::lock_guard lock(mutex_);
    if (generation != generation_) return;  // decoded before a seek
    items_.push_back(std::make_shared<const StereoVideoFrame>(std::move(frame)));
    changed_.notify_all();
  }
  void set_end(std::uint64_t generation) {
    std::lock_guard lock(mutex_);
    if (generation == generation_) end_ = true;
    changed_.notify_all();
  }
  void fail(std::exception_ptr error) {
    std::lock_guard lock(mutex_);
    error_ = error;
    end_ = true;
    changed_.notify_all();
  }

  // Render thread.
  void seek(double seconds) {
    std::lock_guard lock(mutex_);
    seek_to_ = seconds;
    ++generation_;
    items_.clear();
    end_ = false;
    changed_.notify_all();
  }
  // The views of frames decoded from now on as `choose` says (StereoFrameSource::reduce_views);
  // frames already queued keep theirs.
  void reduce_views(ViewBlockChooser choose) {
    std::lock_guard lock(mutex_);
    reduce_ = std::move(choose);
    changed_.notify_all();
  }
  void stop() {
    std::lock_guard lock(mutex_);
    stop_ = true;
    changed_.notify_all();
  }
  // pts of the queued frames and whether the stream has ended; rethrows the decoder's failure.
  std::vector<double> snapshot(bool& end) {
    std::lock_guard lock(mutex_);
    if (error_) std::rethrow_exception(error_);
    std::vector<double> pts;
    pts.reserve(items_.size());
    for (const auto& f : items_) pts.push_back(f->pts_s);
    end = end_ && !seek_to_;
    return pts;
  }
  // Removes `drop` frames, then returns the next one if `take` (null when there is none).
  Frame pop(std::size_t drop, bool take) {
    std::lock_guard lock(mutex_);
    for (std::size_t i = 0; i < drop && !items_.empty(); ++i) items_.pop_front();
    Frame out;
    if (take && !items_.empty()) {
      out = std::move(items_.front());
      items_.pop_front();
    }
    changed_.notify_all();
    return out;
  }
  // The first `count` queued frames (fewer when fewer are there), oldest first; they stay queued.
  std::vector<Frame> front(std::size_t count) {
    std::lock_guard lock(mutex_);
    return std::vector<Frame>(items_.begin(),
                              items_.begin() + static_cast<std::ptrdiff_t>(std::min(count, items_.size())));
  }
  // Waits up to `timeout` for a frame (or the end); true when one is there.
  bool wait_for_frame(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return !items_.empty() || end_ || error_; });
    if (error_) std::rethrow_exception(error_);
    return !items_.empty();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Frame> items_;
  std::size_t capacity_;
  std::optional<double> seek_to_;
  std::optional<ViewBlockChooser> reduce_;
  std::uint64_t generation_ = 0;
  bool end_ = false, stop_ = false;
  std::exception_ptr error_;
};

// The decode thread: fills the queue, follows seeks. Frames whose time passes while they wait are
// dropped by the scheduler. (Skipping late frames here as well was measured and is worse when
// decoding is the bottleneck: each decoded frame is late, so most were thrown away without the
// decoder catching up; jumping ahead by seeking is worse still with long GOPs.)
void decode_loop(StereoFrameSource& source, FrameQueue& queue) {
  try {
    for (;;) {
      const FrameQueue::Work work = queue.wait_for_work();
      if (work.stop) return;
      if (work.reduce) source.reduce_views(*work.reduce);
      if (work.seek_to) {
        source.seek(*work.seek_to);
        continue;
      }
      auto frame = source.next();
      if (!frame) {
        queue.set_end(work.generation);
        continue;
      }
      queue.push(std::move(*frame), work.generation);
    }
  } catch (...) {
    queue.fail(std::current_exception());
  }
}

// Feeds decoded audio to the device, about half a second ahead, until stopped.
class AudioFeeder {
 public:
  AudioFeeder(AudioSource source, AudioOutput& output) : source_(std::move(source)), output_(output) {
    thread_ = std::jthread([this](std::stop_token stop) { run(stop); });
  }
  ~AudioFeeder() {
    thread_.request_stop();
    wake_.notify_all();
  }
  AudioFeeder(const AudioFeeder&) = delete;
  AudioFeeder& operator=(const AudioFeeder&) = delete;

  // Render thread: drop what is queued and continue from `seconds`.
  void seek(double seconds) {
    std::lock_guard lock(mutex_);
    output_.restart_at(seconds);
    seek_to_ = seconds;
    ++generation_;
    ended_ = false;
    wake_.notify_all();
  }
  std::int64_t decode_errors() const { return errors_.load(); }

 private:
  void run(std::stop_token stop) {
    while (!stop.stop_requested()) {
      std::uint64_t generation;
      {
        std::unique_lock lock(mutex_);
        if (seek_to_) {
          try {
            source_.seek(*std::exchange(seek_to_, std::nullopt));
          } catch (const AudioError&) {
            ended_ = true;  // a file that cannot seek its audio plays on without it
            output_.end_of_stream();
          }
        }
        if (ended_) {
          wake_.wait_for(lock, std::chrono::milliseconds(50));
          continue;
        }
        generation = generation_;
      }
      if (output_.buffered_s() > 0.5) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        continue;
      }
      std::optional<AudioChunk> chunk;
      try {
        chunk = source_.next();
      } catch (const AudioError&) {
        chunk.reset();  // the audio is beyond repair: the video goes on, on the clock the sound left
      }
      errors_.store(source_.decode_errors());
      std::lock_guard lock(mutex_);
      if (generation != generation_) continue;  // decoded before a seek
      if (!chunk) {
        ended_ = true;
        output_.end_of_stream();
        continue;
      }
      output_.queue(*chunk);
    }
  }

  AudioSource source_;
  AudioOutput& output_;
  std::mutex mutex_;
  std::condition_variable_any wake_;
  std::optional<double> seek_to_;
  std::uint64_t generation_ = 0;
  bool ended_ = false;
  std::atomic<std::int64_t> errors_{0};
  std::jthread thread_;  // last: stops before the members it uses go
};

// The GL side: view textures, the compositor (rebuilt when the optics change) and the eye areas;
// on software GL also the CPU path, composite tables replayed from the views' bytes.
class PackedRenderer {
 public:
  // Frames composited ahead: three, with four packed frames (7.5 MB each at 720p frame packing) in
  // memory. With a busy process beside the player on two cores, ten 30 fps runs dropped 17 frames
  // in all with two ahead and 8 with three; on a quiet machine both drop none.
  static constexpr std::size_t ahead_depth = 3;

  PackedRenderer(Display& display, const PlayerOptions& options)
      : display_(display), options_(options), prefer_tables_(prefer_composite_table(*display.context())) {
    profile_ = options.profile;
    rebuild();
  }

  // Throws (and keeps the old compositor) when the profile is not usable.
  void set_profile(const Profile& profile) {
    const Profile previous = profile_;
    profile_ = profile;
    try {
      rebuild();
    } catch (...) {
      profile_ = previous;
      rebuild();
      throw;
    }
  }
  const Profile& profile() const { return profile_; }

  // The frame's views into the view textures: whole views, or (frame.block > 1×1) the block means
  // the compositor's prefilter starts from, 1/block² of the texels to upload and composite. The
  // frame is kept: render() may find it composited ahead.
  void upload(std::shared_ptr<const StereoVideoFrame> shared, bool calibration) {
    frame_ = std::move(shared);
    calibration_ = calibration;
    const StereoVideoFrame& frame = *frame_;
    if (frame.width != view_w_ || frame.height != view_h_ || frame.bits != bits_ || frame.block != block_ ||
        frame.aspect != aspect_) {
      view_w_ = frame.width;
      view_h_ = frame.height;
      bits_ = frame.bits;
      block_ = frame.block;
      aspect_ = frame.aspect;
      for (auto& t : views_) t = gl::make_texture_2d(bits_ > 8 ? GL_RGBA16 : GL_RGBA8, texture_w(), texture_h());
      update_wanted_blocks();
      forget_tables();
    }
    // The textures are filled even when the CPU path will composite this frame: a key changing
    // the optics hands the next renders to GL (until block means for the new optics arrive),
    // which then needs them.
    const GLenum type = bits_ > 8 ? GL_UNSIGNED_SHORT : GL_UNSIGNED_BYTE;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    for (int i = 0; i < 2; ++i) {
      const auto& source = i == 0 ? frame.left : frame.right;
      const std::uint8_t* pixels = source.data();
      if (calibration) {
        grid_views_[i].assign(source.begin(), source.end());
        draw_over(grid_views_[i], calibration_grid(i), bits_);
        pixels = grid_views_[i].data();
      }
      glTextureSubImage2D(views_[i].id(), 0, 0, 0, texture_w(), texture_h(), GL_RGBA, type, pixels);
    }
    gl::check_error("uploading the views");
  }

  // The block each eye's prefilter wants for the current views and optics ({1, 1}: whole views).
  std::array<int, 2> wanted_block(Eye eye) const { return wanted_blocks_[static_cast<int>(eye)]; }

  // The grid for view `i` at the view's size and the current optics, as cover for the view
  // texture (cover_grid: block means of it on reduced views). Made when first needed.
  const Image& calibration_grid(int i) {
    const PatternGeometry geometry = pattern_geometry(profile_, view_w_, view_h_);
    if (!grid_ || !(grid_geometry_ == geometry) || grid_block_ != block_) {
      const StereoPair pair = make_test_pattern(TestPattern::grid, geometry);
      // A new object, never changed: a CompositeSetup holding the old one stays as it was made.
      grid_ = std::make_shared<const std::array<Image, 2>>(
          std::array<Image, 2>{cover_grid(pair.left.image, block_), cover_grid(pair.right.image, block_)});
      grid_geometry_ = geometry;
      grid_block_ = block_;
    }
    return (*grid_)[static_cast<std::size_t>(i)];
  }

  // The on-screen message ("" for none), blended into both views before compositing so that it
  // is seen in focus through the lenses.
  void set_message(const std::string& text) { overlay_.set_text(text); }

  // Both eyes into the display's packed framebuffer; the gap (and any border) black. True when the
  // frame came composited ahead by the worker.
  bool render(bool swap_eyes) {
    if (use_tables()) {
      // Only a packed frame made for this frame with exactly the current setup; else as before.
      const auto setup = frame_ ? ahead_setup(swap_eyes) : nullptr;
      if (setup) {
        if (const auto packed = ahead_.take(*frame_, *setup)) {
          upload_packed(packed->data());
          return true;
        }
      }
      render_from_tables(swap_eyes);
      return false;
    }
    const GLuint fbo = display_.packed_framebuffer();
    const float black[4] = {0.f, 0.f, 0.f, 1.f};
    glClearNamedFramebufferfv(fbo, GL_COLOR, 0, black);
    if (view_w_ == 0) return false;
    for (Eye eye : {Eye::left, Eye::right}) {
      const auto& origin = origins_[static_cast<int>(eye)];
      if (!origin) continue;
      const int view = static_cast<int>(eye) ^ (swap_eyes ? 1 : 0);
      // The text goes onto the texture as it is (block means: at their size, where it is as sharp
      // as the prefilter would leave full-size text, and its cap height still 1/20 of the view).
      const GlTextureView shown =
          overlay_.apply(eye, GlTextureView{views_[view].id(), texture_w(), texture_h(),
                                            aspect_ > 0.0 ? aspect_ : double(view_w_) / view_h_});
      const GlTarget target{fbo, origin->first, origin->second};
      if (reduced() && block_ == wanted_block(eye))
        compositor_->render_eye_reduced(eye, GlReducedView{{shown.texture, view_w_, view_h_, aspect_}, block_}, target);
      else  // whole views, or block means made for optics changed since (a key): a smaller view
        compositor_->render_eye(eye, shown, target);
    }
    return false;
  }

  // Every refresh: `frames` (the next to be shown, in order) to be composited ahead on the worker
  // with the setup render() would use now, or none when it would not use the tables.
  void composite_ahead(bool swap_eyes, std::span<const CompositeAhead::Frame> frames) {
    ahead_.want(ahead_setup(swap_eyes), frames);
  }
  // Waits (up to `timeout`) until the worker has made what it was asked for.
  void wait_for_ahead(std::chrono::milliseconds timeout) { ahead_.wait_until_idle(timeout); }

 private:
  // The CPU path (compositor/cpu/composite_table.hpp) replays the fsaa-1 composite of 8-bit block
  // means several times cheaper than llvmpipe runs the GL passes; prefer_composite_table says
  // where it pays (software GL, or NELF_COMPOSITE).
  bool may_use_tables() const { return prefer_tables_ && bits_ == 8 && reduced(); }
  // Whether this render goes the CPU path: not with block means made for optics a key has changed
  // since (the GL path's smaller view covers the frames until the new block arrives). A message
  // goes into the views' bytes (message_cover). Records the tables on first use for the current
  // views and optics.
  bool table_path_open() const {
    if (view_w_ == 0 || !may_use_tables()) return false;
    for (Eye eye : {Eye::left, Eye::right})
      if (origins_[static_cast<int>(eye)] && block_ != wanted_block(eye)) return false;
    return true;
  }
  bool use_tables() {
    if (!table_path_open()) return false;
    if (!tables_tried_) {
      tables_tried_ = true;
      for (Eye eye : {Eye::left, Eye::right}) {
        const int e = static_cast<int>(eye);
        if (!origins_[e]) continue;
        // From the cache when these optics and views were seen before (recording takes ~0.4 s,
        // e.g. after +/− back to a distance already used).
        tables_[e] = load_or_record_composite_table(table_cache_, compositor_.get(), profile_, options_.compositor, eye,
                                                    view_w_, view_h_, aspect_, block_);
        // No table for these options (fsaa other than 1, no prefilter): GL for both eyes.
        if (!tables_[e]) {
          tables_ = {};
          break;
        }
      }
    }
    return tables_[0] || tables_[1];
  }
  void forget_tables() {
    tables_ = {};
    tables_tried_ = false;
    worker_tables_.reset();
    setup_.reset();
  }

  // What the worker composites the next frames with: exactly what render_from_tables() would use
  // for them now (tables, eye positions, swap, calibration grid, views). Null while render() would
  // not take the table path, and until render() has made the tables (that needs GL, this thread).
  // A new setup for every change, so that frames made with the old one are never shown.
  std::shared_ptr<const CompositeSetup> ahead_setup(bool swap_eyes) {
    if (!table_path_open() || !tables_tried_ || !(tables_[0] || tables_[1])) return nullptr;
    std::shared_ptr<const std::array<Image, 2>> grid;
    if (calibration_) {
      try {
        calibration_grid(0);  // as upload() would make it for the next frame (the optics may have changed)
      } catch (const TestPatternError&) {
        return nullptr;
      }
      grid = grid_;
    }
    std::shared_ptr<const Image> message;
    try {
      message = message_cover();
    } catch (const std::runtime_error&) {
      return nullptr;  // no font: render() says so
    }
    if (!setup_ || setup_->swap_eyes != swap_eyes || setup_->grid != grid || setup_->message != message) {
      // The worker's own copy (once per tables): a table's render() uses its scratch buffers.
      if (!worker_tables_) worker_tables_ = std::make_shared<std::array<std::optional<CompositeTable>, 2>>(tables_);
      setup_ = std::make_shared<const CompositeSetup>(CompositeSetup{worker_tables_, origins_, display_.packed_size(),
                                                                     swap_eyes, grid, view_w_, view_h_, block_, aspect_,
                                                                     message});
    }
    return setup_;
  }
  // The message as a cover for the views' bytes (what overlay_.apply() draws into the view
  // textures on the GL path), or null for none. Made when the text or the views change.
  std::shared_ptr<const Image> message_cover() {
    if (overlay_.text().empty()) return nullptr;
    const double aspect = aspect_ > 0.0 ? aspect_ : static_cast<double>(view_w_) / view_h_;
    if (!message_ || message_text_ != overlay_.text() || message_->width() != texture_w() ||
        message_->height() != texture_h() || message_aspect_ != aspect) {
      message_ = std::make_shared<const Image>(overlay_.cover(texture_w(), texture_h(), aspect));
      message_text_ = overlay_.text();
      message_aspect_ = aspect;
    }
    return message_;
  }
  // Both eyes into a CPU copy of the packed frame, then that into the display's texture: one
  // upload of the whole frame, since the eyes' panels are nearly all of it.
  void render_from_tables(bool swap_eyes) {
    // The views as uploaded: the frame's own bytes, or the copies with the grid drawn over them.
    std::array<const std::uint8_t*, 2> views =
        calibration_ ? std::array<const std::uint8_t*, 2>{grid_views_[0].data(), grid_views_[1].data()}
                     : std::array<const std::uint8_t*, 2>{frame_->left.data(), frame_->right.data()};
    // The message over them, as the GL path draws it over the textures.
    const auto message = message_cover();
    const std::size_t view_bytes = static_cast<std::size_t>(texture_w()) * texture_h() * 4;
    for (std::size_t i = 0; i < 2; ++i)
      views[i] = covered_view({views[i], view_bytes}, nullptr, message.get(), message_views_[i]);
    render_packed_frame(tables_, views, static_cast<std::size_t>(texture_w()) * 4, swap_eyes, origins_,
                        display_.packed_size(), packed_);
    upload_packed(packed_.pixels.data());
  }
  // A BGRA packed frame into the display's (BGRA) texture: a copy.
  void upload_packed(const std::uint8_t* pixels) {
    const auto packed = display_.packed_size();
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(display_.packed_texture(), 0, 0, 0, packed[0], packed[1], GL_BGRA, GL_UNSIGNED_BYTE, pixels);
    gl::check_error("uploading the packed frame");
  }

  bool reduced() const { return block_[0] > 1 || block_[1] > 1; }
  int texture_w() const { return view_w_ / block_[0]; }
  int texture_h() const { return view_h_ / block_[1]; }
  void update_wanted_blocks() {
    for (Eye eye : {Eye::left, Eye::right})
      wanted_blocks_[static_cast<int>(eye)] =
          view_w_ > 0 ? prefilter_block(profile_, options_.compositor, eye, view_w_, view_h_, aspect_)
                      : std::array<int, 2>{1, 1};
  }

  void rebuild() {
    forget_tables();
    compositor_.reset();
    compositor_ = std::make_unique<GlCompositor>(profile_, options_.compositor, display_.context());
    update_wanted_blocks();
    const auto panel = compositor_->panel();
    const auto packed = display_.packed_size();
    for (Eye eye : {Eye::left, Eye::right}) {
      const auto area = eye_area(options_.signal, eye, panel[0], panel[1]);
      origins_[static_cast<int>(eye)].reset();
      if (!area) continue;
      if (panel[0] > area->width || panel[1] > area->height)
        throw UserError(fmt::format("the {}x{} panel of profile {} does not fit the {}x{} eye area of signal {}",
                                    panel[0], panel[1], profile_.name, area->width, area->height, options_.signal.name),
                        2);
      const int x = area->x + (area->width - panel[0]) / 2, y = area->y + (area->height - panel[1]) / 2;
      if (x + panel[0] > packed[0] || y + panel[1] > packed[1])
        throw UserError(fmt::format("the display's {}x{} frame is smaller than signal {} needs", packed[0], packed[1],
                                    options_.signal.name),
                        1);
      origins_[static_cast<int>(eye)] = std::pair{x, y};
    }
  }

  Display& display_;
  const PlayerOptions& options_;
  Profile profile_;
  std::unique_ptr<GlCompositor> compositor_;
  TextOverlay overlay_;
  std::shared_ptr<const std::array<Image, 2>> grid_;
  PatternGeometry grid_geometry_;
  std::array<int, 2> grid_block_{1, 1};
  std::array<std::optional<std::pair<int, int>>, 2> origins_;
  std::array<gl::Texture, 2> views_;
  // The views with the calibration grid drawn over them, as in the textures while it is on.
  std::array<std::vector<std::uint8_t>, 2> grid_views_;
  // The message as a cover for the views' bytes (CPU path), what it was made for, and the views
  // with it drawn over them.
  std::shared_ptr<const Image> message_;
  std::string message_text_;
  double message_aspect_ = 0.0;
  std::array<std::vector<std::uint8_t>, 2> message_views_;
  // The CPU path: the tables for the current views and optics (recorded when first used), and the
  // packed frame.
  const bool prefer_tables_;
  std::array<std::optional<CompositeTable>, 2> tables_;
  bool tables_tried_ = false;
  // Compositing ahead: the frame last uploaded and whether with the grid, the worker's copy of the
  // tables and the setup last handed to it, and the worker (last: it stops first).
  std::shared_ptr<const StereoVideoFrame> frame_;
  bool calibration_ = false;
  std::shared_ptr<std::array<std::optional<CompositeTable>, 2>> worker_tables_;
  std::shared_ptr<const CompositeSetup> setup_;
  const CompositeTableCache table_cache_;
  PackedFrameBytes packed_;
  int view_w_ = 0, view_h_ = 0, bits_ = 8;
  std::array<int, 2> block_{1, 1};  // of the views in the textures
  std::array<std::array<int, 2>, 2> wanted_blocks_{};
  double aspect_ = 0.0;
  CompositeAhead ahead_{ahead_depth};
};

class FrameLog {
 public:
  explicit FrameLog(const std::string& path) {
    if (path.empty()) return;
    file_ = std::fopen(path.c_str(), "w");
    if (!file_) throw UserError(fmt::format("{}: cannot write the frame log", path), 1);
    std::fputs(
        "refresh,event,pts_s,clock_s,audio_clock_s,shown,repeated,dropped,upload_ms,render_ms,present_ms,queued,"
        "ahead\n",
        file_);
  }
  ~FrameLog() {
    if (file_) std::fclose(file_);
  }
  FrameLog(const FrameLog&) = delete;
  FrameLog& operator=(const FrameLog&) = delete;
  bool enabled() const { return file_ != nullptr; }
  // Times in seconds; what was not done this refresh is 0. `queued`: decoded frames waiting at the
  // decision; `ahead`: the frame rendered was composited ahead by the worker.
  void write(std::int64_t refresh, const char* event, std::optional<double> pts, double clock,
             std::optional<double> audio_clock, const FrameCounters& c, double upload_s, double render_s,
             double present_s, std::size_t queued, bool ahead) {
    if (!file_) return;
    std::fprintf(file_, "%lld,%s,%s,%.6f,%s,%lld,%lld,%lld,%.2f,%.2f,%.2f,%zu,%d\n", static_cast<long long>(refresh),
                 event, pts ? fmt::format("{:.6f}", *pts).c_str() : "", clock,
                 audio_clock ? fmt::format("{:.6f}", *audio_clock).c_str() : "", static_cast<long long>(c.shown),
                 static_cast<long long>(c.repeated), static_cast<long long>(c.dropped), upload_s * 1e3, render_s * 1e3,
                 present_s * 1e3, queued, ahead ? 1 : 0);
  }

 private:
  std::FILE* file_ = nullptr;
};

}  // namespace

std::string play_summary(const PlayResult& r) {
  std::string line = fmt::format("{} frames shown, {} repeated, {} dropped", r.counters.shown, r.counters.repeated,
                                 r.counters.dropped);
  if (r.video_decode_errors > 0) line += fmt::format(", {} video frames lost to decode errors", r.video_decode_errors);
  if (r.audio_decode_errors > 0) line += fmt::format(", {} audio decode errors", r.audio_decode_errors);
  return line;
}

PlayResult play(Display& display, StereoFrameSource& source, const PlayerOptions& options,
                const std::atomic<bool>* stop) {
  PlayResult result;
  // The on-screen messages draw their text with OpenImageIO, loaded on first use: load it now
  // (~0.3 s) rather than as a hitch at the first key press. Without it the film still plays; the
  // first message then stops play with the same error, as a missing font would.
  try {
    image_library::preload();
  } catch (const image_library::ImageLibraryError& e) {
    std::fprintf(stderr, "nelf: warning: %s\n", e.what());
  }
  display.context()->make_current();
  PackedRenderer renderer(display, options);
  FrameLog log(options.log_frames);

  // The master clock: the sound's when there is sound.
  std::unique_ptr<AudioOutput> audio;
  std::unique_ptr<AudioFeeder> feeder;
  SystemClock system_clock;
  PlaybackClock* clock = &system_clock;
  if (!options.audio) {
    result.sound = "--no-audio";
  } else if (source.has_generated_audio()) {
    result.sound = "the synthetic clip's tone is not played";
  } else if (source.audio_path().empty()) {
    result.sound = "no audio stream";
  } else {
    std::optional<AudioSource> audio_source;
    try {
      audio_source.emplace(source.audio_path(),
                           AudioSourceOptions{options.audio_rate, source.origin_s(), options.allow_network});
    } catch (const AudioError& e) {
      result.sound = std::string(e.what()).find("no audio stream") != std::string::npos
                         ? "no audio stream"
                         : fmt::format("the audio cannot be decoded ({})", e.what());
    }
    if (audio_source) {
      std::string why_not;
      audio = AudioOutput::open(audio_source->sample_rate(), why_not);
      if (!audio) {
        result.sound = fmt::format("no audio device ({})", why_not);
      } else {
        // The device may run at another rate: decode for the rate it has.
        if (audio->sample_rate() != audio_source->sample_rate())
          audio_source.emplace(source.audio_path(),
                               AudioSourceOptions{audio->sample_rate(), source.origin_s(), options.allow_network});
        result.had_sound = true;
        result.sound = audio->description();
        clock = audio.get();
        feeder = std::make_unique<AudioFeeder>(std::move(*audio_source), *audio);
      }
    }
  }
  if (!options.quiet) {
    if (result.had_sound)
      std::fprintf(stderr, "nelf: sound: %s\n", result.sound.c_str());
    else
      std::fprintf(stderr, "nelf: %s: playing without sound\n", result.sound.c_str());
  }
  clock->set_paused(true);  // starts with the first frame on screen

  const double refresh_period = 1.0 / display.refresh_hz();
  const double fps = source.frame_rate();
  FrameScheduler scheduler(refresh_period, fps > 0 ? 1.0 / fps : 0.0);
  // Views as the prefilter's block means where the input allows (swscale makes them while
  // converting from YUV): far less to convert, upload and composite per frame.
  const auto blocks_for = [&options](const Profile& profile) -> ViewBlockChooser {
    return [profile, compositor = options.compositor](int width, int height, double aspect) {
      return stereo_prefilter_block(profile, compositor, width, height, aspect);
    };
  };
  source.reduce_views(blocks_for(options.profile));
  constexpr std::size_t queue_capacity = 6;
  FrameQueue queue(queue_capacity);
  std::jthread decoder([&] { decode_loop(source, queue); });
  struct StopDecoder {
    FrameQueue& queue;
    ~StopDecoder() { queue.stop(); }
  } stop_decoder{queue};

  const auto duration = source.duration_s();

  bool paused = false, started = false, calibration = false, swap_eyes = false, dirty = false;
  std::size_t help_line = 0;  // the next line of the key help that h shows
  bool awaiting_seek = false;
  bool show_while_paused = false;  // a seek while paused shows the first frame at the new place
  std::shared_ptr<const StereoVideoFrame> current;
  std::string message;
  Steady::time_point message_until{};
  // Time from the decision to the end of present(): the median of the last few renders (the first,
  // which compiles shaders, does not count), so one slow frame on a loaded machine does not make
  // the next ones come early.
  std::deque<double> render_times;
  double render_s = refresh_period;
  std::int64_t refresh = 0;
  auto next_tick = Steady::now();

  auto say = [&](std::string text) {
    dirty = true;
    if (!options.on_screen_messages) return;
    message = std::move(text);
    renderer.set_message(message);
    message_until = Steady::now() + std::chrono::seconds(2);
  };
  auto seek_by = [&](double delta) {
    const double from = current ? current->pts_s : clock->now();
    double target = std::max(0.0, from + delta);
    if (duration) target = std::min(target, std::max(0.0, *duration - 0.001));
    queue.seek(target);
    if (feeder) feeder->seek(target);
    clock->restart_at(target);
    clock->set_paused(true);  // until the first frame after the seek is decoded
    awaiting_seek = true;
    scheduler.reset();
    say(fmt::format("{} {:.0f} s: {}:{:02d}", delta < 0 ? "back" : "forward", std::abs(delta),
                    static_cast<int>(target) / 60, static_cast<int>(target) % 60));
  };
  auto change_profile = [&](Profile changed, const std::string& what) {
    try {
      renderer.set_profile(changed);
      queue.reduce_views(blocks_for(changed));  // the block follows the optics
      dirty = true;
      say(what);
    } catch (const std::exception& e) {
      say(fmt::format("cannot: {}", e.what()));
    }
  };

  // Before the clock starts (after the first frame) or restarts (after a seek): the next frames
  // composited ahead, waiting up to 0.3 s. The worker's first frames take 40 ms and more (new
  // buffers, cold caches), and with the clock running the first refreshes dropped frames waiting
  // for them (2 of 300 at 30 fps in a run of tests/bench/play_pacing.sh).
  auto prime_ahead = [&] {
    const std::vector<FrameQueue::Frame> next = queue.front(queue_capacity);
    renderer.composite_ahead(swap_eyes, next);
    renderer.wait_for_ahead(std::chrono::milliseconds(300));
  };

  // Wait (briefly) for the first frame so the clock does not run ahead of a slow start.
  while (!queue.wait_for_frame(std::chrono::milliseconds(50))) {
    bool end = false;
    queue.snapshot(end);
    if (end || (stop && stop->load()) || display.close_requested()) break;
    display.poll_events();
  }

  for (;;) {
    for (const KeyPress& key : display.poll_events()) {
      const std::optional<Command> command = command_for(KeyScope::play, key);
      if (!command) continue;
      switch (*command) {
        case Command::quit:
          result.end = PlayEnd::quit_key;
          break;
        case Command::pause:
          paused = !paused;
          if (!awaiting_seek && started) clock->set_paused(paused);
          say(paused ? "paused" : "playing");
          break;
        case Command::seek_back_10s:
          seek_by(-10);
          break;
        case Command::seek_forward_10s:
          seek_by(10);
          break;
        case Command::seek_forward_60s:
          seek_by(60);
          break;
        case Command::seek_back_60s:
          seek_by(-60);
          break;
        case Command::screen_farther:
        case Command::screen_nearer: {
          Profile p = renderer.profile();
          const double now_mm = p.screen.distance_mm > 0 ? p.screen.distance_mm : p.viewing.virtual_image_mm;
          p.screen.distance_mm = *command == Command::screen_nearer ? now_mm / 1.25 : now_mm * 1.25;
          change_profile(p, fmt::format("screen distance {:.0f} mm", p.screen.distance_mm));
          break;
        }
        case Command::ipd_narrower:
        case Command::ipd_wider: {
          Profile p = renderer.profile();
          p.viewing.ipd_mm += *command == Command::ipd_narrower ? -0.5 : 0.5;
          change_profile(p, fmt::format("IPD {:.1f} mm", p.viewing.ipd_mm));
          break;
        }
        case Command::swap_eyes:
          swap_eyes = !swap_eyes;
          dirty = true;
          say(swap_eyes ? "eyes swapped" : "eyes as the source says");
          break;
        case Command::calibration_grid:
          calibration = !calibration;
          try {
            if (current) renderer.upload(current, calibration);
          } catch (const TestPatternError& e) {
            calibration = false;
            if (current) renderer.upload(current, calibration);
            say(fmt::format("no calibration grid: {}", e.what()));
            break;
          }
          dirty = true;
          say(calibration ? "calibration grid on" : "calibration grid off");
          break;
        case Command::fullscreen:
          say(display.toggle_fullscreen());
          dirty = true;
          break;
        case Command::help: {
          // Each press shows the next line on screen; the first also prints them all.
          const std::vector<std::string> lines = key_help(KeyScope::play);
          if (help_line == 0 && !options.quiet)
            for (const std::string& line : lines) fmt::print(stderr, "nelf: key {}\n", line);
          say(lines[help_line++ % lines.size()]);
          dirty = true;
          break;
        }
        default:
          break;  // a calibrate command: not bound in play
      }
    }
    if (result.end == PlayEnd::quit_key) break;
    if (display.close_requested()) {
      result.end = PlayEnd::window_closed;
      break;
    }
    if (stop && stop->load()) {
      result.end = PlayEnd::interrupted;
      break;
    }

    const auto decided_at = Steady::now();
    const char* event = nullptr;
    double upload_s = 0.0, render_only_s = 0.0, present_s = 0.0;
    bool end = false;
    std::vector<double> queued = queue.snapshot(end);
    if (awaiting_seek && (!queued.empty() || end)) {
      awaiting_seek = false;
      show_while_paused = paused;
      if (!paused) {
        prime_ahead();
        clock->set_paused(false);
      }
    }
    bool finished = false;
    if (!awaiting_seek && (!(paused && started) || show_while_paused)) {
      // When this refresh will be seen: after the next vblank, or once rendered and presented.
      double visible_at = clock->now() + (display.vsync() ? refresh_period : render_s);
      // The clock waits, paused, for the first frame to be on screen; a stream whose video starts
      // later than its sound (mkv: video at 0.023 s, audio at 0) would wait for it for ever. The
      // first frame is the poster shown while the clock waits, whenever its pts.
      if (!started && !queued.empty()) visible_at = std::max(visible_at, queued.front());
      const FrameDecision d = scheduler.decide(visible_at, queued, end);
      if (d.drop > 0 || d.show_front) {
        auto frame = queue.pop(d.drop, d.show_front);
        if (frame) {
          show_while_paused = false;
          current = std::move(frame);
          const auto t = Steady::now();
          renderer.upload(current, calibration);
          if (log.enabled()) glFinish();  // so that the log says where the time goes
          upload_s = seconds_since(t);
          dirty = true;
          event = "shown";
        }
      }
      if (d.repeat) event = "repeated";
      finished = d.finished;
    }
    if (!message.empty() && Steady::now() > message_until) {
      message.clear();
      renderer.set_message("");
      dirty = true;
    }
    if (finished) break;

    bool ahead = false;
    if (dirty) {
      auto t = Steady::now();
      ahead = renderer.render(swap_eyes);
      if (ahead) ++result.composited_ahead;
      if (log.enabled()) glFinish();
      render_only_s = seconds_since(t);
      if (options.after_render) options.after_render(display, current ? current->pts_s : 0.0);
      t = Steady::now();
      try {
        display.present();
      } catch (const std::runtime_error& e) {
        throw UserError(fmt::format("the display was lost: {}", e.what()), 1);
      }
      present_s = seconds_since(t);
      dirty = false;
      if (started) {
        render_times.push_back(seconds_since(decided_at));
        if (render_times.size() > 9) render_times.pop_front();
        std::vector<double> sorted(render_times.begin(), render_times.end());
        std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
        render_s = sorted[sorted.size() / 2];
      }
      if (!started) {
        started = true;
        if (!paused && !awaiting_seek) {
          prime_ahead();
          clock->set_paused(false);
        }
      }
      if (!event) event = "redrawn";
    } else if (display.vsync()) {
      display.present();  // paces the loop at the refresh
    }
    if (event)
      log.write(refresh, event, current ? std::optional(current->pts_s) : std::nullopt, clock->now(),
                audio ? std::optional(audio->now()) : std::nullopt, scheduler.counters(), upload_s, render_only_s,
                present_s, queued.size(), ahead);
    ++refresh;

    // The next frames, composited on the worker while this thread waits for the next refresh; not
    // those whose time will have passed by then (the next refresh drops them): after a slow spell
    // the worker would otherwise spend itself on frames never shown.
    {
      const std::vector<FrameQueue::Frame> next = queue.front(queue_capacity);
      std::vector<double> next_pts;
      for (const auto& f : next) next_pts.push_back(f->pts_s);
      const double next_visible = clock->now() + refresh_period + (display.vsync() ? refresh_period : render_s);
      const std::size_t stale = scheduler.stale(next_visible, next_pts);
      renderer.composite_ahead(swap_eyes, std::span(next).subspan(stale));
    }

    if (!display.vsync()) {
      next_tick += std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(refresh_period));
      const auto now = Steady::now();
      if (next_tick < now - std::chrono::milliseconds(100)) next_tick = now;  // far behind: do not race
      std::this_thread::sleep_until(next_tick);
    }
  }

  queue.stop();
  decoder.join();
  if (feeder) result.audio_decode_errors = feeder->decode_errors();
  feeder.reset();
  result.counters = scheduler.counters();
  result.video_decode_errors = source.lost_frames();
  return result;
}

}  // namespace nelf
