#include "compositor/cpu/composite_table_cache.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <type_traits>
#include <vector>

#include "compositor/gl/gl_compositor.hpp"
#include "core/embedded.hpp"

namespace nelf {

namespace {

// Version 2 holds the built table (taps, not texture coordinates), so a load skips make_tap;
// version 3 the depth-aware composite's rays after it (a flag, then those where it is 1).
constexpr char kMagic[8] = {'N', 'E', 'L', 'F', 'C', 'T', '3', '\n'};
constexpr std::uint64_t kMaxElements = std::uint64_t{1} << 28;  // far beyond any panel

std::uint64_t fnv1a(const std::string& text) {
  std::uint64_t hash = 14695981039346656037ull;
  for (unsigned char c : text) hash = (hash ^ c) * 1099511628211ull;
  return hash;
}

class Writer {
 public:
  explicit Writer(std::ofstream& out) : out_(out) {}
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.write(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <class T>
  void vector(const std::vector<T>& v) {
    value(static_cast<std::uint64_t>(v.size()));
    out_.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
  }
  void string(const std::string& s) {
    value(static_cast<std::uint64_t>(s.size()));
    out_.write(s.data(), static_cast<std::streamsize>(s.size()));
  }

 private:
  std::ofstream& out_;
};

class Reader {
 public:
  explicit Reader(std::ifstream& in) : in_(in) {
    in_.seekg(0, std::ios::end);
    end_ = in_.tellg();
    in_.seekg(0);
  }
  template <class T>
  bool value(T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    return static_cast<bool>(in_.read(reinterpret_cast<char*>(&v), sizeof v));
  }
  template <class T>
  bool vector(std::vector<T>& v) {
    std::uint64_t size = 0;
    if (!value(size) || size > kMaxElements || !fits(size * sizeof(T))) return false;
    v.resize(size);
    return static_cast<bool>(
        in_.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(size * sizeof(T))));
  }
  bool string(std::string& s) {
    std::uint64_t size = 0;
    if (!value(size) || size > kMaxElements || !fits(size)) return false;
    s.resize(size);
    return static_cast<bool>(in_.read(s.data(), static_cast<std::streamsize>(size)));
  }

 private:
  // Whether `bytes` more are in the file: a damaged size allocates nothing.
  bool fits(std::uint64_t bytes) {
    const std::streamoff at = in_.tellg();
    return at >= 0 && end_ >= at && bytes <= static_cast<std::uint64_t>(end_ - at);
  }
  std::ifstream& in_;
  std::streamoff end_ = 0;
};

void write_axis(Writer& w, const BoxAxis& axis) {
  w.vector(axis.first);
  w.vector(axis.begin);
  w.vector(axis.weights);
}
bool read_axis(Reader& r, BoxAxis& axis) {
  return r.vector(axis.first) && r.vector(axis.begin) && r.vector(axis.weights);
}

}  // namespace

std::filesystem::path default_composite_table_cache() {
  const auto set = [](const char* name) -> const char* {
    const char* value = std::getenv(name);
    return value && *value ? value : nullptr;
  };
  std::filesystem::path base;
  if (const char* dir = set("NELF_CACHE_DIR"))
    base = dir;
  else if (const char* xdg = set("XDG_CACHE_HOME"))
    base = std::filesystem::path(xdg) / "nelf";
  else if (const char* home = set("HOME"))
    base = std::filesystem::path(home) / ".cache" / "nelf";
  else
    return {};
  return base / "composite-tables";
}

std::string composite_table_key(const Profile& profile, const CompositorOptions& options, Eye eye, int view_width,
                                int view_height, double aspect, std::array<int, 2> block) {
  // The shaders that record the table are part of the key: a changed shader is a new table.
  std::string shaders;
  for (const char* name : {"elemental.frag", "border_strips.vert", "fullscreen.vert", "mapping.glsl"})
    shaders += std::string(embedded::find(embedded::nelf_embedded_shaders(), name).value_or(""));
  // With depth on, the table holds the depth-aware rays as well (any mode: they do not depend on it).
  return fmt::format("nelf {}\nfsaa {} eye {} view {}x{} aspect {:.17g} block {}x{} depth rays {}\nshaders {:016x}\n{}",
                     NELF_VERSION, options.fsaa, static_cast<int>(eye), view_width, view_height, aspect, block[0],
                     block[1], options.depth != DepthMode::off ? 1 : 0, fnv1a(shaders), profile_to_toml(profile));
}

std::filesystem::path CompositeTableCache::path_for(const std::string& key) const {
  return directory_ / fmt::format("{:016x}.table", fnv1a(key));
}

std::optional<CompositeTable> CompositeTableCache::load(const std::string& key) const {
  if (directory_.empty()) return std::nullopt;
  std::ifstream in(path_for(key), std::ios::binary);
  if (!in) return std::nullopt;
  Reader r(in);
  char magic[sizeof kMagic] = {};
  std::string stored_key;
  if (!in.read(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof magic) != 0 || !r.string(stored_key) ||
      stored_key != key)
    return std::nullopt;
  CompositeTable::Built built;
  if (!r.value(built.panel) || !r.value(built.reduced) || !r.value(built.prefiltered) ||
      !read_axis(r, built.horizontal) || !read_axis(r, built.vertical) || !r.vector(built.taps) ||
      !r.vector(built.borders))
    return std::nullopt;
  std::uint8_t has_depth = 0;
  if (!r.value(has_depth) || has_depth > 1) return std::nullopt;
  if (has_depth) {
    CompositeTable::DepthTable depth;
    if (!r.vector(depth.rays) || !r.vector(depth.borders) || !r.value(depth.texture_scale) ||
        !r.value(depth.texture_offset))
      return std::nullopt;
    built.depth = std::move(depth);
  }
  try {
    return CompositeTable(std::move(built));  // which checks everything that indexes memory
  } catch (const std::exception&) {           // inconsistent, or sizes too large to allocate
    return std::nullopt;
  }
}

bool CompositeTableCache::store(const std::string& key, const CompositeTable& table) const {
  if (directory_.empty()) return false;
  std::error_code ec;
  std::filesystem::create_directories(directory_, ec);
  if (ec) return false;
  const std::filesystem::path path = path_for(key);
  const std::filesystem::path temporary = path.string() + fmt::format(".{}.tmp", ::getpid());
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) return false;
    Writer w(out);
    out.write(kMagic, sizeof kMagic);
    w.string(key);
    const CompositeTable::Built& built = table.built();
    w.value(built.panel);
    w.value(built.reduced);
    w.value(built.prefiltered);
    write_axis(w, built.horizontal);
    write_axis(w, built.vertical);
    w.vector(built.taps);
    w.vector(built.borders);
    w.value(static_cast<std::uint8_t>(built.depth ? 1 : 0));
    if (built.depth) {
      w.vector(built.depth->rays);
      w.vector(built.depth->borders);
      w.value(built.depth->texture_scale);
      w.value(built.depth->texture_offset);
    }
    out.flush();
    if (!out) {
      out.close();
      std::filesystem::remove(temporary, ec);
      return false;
    }
  }
  std::filesystem::rename(temporary, path, ec);  // atomic: readers see the old entry or the whole new one
  if (!ec) return true;
  std::filesystem::remove(temporary, ec);
  return false;
}

std::optional<CompositeTable> load_or_record_composite_table(const CompositeTableCache& cache, GlCompositor* recorder,
                                                             const Profile& profile, const CompositorOptions& options,
                                                             Eye eye, int view_width, int view_height, double aspect,
                                                             std::array<int, 2> block) {
  const std::string key = composite_table_key(profile, options, eye, view_width, view_height, aspect, block);
  // An entry for this key describes these views; one that does not (or does not hold together:
  // load checks that) is recorded again.
  const std::array<int, 2> reduced{view_width / block[0], view_height / block[1]};
  if (auto table = cache.load(key);
      table && table->panel() == profile.display.resolution && table->reduced_size() == reduced)
    return table;
  if (!recorder) return std::nullopt;
  auto table = recorder->make_composite_table(eye, view_width, view_height, aspect, block);
  if (table) cache.store(key, *table);
  return table;
}

bool has_render_node() {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/dev/dri", ec))
    if (entry.path().filename().string().rfind("renderD", 0) == 0) return true;
  return false;
}

}  // namespace nelf
