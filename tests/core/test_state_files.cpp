#include "core/state_files.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include "support/test_support.hpp"

namespace nelf {
namespace {

TEST(StateFiles, TheStateFolderFollowsXdgAndIgnoresARelativeOne) {
  const test::ScopedEnv home("HOME", "/home/someone");
  {
    const test::ScopedEnv xdg("XDG_STATE_HOME", "/var/state");
    EXPECT_EQ(xdg_state_home(), "/var/state");
  }
  {
    const test::ScopedEnv xdg("XDG_STATE_HOME", "relative/state");
    EXPECT_EQ(xdg_state_home(), "/home/someone/.local/state");
  }
  const test::ScopedEnv no_xdg("XDG_STATE_HOME", "");
  EXPECT_EQ(xdg_state_home(), "/home/someone/.local/state");
  const test::ScopedEnv no_home("HOME", "");
  EXPECT_TRUE(xdg_state_home().empty());
}

TEST(StateFiles, AFileIsReplacedWholeWithItsModeAndNothingBeside) {
  const test::TempDir dir;
  const auto file = dir.path() / "nelf" / "kept";
  ASSERT_TRUE(replace_file(file, "first\n", 0600));
  ASSERT_TRUE(replace_file(file, "second\n", 0600));
  EXPECT_EQ(test::read_file(file), "second\n");
  struct stat st {};
  ASSERT_EQ(::stat(file.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(file.parent_path()), {}), 1);
}

TEST(StateFiles, AFileThatCannotBeReplacedIsLeftAsItWas) {
  const test::TempDir dir;
  const auto file = dir.path() / "kept";
  ASSERT_TRUE(replace_file(file, "kept\n"));
  // A folder where the file should go: the rename fails, the temporary is removed.
  EXPECT_FALSE(replace_file(dir.path(), "lost\n"));
  EXPECT_FALSE(replace_file(dir.path() / "kept" / "under-a-file", "lost\n"));
  EXPECT_EQ(test::read_file(file), "kept\n");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

}  // namespace
}  // namespace nelf
