#include "core/printable.hpp"

#include <gtest/gtest.h>

namespace nelf {
namespace {

TEST(Printable, OrdinaryTextIsUnchanged) {
  EXPECT_EQ(printable("film.3D.SBS.mkv: no such file"), "film.3D.SBS.mkv: no such file");
  EXPECT_EQ(printable("C:\\films\\a.mkv"), "C:\\films\\a.mkv");
  EXPECT_EQ(printable("Amélie — 映画 🎬"), "Amélie — 映画 🎬");
  EXPECT_EQ(printable(""), "");
}

TEST(Printable, ControlsBecomeVisibleEscapes) {
  EXPECT_EQ(printable("a\nb\rc\td"), "a\\nb\\rc\\td");
  EXPECT_EQ(printable("\x1b[31mred\x1b[0m"), "\\x1b[31mred\\x1b[0m");
  EXPECT_EQ(printable(std::string("nul\0bell\x07", 9)), "nul\\x00bell\\x07");
  EXPECT_EQ(printable("del\x7f"), "del\\x7f");
  // C1 controls: U+009B is a one-character CSI to many terminals, U+0085 a line break.
  EXPECT_EQ(printable("\xc2\x9b"
                      "31m"),
            "\\u009b31m");
  EXPECT_EQ(printable("next\xc2\x85line"), "next\\u0085line");
  EXPECT_EQ(printable("\xc2\xa0"), "\xc2\xa0");  // U+00A0, the first printable one, stays
}

TEST(Printable, InvalidUtf8IsShownByteByByte) {
  EXPECT_EQ(printable("latin1 caf\xe9"), "latin1 caf\\xe9");
  EXPECT_EQ(printable("\xc0\xaf"), "\\xc0\\xaf");                    // overlong '/'
  EXPECT_EQ(printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");           // a UTF-16 surrogate
  EXPECT_EQ(printable("\xf4\x90\x80\x80"), "\\xf4\\x90\\x80\\x80");  // beyond U+10FFFF
  EXPECT_EQ(printable("cut \xe6\x98"), "cut \\xe6\\x98");            // a sequence cut short
  EXPECT_EQ(printable("\xe6\x98\xa0"), "\xe6\x98\xa0");              // the whole one is kept
}

}  // namespace
}  // namespace nelf
