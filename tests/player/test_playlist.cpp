// What `nelf play` makes of its inputs (player/playlist, player/watch_later): natural order, which
// names are media, a record's round trip and a damaged one read as none.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "player/playlist.hpp"
#include "player/watch_later.hpp"
#include "support/test_support.hpp"

namespace nelf::test {
namespace {

TEST(Playlist, NaturalOrderComparesNumbersAsNumbers) {
  std::vector<std::string> names = {"p10.jpg", "p2.jpg", "p1.jpg", "p02.jpg", "a.jpg", "p1b.jpg", "p.jpg"};
  std::sort(names.begin(), names.end(), natural_less);
  EXPECT_EQ(names, (std::vector<std::string>{"a.jpg", "p.jpg", "p1.jpg", "p1b.jpg", "p2.jpg", "p02.jpg", "p10.jpg"}));
  EXPECT_FALSE(natural_less("x", "x"));
}

TEST(Playlist, MediaNamesByExtension) {
  for (const char* name : {"a.MKV", "b.mp4", "c.jps", "d.MPO", "e.png", "f.webm"})
    EXPECT_TRUE(is_media_file_name(name)) << name;
  for (const char* name : {"notes.txt", "list.m3u", "noext", "sub.srt"}) EXPECT_FALSE(is_media_file_name(name)) << name;
}

TEST(Playlist, AnHlsPlaylistStaysOneInput) {
  TempDir dir;
  write_file(dir / "live.m3u8", "#EXTM3U\n#EXT-X-TARGETDURATION:2\n#EXTINF:2,\nseg0.ts\n");
  const auto entries = expand_playlist({(dir / "live.m3u8").string()}, [](const std::string&) {});
  EXPECT_EQ(entries, std::vector<std::string>{(dir / "live.m3u8").string()});
}

TEST(WatchLater, ARecordRoundTripsAndADamagedOneReadsAsNone) {
  TempDir dir;
  write_file(dir / "film.mkv", "x");
  const WatchLater store(dir / "state");
  const auto key = WatchLater::key_for((dir / "film.mkv").string());
  ASSERT_TRUE(key);
  EXPECT_FALSE(WatchLater::key_for("synthetic:duration=1"));
  std::vector<std::string> warnings;
  const auto warn = [&](const std::string& line) { warnings.push_back(line); };
  EXPECT_TRUE(store.load(*key, warn).empty());
  WatchLaterRecord record;
  record.position_s = 754.5;
  record.swap_eyes = true;
  record.layout = "tab";
  store.save(*key, record, warn);
  const WatchLaterRecord back = store.load(*key, warn);
  EXPECT_EQ(back.position_s, 754.5);
  EXPECT_EQ(back.swap_eyes, true);
  EXPECT_EQ(back.layout, "tab");
  EXPECT_TRUE(warnings.empty());

  write_file(store.file_for(*key), "path = 3\n");
  EXPECT_TRUE(store.load(*key, warn).empty());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("is damaged"), std::string::npos) << warnings[0];

  store.save(*key, WatchLaterRecord{}, warn);  // nothing left to remember: the file goes
  EXPECT_FALSE(std::filesystem::exists(store.file_for(*key)));
}

}  // namespace
}  // namespace nelf::test
