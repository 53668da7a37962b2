#pragma once
// The image-file sink: writes one output frame with OpenImageIO (core/image_library.hpp), format by extension
// (.png, .tif, .tiff, .exr, .jpg, .jpeg). The file appears complete or not at all: it is written under a temporary name
// in the same directory and renamed at the end (DESIGN.md §11).
#include <filesystem>
#include <functional>
#include <stdexcept>

#include "core/image.hpp"
#include "core/image_library.hpp"

namespace nelf {

// A frame that could not be written. what() is one line naming the file and the cause.
class ImageWriteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ImageWriteOptions {
  bool overwrite = false;  // replace an existing file (the CLI's -y)
  int bits = 8;            // 8 or 16 per channel for PNG and TIFF; EXR is always half float, JPEG 8
};

// True when `path` ends in an extension write_image_file writes (.png, .tif, .tiff, .exr, .jpg, .jpeg).
bool is_image_file_name(const std::filesystem::path& path);

// Throws ImageWriteError unless `path` could be written with `options`: unknown extension, bits
// not 8/16, 16 bits for a format that cannot hold them, existing file without `overwrite`, missing
// directory. Cheap; the CLI calls it before doing any work.
void check_image_writable(const std::filesystem::path& path, const ImageWriteOptions& options);

// Writes the RGB channels of `image` (alpha is dropped: a display frame is opaque). Values are
// clamped to 0..1 for integer formats. On any failure the temporary file is removed and nothing
// appears at `path`.
void write_image_file(const Image& image, const std::filesystem::path& path, const ImageWriteOptions& options);

// Encodes `picture` into the file `temporary` with every write checked (a full disk is an error,
// not a truncated image). Messages name `shown`, the file the user asked for.
void write_picture(const std::filesystem::path& temporary, const std::filesystem::path& shown,
                   const image_library::Picture& picture, const image_library::EncodeOptions& options);

// Any file written without a half-written state: `write` fills a temporary file beside `path`
// (a hidden name without the extension: name the format explicitly), which is then renamed into
// place; refuses to replace an existing file unless `overwrite`. Ctrl-C is held back meanwhile.
// Throws ImageWriteError (or what `write` throws) and leaves nothing behind on failure.
void write_file_atomically(const std::filesystem::path& path, bool overwrite,
                           const std::function<void(const std::filesystem::path& temporary)>& write);

}  // namespace nelf
