#pragma once
// A release-style Matroska file, generated at test time by the ffmpeg CLI: 6 s of 320x180 H.264 at
// 10 fps, a 5.1 AC-3 track (eng, "Surround 5.1") and a stereo AAC track (fre, "Stereo"), two SRT
// tracks (eng, default; fre, "French"), three chapters (A 0-1.5 s, B 1.5-3 s, C 3-6 s) and a font
// attachment, as a film from a release group comes.
#include <filesystem>
#include <string>

#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf::test {

// The English subtitles: "first" 1-3 s, "second" 3.5-5.5 s; the French: "premier" 0.5-2.5 s.
inline std::filesystem::path make_release_mkv(const std::filesystem::path& dir, const std::string& name = "rel.mkv") {
  write_file(dir / "eng.srt", "1\n00:00:01,000 --> 00:00:03,000\nfirst\n\n2\n00:00:03,500 --> 00:00:05,500\nsecond\n");
  write_file(dir / "fre.srt", "1\n00:00:00,500 --> 00:00:02,500\npremier\n");
  write_file(dir / "chapters.txt",
             ";FFMETADATA1\ntitle=Release\n"
             "[CHAPTER]\nTIMEBASE=1/1000\nSTART=0\nEND=1500\ntitle=A\n"
             "[CHAPTER]\nTIMEBASE=1/1000\nSTART=1500\nEND=3000\ntitle=B\n"
             "[CHAPTER]\nTIMEBASE=1/1000\nSTART=3000\nEND=6000\ntitle=C\n");
  return make_media(
      dir / name,
      "-f lavfi -i testsrc2=s=320x180:r=10 -f lavfi -i sine=duration=6:sample_rate=48000 -f lavfi -i "
      "sine=duration=6:frequency=880:sample_rate=48000 -i " +
          q(dir / "eng.srt") + " -i " + q(dir / "fre.srt") + " -i " + q(dir / "chapters.txt") +
          " -map 0:v -map 1:a -map 2:a -map 3 -map 4 -map_metadata 5 -map_chapters 5 -t 6 -c:v libx264 -bf 0 "
          "-preset ultrafast -c:a:0 ac3 -ac:a:0 6 -c:a:1 aac -ac:a:1 2 -c:s srt -metadata:s:a:0 language=eng "
          "-metadata:s:a:0 \"title=Surround 5.1\" -metadata:s:a:1 language=fre -metadata:s:a:1 title=Stereo "
          "-metadata:s:s:0 language=eng -metadata:s:s:1 language=fre -metadata:s:s:1 title=French "
          "-disposition:s:0 default -attach /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf "
          "-metadata:s:t mimetype=application/x-truetype-font");
}

}  // namespace nelf::test
