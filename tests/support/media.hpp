#pragma once
// Test media generated at test time by the ffmpeg CLI (DESIGN.md §9: never committed as blobs).
#include <filesystem>
#include <stdexcept>
#include <string>

#include "support/test_support.hpp"

namespace nelf::test {

// The ffmpeg CLI's arguments for a quick H.264 stream that every FFmpeg build decodes.
inline const std::string h264 = " -c:v libx264 -preset ultrafast -pix_fmt yuv420p";

// Runs `ffmpeg ARGS OUTPUT` quietly, overwriting OUTPUT; throws with ffmpeg's own message on failure
// so that a broken generator shows up as such and not as a decoder bug. lavfi sources are endless:
// ARGS must bound them (-frames:v, d=, -shortest); the timeout catches a forgotten bound.
inline std::filesystem::path make_media(const std::filesystem::path& output, const std::string& args) {
  const CommandResult result =
      run_command("timeout 60 ffmpeg -nostdin -hide_banner -loglevel error -y " + args + " " + q(output));
  if (result.status != 0 || !std::filesystem::exists(output))
    throw std::runtime_error("ffmpeg could not generate " + output.string() + ": " + result.err);
  return output;
}

// The players' moving-box clip: a white 20×60 box moving right across a red (left view) and a
// blue (right view) 320×180 picture, side by side, `seconds` long at `fps`; with `audio`, a 440 Hz
// tone as an AAC track.
inline std::filesystem::path make_moving_box_clip(const std::filesystem::path& output, int seconds, int fps,
                                                  bool audio) {
  const std::string d = std::to_string(seconds), r = std::to_string(fps);
  std::string args = "-f lavfi -i color=c=0xC03020:s=320x180:r=" + r + ":d=" + d +
                     " -f lavfi -i color=c=0x2040C0:s=320x180:r=" + r + ":d=" + d +
                     " -f lavfi -i color=c=white:s=20x60:r=" + r + ":d=" + d;
  if (audio) args += " -f lavfi -i sine=f=440:r=48000:d=" + d;
  args +=
      " -filter_complex \"[2]split[b1][b2];[0][b1]overlay=x='mod(n*5,300)':y=60[l];"
      "[1][b2]overlay=x='mod(n*5,300)':y=60[r];[l][r]hstack\"" +
      h264;
  if (audio) args += " -c:a aac -shortest";
  return make_media(output, args);
}

// Two flat colours side by side (left red, right blue) or stacked (top red, bottom blue), each
// W×H, as lavfi input arguments for make_media.
inline std::string two_colour_input(int eye_width, int eye_height, bool stacked, int frames = 10, int rate = 10) {
  const std::string size = std::to_string(eye_width) + "x" + std::to_string(eye_height);
  return "-f lavfi -i color=c=red:s=" + size + ":r=" + std::to_string(rate) + " -f lavfi -i color=c=blue:s=" + size +
         ":r=" + std::to_string(rate) + " -filter_complex " + (stacked ? "vstack" : "hstack") + " -frames:v " +
         std::to_string(frames);
}

// A side-by-side video (320x180 views, 24 fps) with two audio tracks, as a film with a dubbing
// has them: track 1 stereo AAC tagged "eng" (440 Hz in both channels), track 2 5.1 AC-3 tagged
// "ger" with a 1 kHz tone in the centre channel only, the others silent. `seconds` long.
inline std::filesystem::path make_two_track_clip(const std::filesystem::path& output, int seconds = 2) {
  const std::string d = ":d=" + std::to_string(seconds);
  return make_media(output, "-f lavfi -i color=c=0xC03020:s=640x180:r=24" + d + " -f lavfi -i sine=f=440:r=48000" + d +
                                " -f lavfi -i sine=f=1000:r=48000" + d +
                                " -filter_complex \"[2]pan=5.1|FC=c0[surround]\" -map 0:v -map 1:a -map \"[surround]\""
                                " -c:v libx264 -preset ultrafast -pix_fmt yuv420p -c:a:0 aac -ac:a:0 2 -c:a:1 ac3"
                                " -metadata:s:a:0 language=eng -metadata:s:a:1 language=ger");
}

}  // namespace nelf::test
