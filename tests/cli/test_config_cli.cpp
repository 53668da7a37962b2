// The configuration file ($XDG_CONFIG_HOME/nelf/nelf.toml) as a user writes it: its [convert] and
// [play] values are the options' defaults and the command line overrides them (the frames ffprobe
// counts, the output play opens); --no-config ignores it; every mistake is one line naming the file
// and line; [keys] rebinds play's keys, pressed over the IPC socket and shown by h.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include "support/test_support.hpp"

namespace nelf::test {
namespace {

class ConfigCli : public ::testing::Test {
 protected:
  TempDir dir_;
  std::filesystem::path file() const { return dir_ / "nelf" / "nelf.toml"; }
  void write_config(const std::string& text) const {
    std::filesystem::create_directories(dir_ / "nelf");
    write_file(file(), text);
  }
  // nelf with this test's configuration directory and no display server.
  std::string nelf() const {
    return "env -u DISPLAY LP_NUM_THREADS=2 XDG_CONFIG_HOME=" + q(dir_.path()) + " " + NELF_BINARY + " ";
  }
  // The one line nelf fails with for a file holding `text`, and its status.
  void expect_config_error(const std::string& text, const std::string& message) const {
    write_config(text);
    const auto r = run_command(nelf() + "profiles");
    EXPECT_EQ(r.status, 2) << text << "\n" << r.err;
    EXPECT_EQ(r.err, "nelf: " + file().string() + ":" + message + "\n") << text;
    EXPECT_EQ(r.out, "");
  }
  int frames_in(const std::filesystem::path& video) const {
    const auto r = run_command(
        "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
        "stream=nb_read_frames -of csv=p=0 " +
        q(video));
    return r.status == 0 ? std::stoi(r.out) : -1;
  }
};

TEST_F(ConfigCli, TheFilesValuesAreDefaultsTheCommandLineOverrides) {
  const auto profile = write_small_profile(dir_);
  write_config("[convert]\nframes = 3\nquiet = true\nprofile = \"" + profile.string() + "\"\n");
  const auto three = dir_ / "three.mkv";
  auto r = run_command(nelf() + "convert synthetic:duration=2 " + q(three));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(frames_in(three), 3);

  const auto five = dir_ / "five.mkv";
  r = run_command(nelf() + "convert synthetic:duration=2 " + q(five) + " --frames 5");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(frames_in(five), 5);

  // --no-config: the option's own default (every frame, 2 s at 24 fps).
  const auto all = dir_ / "all.mkv";
  r = run_command(nelf() + "convert synthetic:duration=2 " + q(all) + " --no-config --profile " + q(profile) +
                  " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(frames_in(all), 48);
}

TEST_F(ConfigCli, PlaysOptionsAndFlagsComeFromTheFile) {
  // A window cannot open without a display server: the file's output would fail, the command
  // line's offscreen plays; the file's quiet drops the "playing on" line, and --quiet=false brings
  // it back.
  write_config("[play]\noutput = \"window\"\nno-audio = true\nquiet = true\n");
  auto r = run_command(nelf() + "play synthetic:duration=1 --output offscreen");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("playing on"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("frames shown"), std::string::npos) << r.err;
  r = run_command(nelf() + "play synthetic:duration=1 --output offscreen --quiet=false");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: playing on offscreen"), std::string::npos) << r.err;
  r = run_command(nelf() + "play synthetic:duration=1");
  EXPECT_NE(r.status, 0) << r.err;
}

TEST_F(ConfigCli, NoFileIsNoConfigurationAndNoConfigIgnoresABrokenOne) {
  auto r = run_command(nelf() + "profiles");  // no nelf/nelf.toml in the directory
  EXPECT_EQ(r.status, 0) << r.err;
  write_config("[probe\n");
  r = run_command(nelf() + "profiles --no-config");
  EXPECT_EQ(r.status, 0) << r.err;
  r = run_command(nelf() + "profiles");
  EXPECT_EQ(r.status, 2) << r.err;
  // XDG_CONFIG_HOME unset: ~/.config.
  r = run_command("env -u DISPLAY -u XDG_CONFIG_HOME HOME=" + q(dir_ / "home") + " " + NELF_BINARY + " profiles");
  EXPECT_EQ(r.status, 0) << r.err;
  std::filesystem::create_directories(dir_ / "home" / ".config" / "nelf");
  write_file(dir_ / "home" / ".config" / "nelf" / "nelf.toml", "[probe]\njsn = true\n");
  r = run_command("env -u DISPLAY -u XDG_CONFIG_HOME HOME=" + q(dir_ / "home") + " " + NELF_BINARY + " profiles");
  EXPECT_EQ(r.err, "nelf: " + (dir_ / "home" / ".config" / "nelf" / "nelf.toml").string() +
                       ":2: unknown key \"jsn\" in [probe] (did you mean \"json\"?)\n");
}

TEST_F(ConfigCli, EveryMistakeIsOneLineWithTheFileAndLine) {
  expect_config_error("[play]\nouptut = \"offscreen\"\n",
                      "2: unknown key \"ouptut\" in [play] (did you mean \"output\"?)");
  expect_config_error("\n[play]\nzzzzzz = 1\n", "3: unknown key \"zzzzzz\" in [play] (see nelf play --help)");
  expect_config_error("[plya]\noutput = \"offscreen\"\n", "1: unknown table [plya] (did you mean [play]?)");
  expect_config_error("output = \"offscreen\"\n",
                      "1: \"output\" is not in a table: options go in their command's ([play], [convert], …)");
  expect_config_error("[convert]\nfsaa = \"four\"\n", "2: \"fsaa\" in [convert] takes an integer");
  expect_config_error("[convert]\nstart = \"soon\"\n", "2: \"start\" in [convert] takes a number");
  expect_config_error("[play]\nno-audio = 1\n", "2: \"no-audio\" in [play] takes true or false");
  expect_config_error("[play]\noutput = 3\n", "2: \"output\" in [play] takes a string");
  expect_config_error("[convert]\nstart = nan\n",
                      "2: bad value nan for \"start\" in [convert]: --start: must be a finite number, got nan");
  expect_config_error("[play]\noutput = \"offscreen\"\n[keys\n",
                      "3: TOML syntax error: Error while parsing table header: expected ']', saw '\\n'");
  expect_config_error("[keys]\n\"x\" = \"swap-eye\"\n",
                      "2: unknown command \"swap-eye\" for \"x\" in [keys] (did you mean \"swap-eyes\"?)");
  expect_config_error("[keys]\n\"Alt+x\" = \"quit\"\n",
                      "2: unknown key name \"Alt+x\" in [keys] (one character, or SPACE, LEFT, RIGHT, UP, DOWN, "
                      "PGUP, PGDWN, ESC, ENTER, TAB, BS, or Ctrl+ and a character)");
  expect_config_error("[keys]\nx = 1\n", "2: \"x\" in [keys] takes a command's name, as a string (e.g. \"swap-eyes\")");
  expect_config_error("[keys]\nesc = \"quit\"\nESC = \"help\"\n",
                      "2: \"esc\" in [keys] names a key another line binds");
}

// [keys] takes effect in the player: x quits and q no longer does (keys pressed over the IPC
// socket, as mpv's keypress command presses them), and h prints the keys as they now are.
TEST_F(ConfigCli, ReboundKeysActAndTheHelpShowsThem) {
  write_config(
      "[play]\noutput = \"offscreen\"\nno-audio = true\n[keys]\n\"x\" = \"quit\"\n\"q\" = \"ignore\"\n"
      "\"PGDWN\" = \"swap-eyes\"\n\"s\" = \"ignore\"\n");
  const auto sock = dir_ / "nelf.sock";
  const auto ask = [&](const std::string& json) {
    return run_command("echo " + shell_quote(json) + " | socat -t 10 - UNIX-CONNECT:" + q(sock)).out;
  };
  run_command("(" + nelf() + "play synthetic:duration=60 --input-ipc-server " + q(sock) + " 2>" + q(dir_ / "err") +
              "; echo $? >" + q(dir_ / "status") + ") >/dev/null 2>&1 </dev/null &");
  for (int i = 0; i < 300 && !std::filesystem::is_socket(sock); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(std::filesystem::is_socket(sock)) << read_file(dir_ / "err");
  EXPECT_EQ(ask(R"({"command": ["keypress", "h"]})"), "{\"error\":\"success\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["keypress", "q"]})"), "{\"error\":\"success\",\"request_id\":0}\n");
  EXPECT_EQ(ask(R"({"command": ["get_property", "pause"]})"),
            "{\"data\":false,\"error\":\"success\",\"request_id\":0}\n")
      << "q quit";
  EXPECT_EQ(ask(R"({"command": ["keypress", "x"]})"), "{\"error\":\"success\",\"request_id\":0}\n");
  for (int i = 0; i < 300 && !std::filesystem::exists(dir_ / "status"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(std::filesystem::exists(dir_ / "status")) << "x did not quit";
  EXPECT_EQ(read_file(dir_ / "status"), "0\n");
  const std::string err = read_file(dir_ / "err");
  for (const std::string line : {"nelf: key S: swap the eyes\n", "nelf: key Esc Q: quit\n", "nelf: key x: quit\n",
                                 "nelf: key PgDn: swap the eyes\n", "nelf: key space: pause / play\n"})
    EXPECT_NE(err.find(line), std::string::npos) << line << err;
  EXPECT_EQ(err.find("nelf: key q Esc: quit\n"), std::string::npos) << err;
  EXPECT_EQ(err.find("nelf: key s: swap the eyes\n"), std::string::npos) << err;
}

}  // namespace
}  // namespace nelf::test
