#include "inputs/pipewire_capture.hpp"

#include <fmt/format.h>

// libpipewire's and SPA's headers and macros are C: compound literals and designated
// initialisers that -Wpedantic rejects in C++. Their use below is fenced the same way.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <pipewire/pipewire.h>
#include <spa/param/buffers.h>
#include <spa/param/video/format-utils.h>
#include <spa/pod/builder.h>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <condition_variable>
#include <cstring>
#include <map>
#include <mutex>
#include <vector>

#include "core/printable.hpp"
#include "core/user_error.hpp"
#include "inputs/pipewire_frame.hpp"
#include "inputs/screencast_portal.hpp"

namespace nelf {
namespace {

using Clock = std::chrono::steady_clock;

template <typename T>
bool parse_number(std::string_view text, T& value) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc() && end == text.data() + text.size();
}

constexpr const char* kKeys = "node=ID or NAME, fps=, wait=, restore=yes|no";

struct ThreadLoopDeleter {
  void operator()(pw_thread_loop* l) const { pw_thread_loop_destroy(l); }
};
struct ContextDeleter {
  void operator()(pw_context* c) const { pw_context_destroy(c); }
};
struct CoreDeleter {
  void operator()(pw_core* c) const { pw_core_disconnect(c); }
};
struct StreamDeleter {
  void operator()(pw_stream* s) const { pw_stream_destroy(s); }
};
struct ProxyDeleter {
  void operator()(pw_proxy* p) const { pw_proxy_destroy(p); }
};

// The video nodes the daemon announces.
struct NodeInfo {
  std::string name, description, media_class;
  std::string serial;  // object.serial: what target.object names (an id is reused, a serial is not)
};

std::string describe(unsigned id, const NodeInfo& node) {
  const std::string& label = node.description.empty() ? node.name : node.description;
  return fmt::format("{} \"{}\"{}", id, printable(label),
                     node.media_class.empty() ? "" : fmt::format(" ({})", node.media_class));
}

}  // namespace

bool is_pipewire_capture_spec(std::string_view input) {
  return input.rfind("pipewire:", 0) == 0 || input == "pipewire";
}

PipeWireCaptureSpec parse_pipewire_capture_spec(const std::string& input) {
  PipeWireCaptureSpec spec;
  std::string_view rest = input == "pipewire" ? std::string_view() : std::string_view(input).substr(9);
  while (!rest.empty()) {
    const std::size_t eq = rest.find('=');
    if (eq == std::string_view::npos) throw UserError(fmt::format("{}: expected key=value ({})", input, kKeys), 2);
    const std::string_view key = rest.substr(0, eq);
    const std::size_t comma = rest.find(',', eq);
    const std::string_view value =
        rest.substr(eq + 1, comma == std::string_view::npos ? std::string_view::npos : comma - eq - 1);
    rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
    const auto bad = [&](std::string_view what) {
      return UserError(fmt::format("{}: {}={} is not {}", input, key, value, what), 2);
    };
    if (key == "node") {
      if (value.empty()) throw bad("a node (its id or name, as pw-cli ls Node lists them)");
      unsigned id = 0;
      if (parse_number(value, id))
        spec.node_id = id;
      else
        spec.node_name = std::string(value);
    } else if (key == "wait") {
      double wait = 0;
      if (!parse_number(value, wait) || !(wait >= 0 && wait <= 3600)) throw bad("a time from 0 to 3600 seconds");
      spec.wait_s = wait;
    } else if (key == "fps") {
      double fps = 0;
      if (!parse_number(value, fps) || !(fps >= 1 && fps <= 1000)) throw bad("a rate from 1 to 1000 frames a second");
      spec.fps = fps;
    } else if (key == "restore") {
      if (value != "yes" && value != "no") throw bad("yes or no");
      spec.restore = value == "yes";
    } else {
      throw UserError(fmt::format("{}: unknown key {} ({})", input, key, kKeys), 2);
    }
  }
  if (spec.restore && (spec.node_id || !spec.node_name.empty()))
    throw UserError(fmt::format("{}: restore= is about the ScreenCast portal's kept choice; a node named with node= "
                                "has none",
                                input),
                    2);
  return spec;
}

struct PipeWireCapture::State {
  std::string input;
  PipeWireCaptureSpec spec;
  std::string description;
  // The portal's screen cast, when the node is its choice; ended after everything below.
  std::unique_ptr<ScreenCastPortal> portal;

  // Declared in the order they are made; ~State stops the loop's thread first, then they go in reverse.
  std::unique_ptr<pw_thread_loop, ThreadLoopDeleter> loop;
  std::unique_ptr<pw_context, ContextDeleter> context;
  std::unique_ptr<pw_core, CoreDeleter> core;
  std::unique_ptr<pw_proxy, ProxyDeleter> registry;
  std::unique_ptr<pw_stream, StreamDeleter> stream;
  std::unique_ptr<pw_proxy, ProxyDeleter> link;
  spa_hook core_listener{}, registry_listener{}, stream_listener{}, link_listener{};

  // Under the loop's lock (the loop thread's callbacks hold it).
  std::map<unsigned, NodeInfo> nodes;
  int sync_seq = -1;
  bool synced = false;
  unsigned target = 0;
  spa_video_info_raw format{};
  std::optional<PipeWireFrameReader> reader;  // for `format`, once negotiated
  std::string failure;                        // why the stream cannot go on (a link or daemon error)

  // Under `mutex`: the newest frame, for the reading thread.
  std::mutex mutex;
  std::condition_variable changed;
  std::optional<CapturedImage> latest;
  Clock::time_point last_kept{};
  std::atomic<bool> ended{false};

  ~State() {
    if (loop) pw_thread_loop_stop(loop.get());
  }

  void end(std::string why) {
    if (failure.empty()) failure = std::move(why);
    {
      const std::lock_guard lock(mutex);
      ended = true;
    }
    changed.notify_all();
    pw_thread_loop_signal(loop.get(), false);
  }

  // --- the daemon's events (the loop's thread) ---
  static void on_core_done(void* data, uint32_t id, int seq) {
    auto* s = static_cast<State*>(data);
    if (id == PW_ID_CORE && seq == s->sync_seq) {
      s->synced = true;
      pw_thread_loop_signal(s->loop.get(), false);
    }
  }
  static void on_core_error(void* data, uint32_t id, int /*seq*/, int res, const char* message) {
    auto* s = static_cast<State*>(data);
    if (id == PW_ID_CORE && res == -EPIPE)
      s->end("the PipeWire daemon went away");
    else if (id == PW_ID_CORE || (s->link && id == pw_proxy_get_id(s->link.get())))
      s->end(fmt::format("PipeWire: {}", message ? message : std::strerror(-res)));
  }
  static void on_global(void* data, uint32_t id, uint32_t /*permissions*/, const char* type, uint32_t /*version*/,
                        const spa_dict* props) {
    auto* s = static_cast<State*>(data);
    if (std::strcmp(type, PW_TYPE_INTERFACE_Node) != 0 || !props) return;
    const auto get = [&](const char* key) {
      const char* v = spa_dict_lookup(props, key);
      return std::string(v ? v : "");
    };
    s->nodes[id] = {get(PW_KEY_NODE_NAME), get(PW_KEY_NODE_DESCRIPTION), get(PW_KEY_MEDIA_CLASS),
                    get(PW_KEY_OBJECT_SERIAL)};
    pw_thread_loop_signal(s->loop.get(), false);
  }
  static void on_global_remove(void* data, uint32_t id) {
    auto* s = static_cast<State*>(data);
    s->nodes.erase(id);
    if (s->target != 0 && id == s->target) s->end("the node was removed");
  }
  static void on_stream_state(void* data, pw_stream_state /*old*/, pw_stream_state state, const char* error) {
    auto* s = static_cast<State*>(data);
    if (state == PW_STREAM_STATE_ERROR) s->end(fmt::format("PipeWire: {}", error ? error : "stream error"));
    if (state == PW_STREAM_STATE_PAUSED && !s->link && !s->portal) s->link_to_target();
  }
  static void on_link_info(void* data, const pw_link_info* info) {
    auto* s = static_cast<State*>(data);
    if (info->state == PW_LINK_STATE_ERROR)
      s->end(fmt::format("the link to the node failed ({}); nelf reads {} in shared memory",
                         info->error ? info->error : "no reason given", PipeWireFrameReader::formats_in_words()));
  }
  static void on_param_changed(void* data, uint32_t id, const spa_pod* param) {
    auto* s = static_cast<State*>(data);
    if (id != SPA_PARAM_Format || !param) return;
    uint32_t media_type = 0, media_subtype = 0;
    if (spa_format_parse(param, &media_type, &media_subtype) < 0 || media_type != SPA_MEDIA_TYPE_video ||
        media_subtype != SPA_MEDIA_SUBTYPE_raw)
      return;
    s->format = {};
    if (spa_format_video_raw_parse(param, &s->format) < 0) return;
    s->reader.emplace(s->format);
    // Buffers nelf can read with the CPU: shared memory, mapped (DMA-BUF import is not done yet).
    std::uint8_t bytes[256];
    spa_pod_builder b = SPA_POD_BUILDER_INIT(bytes, sizeof bytes);
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
    const auto* buffers = static_cast<const spa_pod*>(
        spa_pod_builder_add_object(&b, SPA_TYPE_OBJECT_ParamBuffers, SPA_PARAM_Buffers, SPA_PARAM_BUFFERS_dataType,
                                   SPA_POD_CHOICE_FLAGS_Int((1 << SPA_DATA_MemPtr) | (1 << SPA_DATA_MemFd))));
#pragma GCC diagnostic pop
    pw_stream_update_params(s->stream.get(), &buffers, 1);
  }
  static void on_process(void* data) {
    auto* s = static_cast<State*>(data);
    pw_buffer* buffer = pw_stream_dequeue_buffer(s->stream.get());
    if (!buffer) return;
    while (pw_buffer* newer = pw_stream_dequeue_buffer(s->stream.get())) {  // only the newest counts
      pw_stream_queue_buffer(s->stream.get(), buffer);
      buffer = newer;
    }
    s->keep(*buffer->buffer);
    pw_stream_queue_buffer(s->stream.get(), buffer);
  }

  void link_to_target() {
    const std::string output = std::to_string(target);
    const std::string input_node = std::to_string(pw_stream_get_node_id(stream.get()));
    const spa_dict_item items[] = {{PW_KEY_LINK_OUTPUT_NODE, output.c_str()},
                                   {PW_KEY_LINK_INPUT_NODE, input_node.c_str()},
                                   {PW_KEY_OBJECT_LINGER, "false"}};
    const spa_dict props = SPA_DICT_INIT(items, 3);
    link.reset(static_cast<pw_proxy*>(
        pw_core_create_object(core.get(), "link-factory", PW_TYPE_INTERFACE_Link, PW_VERSION_LINK, &props, 0)));
    if (!link) return end("cannot create a link to the node");
    static const pw_link_events events = [] {
      pw_link_events e{};
      e.version = PW_VERSION_LINK_EVENTS;
      e.info = on_link_info;
      return e;
    }();
    pw_proxy_add_object_listener(link.get(), &link_listener, &events, this);
  }

  // The frame in `buffer` as RGBA, when it holds one and the rate allows.
  void keep(const spa_buffer& buffer) {
    if (!reader || !reader->readable()) return;
    const auto now = Clock::now();
    if (now - last_kept < std::chrono::duration<double>(0.9 / spec.fps)) return;
    std::optional<CapturedImage> converted = reader->read(buffer);
    if (!converted) return;
    converted->captured_at = Clock::now();
    last_kept = now;
    {
      const std::lock_guard lock(mutex);
      latest = std::move(converted);
    }
    changed.notify_all();
  }

  // Waits on the loop (its lock held) until `done`, the deadline, or a stop; false at the deadline.
  template <typename Done>
  bool wait_for(Done done, Clock::time_point deadline, const std::atomic<bool>* stop) {
    while (!done()) {
      if (stop && *stop) throw UserError(fmt::format("{}: interrupted", printable(input)), 130);
      if (Clock::now() >= deadline) return false;
      timespec abstime{};
      pw_thread_loop_get_time(loop.get(), &abstime, 50 * SPA_NSEC_PER_MSEC);
      pw_thread_loop_timed_wait_full(loop.get(), &abstime);
    }
    return true;
  }

  // Finds the node spec names among those announced; throws when a name matches several.
  std::optional<unsigned> find_target() const {
    if (spec.node_id) return nodes.count(*spec.node_id) ? spec.node_id : std::nullopt;
    std::vector<unsigned> matches;
    for (const auto& [id, node] : nodes)
      if (node.name == spec.node_name || node.description == spec.node_name) matches.push_back(id);
    if (matches.size() > 1) {
      std::string list;
      for (unsigned id : matches) list += (list.empty() ? "" : ", ") + describe(id, nodes.at(id));
      throw UserError(fmt::format("{}: several PipeWire nodes are named so: {}; choose one with pipewire:node=ID",
                                  printable(input), list),
                      2);
    }
    return matches.empty() ? std::nullopt : std::optional(matches.front());
  }

  std::string video_nodes() const {
    std::string list;
    for (const auto& [id, node] : nodes)
      if (node.media_class.rfind("Video/", 0) == 0 || node.media_class == "Stream/Output/Video")
        list += (list.empty() ? "" : ", ") + describe(id, node);
    return list.empty() ? "none" : list;
  }
};

PipeWireCapture::PipeWireCapture(const PipeWireCaptureSpec& spec, std::string input, const std::atomic<bool>* stop)
    : state_(std::make_unique<State>()) {
  static std::once_flag initialised;
  std::call_once(initialised, [] { pw_init(nullptr, nullptr); });
  State& s = *state_;
  s.input = std::move(input);
  s.spec = spec;
  const std::string& in = s.input;

  s.loop.reset(pw_thread_loop_new("nelf-pipewire", nullptr));
  if (!s.loop) throw UserError(fmt::format("{}: cannot start PipeWire's loop", printable(in)), 1);
  s.context.reset(pw_context_new(pw_thread_loop_get_loop(s.loop.get()), nullptr, 0));
  if (!s.context) throw UserError(fmt::format("{}: cannot create a PipeWire context", printable(in)), 1);
  if (pw_thread_loop_start(s.loop.get()) < 0)
    throw UserError(fmt::format("{}: cannot start PipeWire's loop", printable(in)), 1);

  // Without a node, the user's choice in the desktop's dialog, before anything waits on the loop.
  if (!spec.node_id && spec.node_name.empty()) {
    s.portal = std::make_unique<ScreenCastPortal>(ScreenCastPortalOptions{spec.restore.value_or(true)}, s.input, stop);
    s.spec.node_id = s.portal->node_id();
  }

  pw_thread_loop_lock(s.loop.get());
  struct Unlock {
    pw_thread_loop* loop;
    ~Unlock() { pw_thread_loop_unlock(loop); }
  } unlock{s.loop.get()};

  if (s.portal) {
    UniqueFd fd = s.portal->take_pipewire_fd();
    s.core.reset(pw_context_connect_fd(s.context.get(), fd.release(), nullptr, 0));
    if (!s.core)
      throw UserError(fmt::format("{}: cannot connect to PipeWire through the portal's connection ({})", printable(in),
                                  std::strerror(errno)),
                      1);
  } else {
    s.core.reset(pw_context_connect(s.context.get(), nullptr, 0));
  }
  if (!s.core)
    throw UserError(fmt::format("{}: cannot connect to PipeWire ({}); is its daemon running in this session?",
                                printable(in), std::strerror(errno)),
                    1);
  static const pw_core_events core_events = [] {
    pw_core_events e{};
    e.version = PW_VERSION_CORE_EVENTS;
    e.done = State::on_core_done;
    e.error = State::on_core_error;
    return e;
  }();
  pw_core_add_listener(s.core.get(), &s.core_listener, &core_events, &s);
  s.registry.reset(reinterpret_cast<pw_proxy*>(pw_core_get_registry(s.core.get(), PW_VERSION_REGISTRY, 0)));
  static const pw_registry_events registry_events = [] {
    pw_registry_events e{};
    e.version = PW_VERSION_REGISTRY_EVENTS;
    e.global = State::on_global;
    e.global_remove = State::on_global_remove;
    return e;
  }();
  pw_registry_add_listener(reinterpret_cast<pw_registry*>(s.registry.get()), &s.registry_listener, &registry_events,
                           &s);
  s.sync_seq = pw_core_sync(s.core.get(), PW_ID_CORE, 0);

  // The node: every global is announced before the sync's reply; then wait= for one still to come.
  const auto start = Clock::now();
  std::optional<unsigned> target;
  s.wait_for([&] { return s.synced || !s.failure.empty(); }, start + std::chrono::seconds(10), stop);
  if (!s.failure.empty()) throw UserError(fmt::format("{}: {}", printable(in), s.failure), 1);
  s.wait_for([&] { return (target = s.find_target()).has_value(); },
             start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(spec.wait_s)), stop);
  if (!target && s.portal)
    throw UserError(fmt::format("{}: the screen cast's PipeWire node {} is not visible through the portal's "
                                "connection",
                                printable(in), *s.spec.node_id),
                    1);
  if (!target)
    throw UserError(fmt::format("{}: no PipeWire node {}{}; the video nodes: {}", printable(in),
                                spec.node_id ? std::to_string(*spec.node_id) : printable(spec.node_name),
                                spec.wait_s > 0 ? fmt::format(" after {} s", spec.wait_s) : "", s.video_nodes()),
                    1);
  s.target = *target;
  s.description = s.portal
                      ? fmt::format("the desktop's screen cast{} (PipeWire node {})",
                                    s.portal->source_type().empty() ? "" : " of a " + s.portal->source_type(), s.target)
                      : fmt::format("PipeWire node {}", describe(s.target, s.nodes.at(s.target)));

  // nelf's input stream: linked to a named node by nelf itself (not left to a session manager); the
  // portal's connection sees nothing but the cast's node, so that link is the session manager's.
  pw_properties* stream_props = pw_properties_new(PW_KEY_MEDIA_TYPE, "Video", PW_KEY_MEDIA_CATEGORY, "Capture",
                                                  PW_KEY_MEDIA_ROLE, "Screen", nullptr);
  if (s.portal && !s.nodes.at(s.target).serial.empty())
    pw_properties_set(stream_props, PW_KEY_TARGET_OBJECT, s.nodes.at(s.target).serial.c_str());
  s.stream.reset(pw_stream_new(s.core.get(), "nelf", stream_props));
  if (!s.stream) throw UserError(fmt::format("{}: cannot create a PipeWire stream", printable(in)), 1);
  static const pw_stream_events stream_events = [] {
    pw_stream_events e{};
    e.version = PW_VERSION_STREAM_EVENTS;
    e.state_changed = State::on_stream_state;
    e.param_changed = State::on_param_changed;
    e.process = State::on_process;
    return e;
  }();
  pw_stream_add_listener(s.stream.get(), &s.stream_listener, &stream_events, &s);
  std::uint8_t bytes[1024];
  spa_pod_builder b = SPA_POD_BUILDER_INIT(bytes, sizeof bytes);
  spa_rectangle size_default = SPA_RECTANGLE(1920, 1080), size_min = SPA_RECTANGLE(1, 1),
                size_max = SPA_RECTANGLE(16384, 16384);
  spa_fraction rate_default = SPA_FRACTION(60, 1), rate_min = SPA_FRACTION(0, 1), rate_max = SPA_FRACTION(1000, 1);
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
  // The formats PipeWireFrameReader reads, its first the default.
  const std::vector<spa_video_format> readable = PipeWireFrameReader::formats();
  spa_pod_frame object{}, choice{};
  spa_pod_builder_push_object(&b, &object, SPA_TYPE_OBJECT_Format, SPA_PARAM_EnumFormat);
  spa_pod_builder_add(&b, SPA_FORMAT_mediaType, SPA_POD_Id(SPA_MEDIA_TYPE_video), SPA_FORMAT_mediaSubtype,
                      SPA_POD_Id(SPA_MEDIA_SUBTYPE_raw), 0);
  spa_pod_builder_prop(&b, SPA_FORMAT_VIDEO_format, 0);
  spa_pod_builder_push_choice(&b, &choice, SPA_CHOICE_Enum, 0);
  spa_pod_builder_id(&b, readable.front());
  for (const spa_video_format f : readable) spa_pod_builder_id(&b, f);
  spa_pod_builder_pop(&b, &choice);
  spa_pod_builder_add(&b, SPA_FORMAT_VIDEO_size, SPA_POD_CHOICE_RANGE_Rectangle(&size_default, &size_min, &size_max),
                      SPA_FORMAT_VIDEO_framerate, SPA_POD_CHOICE_RANGE_Fraction(&rate_default, &rate_min, &rate_max),
                      0);
  const auto* formats = static_cast<const spa_pod*>(spa_pod_builder_pop(&b, &object));
#pragma GCC diagnostic pop
  const auto flags = static_cast<pw_stream_flags>(PW_STREAM_FLAG_MAP_BUFFERS |
                                                  (s.portal ? PW_STREAM_FLAG_AUTOCONNECT : PW_STREAM_FLAG_NONE));
  if (pw_stream_connect(s.stream.get(), PW_DIRECTION_INPUT, s.portal ? s.target : PW_ID_ANY, flags, &formats, 1) < 0)
    throw UserError(fmt::format("{}: cannot connect a PipeWire stream", printable(in)), 1);
}

PipeWireCapture::~PipeWireCapture() = default;

CapturedImage PipeWireCapture::read() {
  // The first frame: the link, the format's negotiation and the node's next frame, within 10 s.
  State& s = *state_;
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  while (Clock::now() < deadline) {
    if (auto image = read_when_changed(std::chrono::milliseconds(50))) return std::move(*image);
    if (s.ended) break;
  }
  pw_thread_loop_lock(s.loop.get());
  std::string why = s.failure;
  const bool negotiated = s.format.size.width > 0;
  const bool readable = s.reader && s.reader->readable();
  pw_thread_loop_unlock(s.loop.get());
  if (why.empty() && negotiated && !readable)
    why = "it sends a pixel format nelf does not read (8-bit RGB or YUV only)";
  if (why.empty() && !negotiated && s.portal)
    why =
        "nothing linked nelf to the cast's node in 10 s (the desktop's session manager does: is WirePlumber or "
        "pipewire-media-session running?)";
  if (why.empty()) why = "no frame came from the node in 10 s (is it producing? a paused game sends none)";
  throw UserError(fmt::format("{}: {}: {}", printable(s.input), s.description, why), 1);
}

std::optional<CapturedImage> PipeWireCapture::read_when_changed(std::chrono::milliseconds wait) {
  State& s = *state_;
  std::unique_lock lock(s.mutex);
  s.changed.wait_for(lock, wait, [&] { return s.latest.has_value() || s.ended.load(); });
  if (!s.latest) return std::nullopt;
  std::optional<CapturedImage> out = std::move(s.latest);
  s.latest.reset();
  return out;
}

bool PipeWireCapture::closed() const { return state_->ended; }

const std::string& PipeWireCapture::description() const { return state_->description; }

}  // namespace nelf
