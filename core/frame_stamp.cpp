#include "core/frame_stamp.hpp"

#include <cstddef>
#include <cstring>

namespace nelf {
namespace {

constexpr bool kSync[4] = {true, false, true, true};
constexpr int kCheckBits = kStampBits - 4 - 32 - 64;  // 28

// splitmix64's finaliser: every input bit changes about half the check bits.
std::uint64_t mix(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

std::uint32_t check_of(const FrameStamp& s) {
  const std::uint64_t h = mix(static_cast<std::uint64_t>(s.present_ns) ^ mix(s.frame + 0x9e3779b97f4a7c15ULL));
  return static_cast<std::uint32_t>(h & ((1u << kCheckBits) - 1));
}

}  // namespace

StampCell stamp_cell(int index, int width, int height) {
  const int column = index % kStampColumns, row = index / kStampColumns;
  const long band = height / kStampBandFraction;
  return {static_cast<int>(static_cast<long>(column) * width / kStampColumns),
          static_cast<int>(row * band / kStampRows),
          static_cast<int>(static_cast<long>(column + 1) * width / kStampColumns),
          static_cast<int>((row + 1) * band / kStampRows)};
}

std::array<bool, kStampBits> stamp_bits(const FrameStamp& stamp) {
  std::array<bool, kStampBits> bits{};
  int k = 0;
  for (bool b : kSync) bits[static_cast<std::size_t>(k++)] = b;
  for (int i = 31; i >= 0; --i) bits[static_cast<std::size_t>(k++)] = (stamp.frame >> i) & 1u;
  const auto ns = static_cast<std::uint64_t>(stamp.present_ns);
  for (int i = 63; i >= 0; --i) bits[static_cast<std::size_t>(k++)] = (ns >> i) & 1u;
  const std::uint32_t check = check_of(stamp);
  for (int i = kCheckBits - 1; i >= 0; --i) bits[static_cast<std::size_t>(k++)] = (check >> i) & 1u;
  return bits;
}

std::optional<FrameStamp> read_frame_stamp(const std::uint8_t* rgba, int width, int height, int bits) {
  if (!rgba || width < 2 * kStampColumns || height < 2 * kStampRows * kStampBandFraction) return std::nullopt;
  const std::size_t pixel = bits > 8 ? 8 : 4;
  // The luminance of a pixel, 0..1 (green dominates; red and blue enough to tell white from black).
  const auto level = [&](int x, int y) {
    const std::uint8_t* p =
        rgba + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * pixel;
    double c[3];
    for (int i = 0; i < 3; ++i) {
      if (bits > 8) {
        std::uint16_t v;
        std::memcpy(&v, p + 2 * i, 2);
        c[i] = v / 65535.0;
      } else {
        c[i] = p[i] / 255.0;
      }
    }
    return 0.25 * c[0] + 0.5 * c[1] + 0.25 * c[2];
  };
  std::array<bool, kStampBits> read{};
  for (int i = 0; i < kStampBits; ++i) {
    const StampCell cell = stamp_cell(i, width, height);
    // The middle half of the cell: scaling and chroma subsampling blur only its edges.
    const int qx = (cell.x1 - cell.x0) / 4, qy = (cell.y1 - cell.y0) / 4;
    double sum = 0;
    int n = 0;
    for (int y = cell.y0 + qy; y < cell.y1 - qy; ++y)
      for (int x = cell.x0 + qx; x < cell.x1 - qx; ++x) {
        sum += level(x, y);
        ++n;
      }
    if (n == 0) return std::nullopt;
    const double mean = sum / n;
    if (mean > 0.35 && mean < 0.65) return std::nullopt;  // neither white nor black: no stamp here
    read[static_cast<std::size_t>(i)] = mean >= 0.5;
  }
  int k = 0;
  for (bool b : kSync)
    if (read[static_cast<std::size_t>(k++)] != b) return std::nullopt;
  FrameStamp stamp;
  for (int i = 0; i < 32; ++i) stamp.frame = (stamp.frame << 1) | (read[static_cast<std::size_t>(k++)] ? 1u : 0u);
  std::uint64_t ns = 0;
  for (int i = 0; i < 64; ++i) ns = (ns << 1) | (read[static_cast<std::size_t>(k++)] ? 1u : 0u);
  stamp.present_ns = static_cast<std::int64_t>(ns);
  std::uint32_t check = 0;
  for (int i = 0; i < kCheckBits; ++i) check = (check << 1) | (read[static_cast<std::size_t>(k++)] ? 1u : 0u);
  if (check != check_of(stamp)) return std::nullopt;
  return stamp;
}

}  // namespace nelf
