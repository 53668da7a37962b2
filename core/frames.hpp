#pragma once
// What flows between the stages for video: the two views of one stereo frame as the sources deliver
// them, and the sound that goes with them. Here, below the stages, so that a source makes them and
// the compositor and the outputs take them without including each other.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/image.hpp"
#include "core/view_disparity.hpp"

namespace nelf {

// The views of a stream as its source has them: the full size of each view and the aspect it is
// displayed at. What a consumer sizes the view format it asks for from (Source::negotiate).
struct ViewGeometry {
  int width = 0, height = 0;
  double aspect = 0.0;
  bool operator==(const ViewGeometry&) const = default;
};

// How the views of a stream travel: each delivered pixel the mean of block[0]×block[1] pixels of
// the view ({1, 1}: whole views). Asked for once per stream, and again when the optics change;
// every frame carries the format it was made in (StereoVideoFrame::block). `max_bits`: the deepest
// views the consumer wants; 8 for an 8-bit output (a display, an 8-bit file), where a 10-bit
// source's block means come as 8 bits, ordered-dithered, which the CPU composite tables take (a
// source that cannot still delivers 16).
struct ViewFormat {
  ViewFormat(std::array<int, 2> block_size = {1, 1}, int deepest = 16) : block(block_size), max_bits(deepest) {}
  std::array<int, 2> block;
  int max_bits;
  bool operator==(const ViewFormat&) const = default;
};

// Both views of one stereo frame, as tightly packed RGBA of `bits` per channel (8: one byte per
// channel; 16: native-endian uint16 per channel): width×height pixels, or, when `block` is more
// than 1×1, (width / block[0])×(height / block[1]) means of block[0]×block[1] pixels each (made
// while converting from YUV, in the ViewFormat the source negotiated). width, height and aspect are
// always those of the full view.
struct StereoVideoFrame {
  int width = 0, height = 0, bits = 8;
  std::vector<std::uint8_t> left, right;
  double aspect = 0.0;
  double pts_s = 0.0;              // time from the source's origin: from 0 at the start (or the requested start)
  std::array<int, 2> block{1, 1};  // ViewFormat::block of this frame
  // The same two views at the source's own precision, when it has them as float (a still): what
  // `nelf convert` composes a still from, so that its output never goes through `bits`.
  std::shared_ptr<const StereoPair> exact_views;
  std::shared_ptr<const StereoDisparity> disparity;  // the content's depth, when known or estimated
  std::int64_t captured_ns = 0;  // a live source's frame: CLOCK_MONOTONIC when it was read; 0 otherwise
};

inline std::size_t bytes_per_pixel(int bits) { return bits > 8 ? 8 : 4; }

// A packed output frame (both eyes' elemental images in the signal's layout) as bytes: RGBA, row 0
// the top row, `bits` per channel (16: native-endian uint16).
struct PackedFrame {
  int width = 0;
  int height = 0;
  int bits = 8;
  std::vector<std::uint8_t> rgba;  // width × height × 4 × (bits / 8) bytes
  double pts_seconds = 0.0;
};

// Interleaved float samples (stereo: L R L R …), −1..1.
struct AudioChunk {
  double pts_s = 0.0;  // time of the first sample
  std::vector<float> samples;
  int channels = 2;
  std::int64_t frames() const { return static_cast<std::int64_t>(samples.size()) / channels; }
};

}  // namespace nelf
