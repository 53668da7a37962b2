#pragma once
// The test game's `--hud` (nelf_test_game.cpp): what a quad-buffer game draws over both eyes at
// once, with glDrawBuffer(GL_BACK) after drawing each eye, in one of the ways games draw it. The
// tests of the interposer look for it in both eyes, here. Fractions of the window, rows from the top.
namespace nelf::test_game {

// A white bar (arrays, immediate, list, copy).
inline constexpr double kHudX0 = 0.05, kHudX1 = 0.25, kHudTop = 0.78, kHudBottom = 0.86;
// --hud list: the list draws the bar and moves the modelview matrix this far right; the game then
// draws the bar again, which lands here once, and twice as far were the list's move made twice.
// --hud copy: the bar, and glCopyPixels of it this far right.
inline constexpr double kHudListShift = 0.3;
// --hud bitmap: kHudBlocks white blocks of kHudBlock pixels, kHudBlockStep apart (glBitmap moves the
// raster position), the first's left edge at kHudX0 and its bottom edge at kHudBlockBottom.
inline constexpr int kHudBlock = 16, kHudBlockStep = 32, kHudBlocks = 5;
inline constexpr double kHudBlockBottom = 0.98;

}  // namespace nelf::test_game
