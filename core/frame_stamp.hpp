#pragma once
// A frame stamp: a frame counter and its CLOCK_MONOTONIC present time drawn as a block code into a
// view's top band, so that a capture of a window (the test game, tests/game/) says which frame it
// caught and when that frame was presented. The code is a grid of cells, each a fraction of the
// view's width and height, so it reads back at any view size; four sync cells and a 28-bit check
// reject anything that is not a stamp (or a torn one).
#include <array>
#include <cstdint>
#include <optional>

namespace nelf {

struct FrameStamp {
  std::uint32_t frame = 0;
  std::int64_t present_ns = 0;  // CLOCK_MONOTONIC
  bool operator==(const FrameStamp&) const = default;
};

inline constexpr int kStampColumns = 32;
inline constexpr int kStampRows = 4;
inline constexpr int kStampBits = kStampColumns * kStampRows;
// The band of cells covers the view's full width and 1/kStampBandFraction of its height.
inline constexpr int kStampBandFraction = 12;

// Cell `index` (row-major, 0 top left) of a stamp in a view of width × height pixels, rows from the
// top: [x0, x1) × [y0, y1).
struct StampCell {
  int x0, y0, x1, y1;
};
StampCell stamp_cell(int index, int width, int height);

// The bits of the stamp, one per cell: true is a white cell, false a black one.
std::array<bool, kStampBits> stamp_bits(const FrameStamp& stamp);

// Reads the stamp from tightly packed RGBA rows (`bits` 8, or 16: native-endian uint16 per
// channel) of a view of width × height pixels; nothing when the cells do not hold a valid stamp.
std::optional<FrameStamp> read_frame_stamp(const std::uint8_t* rgba, int width, int height, int bits);

}  // namespace nelf
