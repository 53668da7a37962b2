#include "app/image_files.hpp"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <unistd.h>
#include <system_error>
#include <vector>

#include "app/commands.hpp"

namespace nelf::app {

namespace {
// Larger stills than this are not content but an attack or a mistake (64 Mpx ≈ 1 GiB as RGBA float).
constexpr long long max_still_pixels = 64LL * 1024 * 1024;
}  // namespace

Image read_still_image(const std::filesystem::path& path) {
  auto input = OIIO::ImageInput::open(path.string());  // std::unique_ptr: closed on every path out
  if (!input) {
    std::string reason = OIIO::geterror();
    if (reason.empty()) reason = "unknown format or unreadable file";
    throw UserError(fmt::format("cannot read image '{}': {}", path.string(), reason));
  }
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1 ||
      static_cast<long long>(spec.width) * spec.height > max_still_pixels)
    throw UserError(fmt::format("image '{}' has unusable dimensions {}x{} with {} channels (at most {} pixels)",
                                path.string(), spec.width, spec.height, spec.nchannels, max_still_pixels));
  const int channels = spec.nchannels;
  std::vector<float> pixels(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height) *
                            static_cast<std::size_t>(channels));
  if (!input->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data()))
    throw UserError(fmt::format("cannot read image '{}': {}", path.string(), input->geterror()));
  Image image(spec.width, spec.height);
  for (std::size_t k = 0; k < image.pixels().size(); ++k) {
    const float* p = &pixels[k * static_cast<std::size_t>(channels)];
    Rgba& out = image.pixels()[k];
    if (channels >= 3) {
      out = {p[0], p[1], p[2], channels >= 4 ? p[3] : 1.f};
    } else {
      out = {p[0], p[0], p[0], channels == 2 ? p[1] : 1.f};
    }
  }
  return image;
}

void check_image_format(const std::filesystem::path& path, const char* option) {
  if (!OIIO::ImageOutput::create(path.string()))
    throw UserError(fmt::format("cannot write {} '{}': no image format for the extension '{}' (use .png)", option,
                                path.string(), path.extension().string()),
                    2);
}

std::filesystem::path temporary_name_for(const std::filesystem::path& path) {
  std::filesystem::path tmp = path;
  tmp.replace_filename(fmt::format(".{}.tmp-{}{}", path.stem().string(), ::getpid(), path.extension().string()));
  return tmp;
}

void write_image_file(const Image& image, const std::filesystem::path& path) {
  const auto tmp = temporary_name_for(path);
  OIIO::ImageSpec spec(image.width(), image.height(), 3, OIIO::TypeDesc::UINT8);
  auto output = OIIO::ImageOutput::create(path.string());  // picks the format from the extension
  if (!output) throw UserError(fmt::format("cannot write '{}': {}", path.string(), OIIO::geterror()));
  const auto fail = [&](const std::string& reason) {
    output.reset();
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    return UserError(fmt::format("cannot write '{}': {}", path.string(), reason));
  };
  if (!output->open(tmp.string(), spec)) throw fail(output->geterror());
  // RGBA float in, RGB 8-bit out: OIIO converts, the stride skips alpha.
  if (!output->write_image(OIIO::TypeDesc::FLOAT, image.data(), 4 * sizeof(float))) throw fail(output->geterror());
  if (!output->close()) throw fail(output->geterror());
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw fail(ec.message());
}

}  // namespace nelf::app
