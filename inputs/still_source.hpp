#pragma once
// Still stereo images (photos, screenshots, renders): read with OpenImageIO into float RGBA and split
// into a stereo pair. Handles one-file layouts (side-by-side, top-bottom, frame-packed, mono), a pair
// of files (--right), JPS (right-left side-by-side JPEG) and MPO (two JPEGs in one file, left first).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "core/pixel_limit.hpp"
#include "inputs/stereo_layout.hpp"

namespace nelf {

// A still that cannot be used. what() is one line naming the file and the problem.
class StillError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Largest width or height accepted from a file: larger claims are corrupt or hostile headers.
constexpr int kMaxImageDimension = 16384;

// Reads the first image of a file as float RGBA 0..1 (gray -> r=g=b, missing alpha -> 1; 8-, 16-bit
// and float sources). `.jps` files are read as JPEG. Throws StillError for missing, unreadable,
// corrupt or truncated files and for zero or over-large dimensions, or more than `max_pixels`
// pixels (checked from the header, before decoding: core/pixel_limit.hpp).
Image read_image_file(const std::filesystem::path& path, std::int64_t max_pixels = kDefaultMaxPixels);

// The same for an encoded image held in memory (e.g. the second JPEG of an MPO). `format` is an
// OIIO format name ("jpeg"); `name` is used in error messages.
Image decode_image(std::span<const std::byte> encoded, const std::string& format, const std::string& name,
                   std::int64_t max_pixels = kDefaultMaxPixels);

// Byte offsets of the JPEG images stored back to back in `bytes` (an MPO file holds two or more;
// a plain JPEG one). Walks the JPEG segments of each image to its EOI, then looks for the next SOI.
std::vector<std::size_t> find_jpeg_images(std::span<const std::byte> bytes);

// Offsets of the images of an MPO file: from its MP Index IFD (APP2 "MPF" of the first image) when
// that is present and points at JPEG images, else from find_jpeg_images.
std::vector<std::size_t> find_mpo_images(std::span<const std::byte> bytes);

// Whether `input` names a still image by its extension (.png, .jpg, .jps, .mpo, .tif, .exr, …, any
// case): those are read here, everything else as video.
bool is_still_image_name(const std::string& input);
// True when `input` is named as an MPO (.mpo, any case): two JPEGs that load_still reads as a pair,
// where FFmpeg sees the first only.
bool is_mpo_name(const std::string& input);

struct StillOptions {
  std::optional<StereoLayout> layout;           // --layout; nothing = detect
  std::optional<std::filesystem::path> right;   // --right: the right view is a second file
  bool swap_eyes = false;                       // --swap-eyes
  std::int64_t max_pixels = kDefaultMaxPixels;  // --max-pixels: the largest image read (each view file)
};

struct StillStereo {
  StereoPair views;
  LayoutDecision decision;  // how the layout was chosen (rule, warning)
};

// Loads `path` (and options.right) and splits it into the two views. Throws StillError naming the
// file for unreadable input, a pair of different sizes, or a layout that does not fit.
StillStereo load_still(const std::filesystem::path& path, const StillOptions& options);

}  // namespace nelf
