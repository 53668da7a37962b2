#pragma once
// Still images in and out for the app's commands, through OpenImageIO.
#include <filesystem>

#include "compositor/image.hpp"

namespace nelf::app {

// Reads the first subimage of `path` as RGBA float (grey and grey+alpha expanded, extra channels
// dropped). Throws UserError naming the file and OIIO's reason when it cannot be read.
Image read_still_image(const std::filesystem::path& path);

// Writes `image` (RGB, 8 bits for PNG/JPEG) to `path`: first to a temporary name beside it, renamed
// at the end, so a failure never leaves a half-written file. Throws UserError when it cannot be written.
void write_image_file(const Image& image, const std::filesystem::path& path);

// Throws UserError when no image format writer is known for `path`'s extension (checked before long work).
void check_image_format(const std::filesystem::path& path, const char* option);

// The temporary name used for `path` while it is being written (same directory, same extension so that
// OIIO picks the same format).
std::filesystem::path temporary_name_for(const std::filesystem::path& path);

}  // namespace nelf::app
