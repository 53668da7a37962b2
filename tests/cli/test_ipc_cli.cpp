// --input-ipc-server driven by socat, as mpv's scripts drive mpv: the replies are mpv's exact JSON,
// seek, cycle pause and quit act on the player off screen, the socket is owner-only and removed at
// exit, and a path that is not a socket is refused in one line. sid and aid switch a movie's
// subtitle and audio tracks as mpv's remotes switch mpv's.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf::test {
namespace {

TEST(IpcCli, SocatDrivesThePlayerWithMpvsJson) {
  TempDir dir;
  const auto sock = dir / "nelf.sock";
  const auto ask = [&](const std::string& json) {
    return run_command("echo " + shell_quote(json) + " | socat -t 10 - UNIX-CONNECT:" + q(sock)).out;
  };
  run_command("(env -u DISPLAY LP_NUM_THREADS=2 " + std::string(NELF_BINARY) +
              " play synthetic:duration=60 --no-config --output offscreen --no-audio --input-ipc-server " + q(sock) +
              " 2>" + q(dir / "err") + "; echo $? >" + q(dir / "status") + ") >/dev/null 2>&1 </dev/null &");
  for (int i = 0; i < 300 && !std::filesystem::is_socket(sock); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(std::filesystem::is_socket(sock)) << read_file(dir / "err");
  EXPECT_EQ(std::filesystem::status(sock).permissions() & std::filesystem::perms::all,
            std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);

  EXPECT_EQ(ask(R"({"command": ["get_property", "duration"], "request_id": 7})"),
            "{\"data\":60.0,\"error\":\"success\",\"request_id\":7}\n");
  EXPECT_EQ(ask(R"({"command": ["get_property", "filename"]})"),
            "{\"data\":\"synthetic:duration=60\",\"error\":\"success\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["seek", 30, "absolute"]})"), "{\"error\":\"success\",\"request_id\":0}\n");
  double pos = 0;
  for (int i = 0; i < 100 && pos < 30; ++i) {
    const std::string r = ask(R"({"command": ["get_property", "time-pos"]})");
    const auto at = r.find("\"data\":");
    ASSERT_NE(at, std::string::npos) << r;
    pos = std::stod(r.substr(at + 7));
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_GE(pos, 30.0);
  EXPECT_LT(pos, 45.0);
  EXPECT_EQ(ask(R"({"command": ["cycle", "pause"]})"), "{\"error\":\"success\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["get_property", "pause"]})"),
            "{\"data\":true,\"error\":\"success\",\"request_id\":0}\n");
  EXPECT_EQ(ask("set pause no"), "");  // a text command: run, not answered
  EXPECT_EQ(ask(R"({"command": ["get_property", "pause"]})"),
            "{\"data\":false,\"error\":\"success\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["set_property", "volume", 54]})"), "{\"error\":\"success\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["get_property", "volume"]})"),
            "{\"data\":54.0,\"error\":\"success\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["set_property", "volume", 200]})"),
            "{\"error\":\"invalid parameter\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["cycle", "mute"]})"), "{\"error\":\"success\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["get_property", "mute"]})"),
            "{\"data\":true,\"error\":\"success\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["get_property", "volumee"]})"),
            "{\"error\":\"property not found\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["seek", "soon"]})"), "{\"error\":\"invalid parameter\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["no-such-command"]})"), "{\"error\":\"invalid parameter\",\"request_id\":0}\n");
  EXPECT_EQ(ask("{not json"), "{\"error\":\"invalid parameter\"}\n");
  EXPECT_EQ(ask(R"({"command": ["quit"], "request_id": 9})"), "{\"error\":\"success\",\"request_id\":9}\n");
  for (int i = 0; i < 300 && !std::filesystem::exists(dir / "status"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(std::filesystem::exists(dir / "status")) << "quit did not end play";
  EXPECT_EQ(read_file(dir / "status"), "0\n") << read_file(dir / "err");
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(sock)));
}

// A movie with two audio tracks (eng, ger) and two subtitle tracks, played with a (dummy) sound
// device so that there is a track to switch.
TEST(IpcCli, SidAndAidSwitchTheTracksAsMpvsRemotesExpect) {
  TempDir dir;
  make_two_track_clip(dir / "audio.mp4", 30);
  write_file(dir / "eng.srt", "1\n00:00:00,000 --> 00:00:30,000\nHELLO\n\n");
  write_file(dir / "ger.srt", "1\n00:00:00,000 --> 00:00:30,000\nHALLO\n\n");
  make_media(dir / "movie.mkv", "-i " + q(dir / "audio.mp4") + " -i " + q(dir / "eng.srt") + " -i " +
                                    q(dir / "ger.srt") +
                                    " -map 0 -map 1 -map 2 -c:v copy -c:a copy -c:s srt -metadata:s:s:0 language=eng "
                                    "-metadata:s:s:1 language=ger");
  const auto sock = dir / "nelf.sock";
  const auto ask = [&](const std::string& json) {
    return run_command("echo " + shell_quote(json) + " | socat -t 10 - UNIX-CONNECT:" + q(sock)).out;
  };
  const auto ok = std::string("{\"error\":\"success\",\"request_id\":0}\n");
  const auto is = [](const std::string& data) {
    return "{\"data\":" + data + ",\"error\":\"success\",\"request_id\":0}\n";
  };
  run_command("(env -u DISPLAY SDL_AUDIODRIVER=dummy LP_NUM_THREADS=2 " + std::string(NELF_BINARY) + " play " +
              q(dir / "movie.mkv") + " --layout sbs --no-config --output offscreen --input-ipc-server " + q(sock) +
              " 2>" + q(dir / "err") + "; echo $? >" + q(dir / "status") + ") >/dev/null 2>&1 </dev/null &");
  for (int i = 0; i < 300 && !std::filesystem::is_socket(sock); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(std::filesystem::is_socket(sock)) << read_file(dir / "err");

  EXPECT_EQ(ask(R"({"command": ["get_property", "sid"]})"), is("1"));
  EXPECT_EQ(ask(R"({"command": ["set_property", "sid", 2]})"), ok);
  EXPECT_EQ(ask(R"({"command": ["get_property", "sub"]})"), is("2"));
  EXPECT_EQ(ask(R"({"command": ["set_property", "sid", "no"]})"), ok);
  EXPECT_EQ(ask(R"({"command": ["get_property", "sid"]})"), is("false"));
  EXPECT_EQ(ask(R"({"command": ["cycle", "sub"]})"), ok);  // off → the first
  EXPECT_EQ(ask(R"({"command": ["get_property", "sid"]})"), is("1"));
  EXPECT_EQ(ask(R"({"command": ["cycle", "sub", "down"]})"), ok);  // the first → off
  EXPECT_EQ(ask(R"({"command": ["get_property", "sid"]})"), is("false"));
  EXPECT_EQ(ask(R"({"command": ["set_property", "sid", 3]})"), "{\"error\":\"invalid parameter\",\"request_id\":0}\n");

  EXPECT_EQ(ask(R"({"command": ["get_property", "aid"]})"), is("1"));
  EXPECT_EQ(ask(R"({"command": ["set_property", "aid", 2]})"), ok);
  EXPECT_EQ(ask(R"({"command": ["get_property", "audio"]})"), is("2"));
  EXPECT_EQ(ask(R"({"command": ["cycle", "audio"]})"), ok);  // after the last, the first
  EXPECT_EQ(ask(R"({"command": ["get_property", "aid"]})"), is("1"));
  EXPECT_EQ(ask(R"({"command": ["set_property", "aid", 5]})"), "{\"error\":\"invalid parameter\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["quit"]})"), ok);
  for (int i = 0; i < 300 && !std::filesystem::exists(dir / "status"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(std::filesystem::exists(dir / "status")) << "quit did not end play";
  EXPECT_EQ(read_file(dir / "status"), "0\n") << read_file(dir / "err");
  const std::string err = read_file(dir / "err");
  EXPECT_NE(err.find("nelf: Subtitles: track 2/2 (ger, subrip, movie.mkv)"), std::string::npos) << err;
  EXPECT_NE(err.find("nelf: Audio: track 2/2 (ger, ac3, 5.1)"), std::string::npos) << err;
}

// One socket for the whole playlist, as mpv's: a client connected during the first file is answered
// in the second on the same connection.
TEST(IpcCli, AClientStaysConnectedFromOneFileOfThePlaylistToTheNext) {
  TempDir dir;
  const auto sock = dir / "nelf.sock";
  run_command("(env -u DISPLAY LP_NUM_THREADS=2 " + std::string(NELF_BINARY) +
              " play synthetic:duration=1 synthetic:duration=3 --no-config --output offscreen --no-audio "
              "--input-ipc-server " +
              q(sock) + " 2>" + q(dir / "err") + "; echo $? >" + q(dir / "status") + ") >/dev/null 2>&1 </dev/null &");
  for (int i = 0; i < 300 && !std::filesystem::is_socket(sock); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(std::filesystem::is_socket(sock)) << read_file(dir / "err");
  const std::string ask = R"({"command": ["get_property", "duration"]})";
  // The second request once the second file is opening (its line is said before it plays).
  const auto r =
      run_command("(echo " + shell_quote(ask) + "; for i in $(seq 300); do grep -q '2/2:' " + q(dir / "err") +
                  " && break; sleep 0.1; done; echo " + shell_quote(ask) + ") | socat -t 10 - UNIX-CONNECT:" + q(sock));
  EXPECT_EQ(r.out,
            "{\"data\":1.0,\"error\":\"success\",\"request_id\":0}\n"
            "{\"data\":3.0,\"error\":\"success\",\"request_id\":0}\n")
      << read_file(dir / "err");
  for (int i = 0; i < 300 && !std::filesystem::exists(dir / "status"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(read_file(dir / "status"), "0\n") << read_file(dir / "err");
}

TEST(IpcCli, APathThatIsNotASocketIsRefused) {
  TempDir dir;
  write_file(dir / "notes.txt", "keep");
  const auto r = run_command("env -u DISPLAY LP_NUM_THREADS=2 " + std::string(NELF_BINARY) +
                             " play synthetic:duration=1 --no-config --output offscreen --no-audio --quiet "
                             "--input-ipc-server " +
                             q(dir / "notes.txt"));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err, "nelf: --input-ipc-server " + (dir / "notes.txt").string() + ": exists and is not a socket\n");
  EXPECT_EQ(read_file(dir / "notes.txt"), "keep");
}

}  // namespace
}  // namespace nelf::test
