#pragma once
// Composite tables kept on disk (like Mesa's shader cache), so that a conversion whose
// optics and view geometry were seen before starts without a GL context: on a machine without a
// GPU, loading llvmpipe and recording the tables is ~1 s of the start-up of `nelf convert`,
// against ~0.3 s for all of ffmpeg's. An entry holds its whole key (profile, eye, view geometry,
// shaders, nelf version) and is used only when that matches; entries are written atomically, and
// a cache that cannot be read or written is simply not used.
#include <array>
#include <filesystem>
#include <optional>
#include <string>

#include "compositor/cpu/composite_table.hpp"
#include "compositor/compositor.hpp"
#include "optics/profile.hpp"

namespace nelf {

// $NELF_CACHE_DIR, else $XDG_CACHE_HOME/nelf, else $HOME/.cache/nelf; with /composite-tables
// appended. Empty when none of them is set (no cache).
std::filesystem::path default_composite_table_cache();

// Everything a recording depends on, as text.
std::string composite_table_key(const Profile& profile, const CompositorOptions& options, Eye eye, int view_width,
                                int view_height, double aspect, std::array<int, 2> block);

class CompositeTableCache {
 public:
  explicit CompositeTableCache(std::filesystem::path directory = default_composite_table_cache())
      : directory_(std::move(directory)) {}

  // The table stored under `key`, if there is a readable one that holds together (an entry is
  // untrusted input: CompositeTable checks everything that indexes memory).
  std::optional<CompositeTable> load(const std::string& key) const;
  // Stores `table` (as built: its taps, so a load needs no make_tap per pixel) under `key`; false
  // (and nothing left behind) when that fails.
  bool store(const std::string& key, const CompositeTable& table) const;

  const std::filesystem::path& directory() const { return directory_; }

 private:
  std::filesystem::path path_for(const std::string& key) const;
  std::filesystem::path directory_;
};

class GlCompositor;

// The table for `eye` of `profile` and views of view_width×view_height at `aspect`, averaged in
// `block`: from `cache` when it holds a usable one, else recorded with `recorder` (when given) and
// stored in `cache`. Nothing when neither works (no entry and no recorder, or no table for these
// options: fsaa other than 1, whole views).
std::optional<CompositeTable> load_or_record_composite_table(const CompositeTableCache& cache, GlCompositor* recorder,
                                                             const Profile& profile, const CompositorOptions& options,
                                                             Eye eye, int view_width, int view_height, double aspect,
                                                             std::array<int, 2> block);

// True when the machine has a DRM render node (/dev/dri/renderD*): a GPU may be there, so the
// GL context decides between GL and the CPU table rather than a cached table.
bool has_render_node();

}  // namespace nelf
