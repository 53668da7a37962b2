// The composite-table cache: what is stored comes back whole under its key only; damaged, foreign
// or missing entries and an unusable directory mean "not cached", never an error or a wrong table.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "compositor/composite_table_cache.hpp"
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

void expect_same(const CompositeTable::Recording& a, const CompositeTable::Recording& b) {
  EXPECT_EQ(a.panel, b.panel);
  EXPECT_EQ(a.reduced, b.reduced);
  EXPECT_EQ(a.prefiltered, b.prefiltered);
  EXPECT_EQ(a.horizontal.first, b.horizontal.first);
  EXPECT_EQ(a.horizontal.begin, b.horizontal.begin);
  EXPECT_EQ(a.horizontal.weights, b.horizontal.weights);
  EXPECT_EQ(a.vertical.weights, b.vertical.weights);
  EXPECT_EQ(a.coordinates, b.coordinates);
  EXPECT_EQ(a.border_pixels, b.border_pixels);
  ASSERT_EQ(a.border_parts.size(), b.border_parts.size());
  for (std::size_t i = 0; i < a.border_parts.size(); ++i)
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(a.border_parts[i][k].x, b.border_parts[i][k].x);
      EXPECT_EQ(a.border_parts[i][k].weight, b.border_parts[i][k].weight);
    }
}

TEST(CompositeTableCache, StoredRecordingComesBackWholeUnderItsKeyOnly) {
  test::TempDir dir;
  const CompositeTableCache cache(dir / "tables");
  const auto recording = small_recording();
  EXPECT_FALSE(cache.load("key one"));
  ASSERT_TRUE(cache.store("key one", recording));
  const auto loaded = cache.load("key one");
  ASSERT_TRUE(loaded);
  expect_same(*loaded, recording);
  EXPECT_FALSE(cache.load("key two"));
  // The table built from it works like one built from the recording itself.
  EXPECT_EQ(CompositeTable(*loaded).panel(), (std::array<int, 2>{3, 2}));
  // Nothing but the entry (no temporary file) is left in the directory.
  EXPECT_EQ(test::files_in(dir / "tables").size(), 1u);
}

TEST(CompositeTableCache, DamagedEntriesAreNotUsed) {
  test::TempDir dir;
  const CompositeTableCache cache(dir.path());
  ASSERT_TRUE(cache.store("key", small_recording()));
  const auto entry = dir / test::files_in(dir.path()).at(0);
  const auto size = std::filesystem::file_size(entry);
  std::filesystem::resize_file(entry, size - 5);  // truncated
  EXPECT_FALSE(cache.load("key"));
  {
    std::ofstream out(entry, std::ios::binary | std::ios::trunc);
    out << "not a table at all";
  }
  EXPECT_FALSE(cache.load("key"));
  ASSERT_TRUE(cache.store("key", small_recording()));  // a new store replaces the damaged one
  EXPECT_TRUE(cache.load("key"));
}

TEST(CompositeTableCache, UnusableDirectoryMeansNoCache) {
  test::TempDir dir;
  test::write_file(dir / "file", "x");
  const CompositeTableCache under_a_file(dir / "file" / "tables");
  EXPECT_FALSE(under_a_file.store("key", small_recording()));
  EXPECT_FALSE(under_a_file.load("key"));
  const CompositeTableCache none{std::filesystem::path{}};
  EXPECT_FALSE(none.store("key", small_recording()));
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

}  // namespace
}  // namespace nelf
