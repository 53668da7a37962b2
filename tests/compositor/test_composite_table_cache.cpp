// The composite-table cache: what is stored comes back whole under its key only; damaged, foreign
// or missing entries and an unusable directory mean "not cached", never an error or a wrong table.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "compositor/cpu/composite_table_cache.hpp"
#include "optics/depth.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

CompositeTable::Recording small_recording() {
  CompositeTable::Recording r;
  r.panel = {3, 2};
  r.reduced = {2, 2};
  r.prefiltered = {4, 3};
  r.horizontal = make_box_axis(4, -1.0, 1.0, 1.5, 1.0, 2, 2.0);
  r.vertical = make_box_axis(3, -0.5, 1.0, 1.5, 1.0, 2, 2.0);
  r.coordinates = {0.1f, 0.2f, 0.3f, 0.4f, -1.f, -1.f, 0.5f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f};
  r.border_pixels = {1, 4};
  r.border_parts = {{{{0.1f, 0.2f, 0.75f}, {0.3f, 0.4f, 0.25f}, {}, {}}}, {{{0.5f, 0.5f, 1.f}, {}, {}, {}}}};
  return r;
}

// small_recording() with the depth-aware rays: pixel 2 black, the border parts taking pixel 0's
// and pixel 4's crossings.
CompositeTable::Recording small_depth_recording() {
  CompositeTable::Recording r = small_recording();
  CompositeTable::Recording::DepthRecording d;
  d.rays = {0.1f, 0.2f, 1.f, 0.f, 0.3f, 0.4f, -1.f, 0.5f, -1e9f, -1e9f, 0.f, 0.f,
            0.5f, 0.5f, 0.f, 1.f, 0.6f, 0.7f, 2.f,  -1.f, 0.8f,  0.9f,  0.f, 0.f};
  d.border_parts = {{{{0.1f, 0.2f, 1.f, 0.f, 0.75f, 0}, {0.3f, 0.4f, -1.f, 0.f, 0.25f, 4}, {}, {}}},
                    {{{0.5f, 0.5f, 0.f, 1.f, 1.f, 4}, {}, {}, {}}}};
  d.parallax_gain = {0.02f, -0.03f};
  d.texture_scale = {0.5f, 0.5f};
  d.texture_offset = {0.25f, 0.25f};
  r.depth = d;
  return r;
}

// A rough surface for the small tables: values from behind the screen to in front of it.
DisparitySurface small_surface() {
  ViewDisparity d{8, 6, std::vector<float>(48)};
  for (std::size_t i = 0; i < d.d.size(); ++i) d.d[i] = static_cast<float>(static_cast<int>(i * 7 % 11) - 4);
  return DisparitySurface(d);
}

// A small image to render: RGBA8 block means, `size` of them.
std::vector<std::uint8_t> test_means(std::array<int, 2> size) {
  std::vector<std::uint8_t> means(static_cast<std::size_t>(size[0]) * size[1] * 4);
  for (std::size_t i = 0; i < means.size(); ++i) means[i] = static_cast<std::uint8_t>(i % 4 == 3 ? 255 : 37 * i + 11);
  return means;
}

std::vector<std::uint8_t> rendered(CompositeTable& table, const DisparitySurface* surface = nullptr) {
  const auto panel = table.panel();
  std::vector<std::uint8_t> out(static_cast<std::size_t>(panel[0]) * panel[1] * 4, 0);
  const auto means = test_means(table.reduced_size());
  table.render(means.data(), static_cast<std::size_t>(table.reduced_size()[0]) * 4, out.data(),
               static_cast<std::size_t>(panel[0]) * 4, ChannelOrder::rgba, surface);
  return out;
}

void expect_same(const CompositeTable& a, const CompositeTable& b) {
  const CompositeTable::Built &x = a.built(), &y = b.built();
  EXPECT_EQ(x.panel, y.panel);
  EXPECT_EQ(x.reduced, y.reduced);
  EXPECT_EQ(x.prefiltered, y.prefiltered);
  EXPECT_EQ(x.horizontal.first, y.horizontal.first);
  EXPECT_EQ(x.horizontal.begin, y.horizontal.begin);
  EXPECT_EQ(x.horizontal.weights, y.horizontal.weights);
  EXPECT_EQ(x.vertical.weights, y.vertical.weights);
  ASSERT_EQ(x.taps.size(), y.taps.size());
  for (std::size_t i = 0; i < x.taps.size(); ++i) {
    EXPECT_EQ(x.taps[i].texel, y.taps[i].texel);
    EXPECT_EQ(x.taps[i].weights, y.taps[i].weights);
  }
  ASSERT_EQ(x.borders.size(), y.borders.size());
  for (std::size_t i = 0; i < x.borders.size(); ++i) {
    EXPECT_EQ(x.borders[i].x, y.borders[i].x);
    EXPECT_EQ(x.borders[i].y, y.borders[i].y);
    EXPECT_EQ(x.borders[i].weights, y.borders[i].weights);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(x.borders[i].taps[k].texel, y.borders[i].taps[k].texel);
  }
}

TEST(CompositeTableCache, StoredTableComesBackWholeUnderItsKeyOnly) {
  test::TempDir dir;
  const CompositeTableCache cache(dir / "tables");
  CompositeTable table(small_recording());
  EXPECT_FALSE(cache.load("key one"));
  ASSERT_TRUE(cache.store("key one", table));
  auto loaded = cache.load("key one");
  ASSERT_TRUE(loaded);
  expect_same(*loaded, table);
  EXPECT_FALSE(cache.load("key two"));
  // The loaded table renders what the one built from the recording does.
  EXPECT_EQ(loaded->panel(), (std::array<int, 2>{3, 2}));
  EXPECT_EQ(rendered(*loaded), rendered(table));
  // Nothing but the entry (no temporary file) is left in the directory.
  EXPECT_EQ(test::files_in(dir / "tables").size(), 1u);
}

TEST(CompositeTableCache, DepthRaysComeBackAndRenderTheSame) {
  test::TempDir dir;
  const CompositeTableCache cache(dir.path());
  CompositeTable table(small_depth_recording());
  ASSERT_TRUE(table.has_depth());
  ASSERT_TRUE(cache.store("depth", table));
  auto loaded = cache.load("depth");
  ASSERT_TRUE(loaded);
  ASSERT_TRUE(loaded->has_depth());
  expect_same(*loaded, table);
  const DisparitySurface surface = small_surface();
  EXPECT_EQ(rendered(*loaded, &surface), rendered(table, &surface));
  EXPECT_NE(rendered(table, &surface), rendered(table)) << "the surface must move what the rays show";
  // A table without the rays stays without them.
  ASSERT_TRUE(cache.store("flat", CompositeTable(small_recording())));
  EXPECT_FALSE(cache.load("flat")->has_depth());
}

TEST(CompositeTableCache, InconsistentDepthRaysAreRefused) {
  const auto refused = [](const std::function<void(CompositeTable::Built&)>& damage) {
    CompositeTable::Built built = CompositeTable(small_depth_recording()).built();
    damage(built);
    EXPECT_THROW(CompositeTable{std::move(built)}, std::invalid_argument);
  };
  refused([](auto& b) { b.depth->rays.pop_back(); });
  refused([](auto& b) { b.depth->rays[1].gain_u = std::numeric_limits<float>::infinity(); });
  refused([](auto& b) { b.depth->rays[3].v = std::numeric_limits<float>::quiet_NaN(); });
  refused([](auto& b) { b.depth->borders[0].hit_pixels[1] = 6; });  // past the 3×2 panel
  refused([](auto& b) { b.depth->borders[0].hit_pixels[0] = -1; });
  refused([](auto& b) { b.depth->borders[1].x = 3; });
  refused([](auto& b) { b.depth->texture_scale[0] = std::numeric_limits<float>::quiet_NaN(); });
  CompositeTable::Recording mismatched = small_depth_recording();
  mismatched.depth->border_parts.pop_back();
  EXPECT_THROW(CompositeTable{mismatched}, std::invalid_argument);
}

TEST(CompositeTableCache, DamagedEntriesAreNotUsed) {
  test::TempDir dir;
  const CompositeTableCache cache(dir.path());
  ASSERT_TRUE(cache.store("key", CompositeTable(small_recording())));
  const auto entry = dir / test::files_in(dir.path()).at(0);
  const auto size = std::filesystem::file_size(entry);
  std::filesystem::resize_file(entry, size - 5);  // truncated
  EXPECT_FALSE(cache.load("key"));
  {
    std::ofstream out(entry, std::ios::binary | std::ios::trunc);
    out << "not a table at all";
  }
  EXPECT_FALSE(cache.load("key"));
  ASSERT_TRUE(cache.store("key", CompositeTable(small_recording())));  // a new store replaces the damaged one
  EXPECT_TRUE(cache.load("key"));
}

TEST(CompositeTableCache, UnusableDirectoryMeansNoCache) {
  test::TempDir dir;
  test::write_file(dir / "file", "x");
  const CompositeTableCache under_a_file(dir / "file" / "tables");
  EXPECT_FALSE(under_a_file.store("key", CompositeTable(small_recording())));
  EXPECT_FALSE(under_a_file.load("key"));
  const CompositeTableCache none{std::filesystem::path{}};
  EXPECT_FALSE(none.store("key", CompositeTable(small_recording())));
  EXPECT_FALSE(none.load("key"));
}

TEST(CompositeTableCache, KeyNamesWhatTheTableDependsOn) {
  const Profile hmz = load_profile("hmz-t1");
  Profile shifted = hmz;
  shifted.calibration[0].shift_px = {1.0, 0.0};
  const CompositorOptions fsaa1{1, std::nullopt};
  const std::string key = composite_table_key(hmz, fsaa1, Eye::left, 960, 1080, 16.0 / 9.0, {2, 4});
  EXPECT_EQ(key, composite_table_key(hmz, fsaa1, Eye::left, 960, 1080, 16.0 / 9.0, {2, 4}));
  EXPECT_NE(key, composite_table_key(hmz, fsaa1, Eye::right, 960, 1080, 16.0 / 9.0, {2, 4}));
  EXPECT_NE(key, composite_table_key(hmz, fsaa1, Eye::left, 1920, 1080, 16.0 / 9.0, {2, 4}));
  EXPECT_NE(key, composite_table_key(hmz, fsaa1, Eye::left, 960, 1080, 4.0 / 3.0, {2, 4}));
  EXPECT_NE(key, composite_table_key(shifted, fsaa1, Eye::left, 960, 1080, 16.0 / 9.0, {2, 4}));
  // With depth on the table holds the depth-aware rays too; which mode does not matter.
  const CompositorOptions estimate{1, std::nullopt, DepthMode::estimate},
      automatic{1, std::nullopt, DepthMode::automatic};
  const std::string depth_key = composite_table_key(hmz, estimate, Eye::left, 960, 1080, 16.0 / 9.0, {2, 4});
  EXPECT_NE(key, depth_key);
  EXPECT_EQ(depth_key, composite_table_key(hmz, automatic, Eye::left, 960, 1080, 16.0 / 9.0, {2, 4}));
}

TEST(CompositeTableCache, DefaultDirectoryFollowsTheEnvironment) {
  const char* saved = std::getenv("NELF_CACHE_DIR");
  const std::string restore = saved ? saved : "";
  setenv("NELF_CACHE_DIR", "/somewhere", 1);
  EXPECT_EQ(default_composite_table_cache(), std::filesystem::path("/somewhere/composite-tables"));
  unsetenv("NELF_CACHE_DIR");
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  if (!xdg || !*xdg) {
    EXPECT_EQ(default_composite_table_cache(),
              std::filesystem::path(std::getenv("HOME")) / ".cache" / "nelf" / "composite-tables");
  }
  if (saved) setenv("NELF_CACHE_DIR", restore.c_str(), 1);
}

}  // namespace
}  // namespace nelf

namespace nelf {
namespace {

// A recording read from a damaged or foreign cache file must not index outside its buffers.
TEST(CompositeTableCache, InconsistentRecordingsAreRefusedByTheTable) {
  EXPECT_NO_THROW(CompositeTable{small_recording()});
  auto bad = small_recording();
  bad.horizontal.first[1] = 5;  // beyond the 2 input cells
  EXPECT_THROW(CompositeTable{bad}, std::invalid_argument);
  bad = small_recording();
  bad.border_pixels[1] = 6;  // the panel has 6 pixels
  EXPECT_THROW(CompositeTable{bad}, std::invalid_argument);
  bad = small_recording();
  bad.coordinates.pop_back();
  EXPECT_THROW(CompositeTable{bad}, std::invalid_argument);
  bad = small_recording();
  bad.vertical.begin.back() = 99;
  EXPECT_THROW(CompositeTable{bad}, std::invalid_argument);
}

// A built table (what a cache entry holds) must not index outside its buffers either.
TEST(CompositeTableCache, InconsistentBuiltTablesAreRefused) {
  const CompositeTable table(small_recording());
  const CompositeTable::Built good = table.built();
  const std::int32_t texels = good.prefiltered[0] * good.prefiltered[1];
  EXPECT_NO_THROW(CompositeTable{good});
  auto bad = good;
  bad.taps[2].texel = texels + good.prefiltered[0] + 1;  // its 2×2 texels run past the spare rows
  EXPECT_THROW(CompositeTable{bad}, std::invalid_argument);
  bad = good;
  bad.taps[0].texel = -1;
  EXPECT_THROW(CompositeTable{bad}, std::invalid_argument);
  bad = good;
  bad.taps[1].weights = {200, 100, 0, 0};  // not out of 256
  EXPECT_THROW(CompositeTable{bad}, std::invalid_argument);
  bad = good;
  bad.taps.pop_back();
  EXPECT_THROW(CompositeTable{bad}, std::invalid_argument);
  bad = good;
  bad.borders[0].x = good.panel[0];
  EXPECT_THROW(CompositeTable{bad}, std::invalid_argument);
  bad = good;
  bad.borders[1].taps[3].texel = texels * 4;  // even a part without weight
  EXPECT_THROW(CompositeTable{bad}, std::invalid_argument);
  bad = good;
  std::swap(bad.borders[0], bad.borders[1]);  // render takes them row by row, in order
  EXPECT_THROW(CompositeTable{bad}, std::invalid_argument);
  bad = good;
  bad.prefiltered = {1 << 20, 3};
  EXPECT_THROW(CompositeTable{bad}, std::invalid_argument);
}

// The taps stored in an entry are checked when it is loaded: one pointing outside the image makes
// the entry unusable, not a read outside the table's buffers.
TEST(CompositeTableCache, EntriesWhoseTapsPointOutsideTheImageAreNotUsed) {
  test::TempDir dir;
  const CompositeTableCache cache(dir.path());
  const CompositeTable table(small_recording());
  ASSERT_TRUE(cache.store("key", table));
  ASSERT_TRUE(cache.load("key"));
  const auto entry = dir / test::files_in(dir.path()).at(0);
  std::string bytes;
  {
    std::ifstream in(entry, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  // The taps follow their count (a 64-bit 6: the panel is 3×2); find them by the first tap's bytes.
  const auto& taps = table.built().taps;
  std::string pattern(8 + sizeof(CompositeTable::Tap), '\0');
  const std::uint64_t count = taps.size();
  std::memcpy(pattern.data(), &count, 8);
  std::memcpy(pattern.data() + 8, &taps[0], sizeof taps[0]);
  const auto at = bytes.find(pattern);
  ASSERT_NE(at, std::string::npos);
  ASSERT_EQ(bytes.find(pattern, at + 1), std::string::npos);
  const std::int32_t outside = 1 << 30;
  std::memcpy(bytes.data() + at + 8, &outside, sizeof outside);
  {
    std::ofstream out(entry, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  EXPECT_FALSE(cache.load("key"));
  // A count larger than the file is refused before anything is allocated for it.
  const std::uint64_t huge = std::uint64_t{1} << 27;
  std::memcpy(bytes.data() + at, &huge, 8);
  {
    std::ofstream out(entry, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  EXPECT_FALSE(cache.load("key"));
}

}  // namespace
}  // namespace nelf
