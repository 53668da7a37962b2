// nelf-oiio.so: nelf's use of OpenImageIO, loaded when first needed (compositor/image_library.hpp
// says why). Only OpenImageIO and the standard library here: the module uses nothing of nelf's
// own code, so it needs no symbols from the executable that loads it.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>

#include "compositor/oiio/module_api.hpp"

namespace nelf::image_library {
namespace {

// OIIO messages can span lines and repeat the file name; keep the first line, which says why.
std::string first_line(std::string message) {
  const auto newline = message.find('\n');
  if (newline != std::string::npos) message.resize(newline);
  if (message.empty()) message = "unknown OpenImageIO error";
  return message;
}

[[noreturn]] void fail(const std::string& message) { throw std::runtime_error(message); }

// Reads the first subimage of an opened input, validating its size first so that a header claiming
// absurd dimensions never gets an allocation.
Pixels read_opened(OIIO::ImageInput& input, const std::string& name, int max_dimension) {
  const OIIO::ImageSpec& spec = input.spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    fail(name + ": the image has no pixels (" + std::to_string(spec.width) + "x" + std::to_string(spec.height) + ", " +
         std::to_string(spec.nchannels) + " channels)");
  if (spec.width > max_dimension || spec.height > max_dimension)
    fail(name + ": " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " is too large (at most " +
         std::to_string(max_dimension) + " pixels per side)");
  if (spec.depth > 1) fail(name + ": volume images are not supported");
  Pixels pixels;
  pixels.width = spec.width;
  pixels.height = spec.height;
  pixels.channels = std::min(spec.nchannels, 4);
  pixels.values.resize(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height) *
                       static_cast<std::size_t>(pixels.channels));
  if (!input.read_image(0, 0, 0, pixels.channels, OIIO::TypeDesc::FLOAT, pixels.values.data()))
    fail(name + ": cannot read the image: " + first_line(input.geterror()));
  input.close();
  return pixels;
}

Pixels read_file(const std::string& path, const std::string& format, int max_dimension) {
  std::unique_ptr<OIIO::ImageInput> input;
  if (!format.empty()) {
    input = OIIO::ImageInput::create(format);
    OIIO::ImageSpec spec;
    if (input && !input->open(path, spec)) fail(path + ": cannot read the image: " + first_line(input->geterror()));
  } else {
    input = OIIO::ImageInput::open(path);
  }
  if (!input) fail(path + ": cannot read the image: " + first_line(OIIO::geterror()));
  return read_opened(*input, path, max_dimension);
}

Pixels decode(std::span<const std::byte> encoded, const std::string& format, const std::string& name,
              int max_dimension) {
  OIIO::Filesystem::IOMemReader reader(encoded.data(), encoded.size());
  auto input = OIIO::ImageInput::create(format, false, nullptr, &reader);
  if (!input) fail(name + ": no " + format + " reader (" + first_line(OIIO::geterror()) + ")");
  // The reader reads from the proxy handed over in the open configuration, not from a file.
  OIIO::ImageSpec config;
  OIIO::Filesystem::IOProxy* proxy = &reader;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  OIIO::ImageSpec spec;
  if (!input->open(name, spec, config)) fail(name + ": cannot read the image: " + first_line(input->geterror()));
  return read_opened(*input, name, max_dimension);
}

bool has_writer(const std::string& format_or_file_name) {
  const bool found = OIIO::ImageOutput::create(format_or_file_name) != nullptr;
  if (!found) OIIO::geterror();  // clear OpenImageIO's pending message: the caller says it its way
  return found;
}

std::optional<std::vector<unsigned char>> encode(const Picture& picture, const EncodeOptions& options,
                                                 const std::string& path) {
  const OIIO::TypeDesc type = options.sample == SampleType::uint16 ? OIIO::TypeDesc::UINT16
                              : options.sample == SampleType::half ? OIIO::TypeDesc::HALF
                                                                   : OIIO::TypeDesc::UINT8;
  OIIO::ImageSpec spec(picture.width, picture.height, picture.channels, type);
  if (options.format == "jpeg") spec.attribute("CompressionQuality", options.jpeg_quality);
  auto out = OIIO::ImageOutput::create(options.format);
  if (!out) fail("no " + options.format + " writer (" + first_line(OIIO::geterror()) + ")");
  // OIIO's writers (PNG at least) ignore failed writes, so a full disk would leave a truncated
  // image and no error: encode into memory where the writer can, for the caller to write.
  OIIO::Filesystem::IOVecOutput encoded;
  const bool in_memory = out->supports("ioproxy") != 0 && out->set_ioproxy(&encoded);
  if (!out->open(path, spec)) fail(first_line(out->geterror()));
  const auto pixel_stride = static_cast<OIIO::stride_t>(sizeof(float)) * picture.pixel_stride;
  const bool written =
      out->write_image(OIIO::TypeDesc::FLOAT, picture.values, pixel_stride, pixel_stride * picture.width);
  const bool closed = out->close();
  if (!written || !closed) fail(first_line(out->geterror()));
  if (!in_memory) return std::nullopt;
  return std::move(encoded.buffer());
}

std::optional<TextBox> text_size(const std::string& text, int size, const std::string& font) {
  const OIIO::ROI box = OIIO::ImageBufAlgo::text_size(text, size, font);
  if (!box.defined()) {
    OIIO::geterror();
    return std::nullopt;
  }
  return TextBox{box.xbegin, box.xend, box.ybegin, box.yend};
}

OIIO::ImageBufAlgo::TextAlignX oiio_align(AlignX a) {
  using X = OIIO::ImageBufAlgo::TextAlignX;
  return a == AlignX::right ? X::Right : a == AlignX::center ? X::Center : X::Left;
}
OIIO::ImageBufAlgo::TextAlignY oiio_align(AlignY a) {
  using Y = OIIO::ImageBufAlgo::TextAlignY;
  return a == AlignY::top ? Y::Top : a == AlignY::bottom ? Y::Bottom : a == AlignY::center ? Y::Center : Y::Baseline;
}

void render_text(const Canvas& canvas, int x, int y, const std::string& text, int size, const std::string& font,
                 std::span<const float> colour, AlignX align_x, AlignY align_y, int shadow) {
  if (colour.size() != static_cast<std::size_t>(canvas.channels)) fail("render_text: one colour value per channel");
  // An ImageBuf over the caller's pixels: drawn in place, nothing copied.
  OIIO::ImageBuf image(OIIO::ImageSpec(canvas.width, canvas.height, canvas.channels, OIIO::TypeDesc::FLOAT),
                       canvas.values);
  if (!OIIO::ImageBufAlgo::render_text(image, x, y, text, size, font, OIIO::cspan<float>(colour.data(), colour.size()),
                                       oiio_align(align_x), oiio_align(align_y), shadow))
    fail(first_line(image.geterror()));
}

const ModuleApi kApi{
    .abi = ModuleApi::kAbi,
    .size = sizeof(ModuleApi),
    .read_file = read_file,
    .decode = decode,
    .has_writer = has_writer,
    .encode = encode,
    .text_size = text_size,
    .render_text = render_text,
};

}  // namespace

extern "C" __attribute__((visibility("default"))) const ModuleApi* nelf_image_library_module() { return &kApi; }

}  // namespace nelf::image_library
