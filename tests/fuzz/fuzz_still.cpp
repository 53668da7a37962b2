// Fuzz target: the still decoders through nelf's loader (inputs/still_source.*): PNG, JPEG, JPS and
// MPO files, read by OpenImageIO in the image-library module that nelf loads (compositor/
// image_library.*), split into views by the detected layout. The first byte picks the file's name
// (extension and a layout token, both of which steer the loader); the rest is the file. The JPEG
// and MPO scanners also see the bytes directly.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>

#include "core/image_library.hpp"
#include "inputs/still_source.hpp"
#include "temp_input.hpp"

namespace {

void require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "broken invariant: %s\n", what);
    std::abort();
  }
}

void check_offsets(const std::vector<std::size_t>& offsets, std::span<const std::byte> bytes) {
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    require(offsets[i] + 1 < bytes.size(), "an image offset lies in the file");
    require(i == 0 || offsets[i] > offsets[i - 1], "image offsets ascend");
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // The module must load, or every input would only exercise the error path.
  try {
    nelf::image_library::preload();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    std::abort();
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const nelf::fuzz::TempInput temp("nelf-fuzz-still");
  if (size == 0) return 0;
  const std::span<const std::uint8_t> file(data + 1, size - 1);
  const std::span<const std::byte> bytes = std::as_bytes(file);
  check_offsets(nelf::find_jpeg_images(bytes), bytes);
  check_offsets(nelf::find_mpo_images(bytes), bytes);

  static constexpr const char* kExtensions[] = {".png", ".jpg", ".jps", ".mpo"};
  static constexpr const char* kTokens[] = {"", ".sbs", ".hou", ".rl"};
  const std::string name = std::string("still") + kTokens[(data[0] >> 2) % 4] + kExtensions[data[0] % 4];
  nelf::StillOptions options;
  options.swap_eyes = (data[0] & 0x10) != 0;
  try {
    const nelf::StillStereo still = nelf::load_still(temp.write(name, file), options);
    const auto& l = still.views.left.image;
    const auto& r = still.views.right.image;
    require(l.width() > 0 && l.height() > 0 && r.width() > 0 && r.height() > 0, "loaded views are not empty");
  } catch (const nelf::StillError&) {
  }
  return 0;
}
