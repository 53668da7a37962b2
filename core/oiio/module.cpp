// nelf-oiio.so: nelf's use of OpenImageIO, loaded when first needed (core/image_library.hpp
// says why). Only OpenImageIO and the standard library here: the module uses nothing of nelf's
// own code, so it needs no symbols from the executable that loads it.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/oiio/module_api.hpp"
#include "core/pixel_limit.hpp"

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

// Refuses a size the header claims before anything is decoded: no pixels, too wide or tall, too many
// pixels (a decompression bomb: a few hundred KB of PNG can claim 16384x16384).
void check_size(const std::string& name, std::int64_t width, std::int64_t height, int channels,
                const DecodeLimits& limits) {
  if (width <= 0 || height <= 0 || channels <= 0)
    fail(name + ": the image has no pixels (" + std::to_string(width) + "x" + std::to_string(height) + ", " +
         std::to_string(channels) + " channels)");
  if (width > limits.max_dimension || height > limits.max_dimension)
    fail(name + ": " + std::to_string(width) + "x" + std::to_string(height) + " is too large (at most " +
         std::to_string(limits.max_dimension) + " pixels per side)");
  // At most four channels are read (read_opened), so the pixel count bounds the memory.
  if (const auto problem = pixel_limit_problem(width, height, limits.max_pixels)) fail(name + ": " + *problem);
}

// OIIO 2.4's PNG reader installs an error handler that records libpng's message and returns, so
// libpng falls back to its default handler, which prints "libpng error: ..." on stderr before OIIO
// reports the failure. A PNG is therefore first decoded here, row by row into one scratch row, by
// libpng with handlers that keep the message and never print: a damaged file fails with one line
// (ours) and never reaches OIIO. This pass also checks the header's size before OIIO sees it.
struct PngCheck {
  std::jmp_buf jump;
  char message[256] = "";
  std::span<const std::byte> bytes;
  std::size_t at = 0;
};

extern "C" void png_check_error(png_structp png, png_const_charp message) {
  auto* check = static_cast<PngCheck*>(png_get_error_ptr(png));
  std::snprintf(check->message, sizeof check->message, "%s", message ? message : "unknown libpng error");
  std::longjmp(check->jump, 1);
}
extern "C" void png_check_warning(png_structp, png_const_charp) {}  // OIIO ignores them too
extern "C" void png_check_read(png_structp png, png_bytep out, png_size_t size) {
  auto* check = static_cast<PngCheck*>(png_get_io_ptr(png));
  if (size > check->bytes.size() - check->at) png_error(png, "the file ends early (truncated)");
  std::memcpy(out, check->bytes.data() + check->at, size);
  check->at += size;
}

struct PngHeader {
  png_uint_32 width = 0, height = 0;
  int channels = 0;
};

// Only plain data lives between setjmp and longjmp here (no destructors to skip): the scratch row
// is owned by the caller. Returns false with check.message set when libpng fails. `header` is
// filled once the header is read; `accept` decides (after the header) whether to decode the rows.
bool png_decode_check(PngCheck& check, PngHeader& header, std::vector<png_byte>& row,
                      bool (*accept)(const PngHeader&, void*), void* context) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &check, png_check_error, png_check_warning);
  if (png == nullptr) {
    std::snprintf(check.message, sizeof check.message, "%s", "out of memory");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (setjmp(check.jump)) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  if (info == nullptr) png_error(png, "out of memory");
  png_set_read_fn(png, &check, png_check_read);
  png_read_info(png, info);
  header.width = png_get_image_width(png, info);
  header.height = png_get_image_height(png, info);
  header.channels = png_get_channels(png, info);
  if (!accept(header, context)) {
    png_destroy_read_struct(&png, &info, nullptr);
    return true;
  }
  const int passes = png_set_interlace_handling(png);
  png_read_update_info(png, info);
  row.resize(png_get_rowbytes(png, info));
  for (int pass = 0; pass < passes; ++pass)
    for (png_uint_32 y = 0; y < header.height; ++y) png_read_row(png, row.data(), nullptr);
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

bool is_png(std::span<const std::byte> bytes) {
  return bytes.size() >= 8 && png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) == 0;
}

void check_png(std::span<const std::byte> bytes, const std::string& name, const DecodeLimits& limits) {
  PngCheck check;
  check.bytes = bytes;
  PngHeader header;
  std::vector<png_byte> row;
  struct Context {
    const DecodeLimits& limits;
    std::string refusal;
  } context{limits, {}};
  // The size is checked between the header and the rows, outside the setjmp frame (a throw must
  // not cross libpng), by refusing the rows and remembering why.
  auto accept = [](const PngHeader& h, void* c) {
    auto& ctx = *static_cast<Context*>(c);
    try {
      check_size("", h.width, h.height, h.channels, ctx.limits);
    } catch (const std::runtime_error& e) {
      ctx.refusal = e.what();
      return false;
    }
    return true;
  };
  if (!png_decode_check(check, header, row, accept, &context)) fail(name + ": cannot read the image: " + check.message);
  if (!context.refusal.empty()) fail(name + context.refusal);
}

// Reads the first subimage of an opened input, validating its size first so that a header claiming
// absurd dimensions never gets an allocation.
Pixels read_opened(OIIO::ImageInput& input, const std::string& name, const DecodeLimits& limits) {
  const OIIO::ImageSpec& spec = input.spec();
  check_size(name, spec.width, spec.height, spec.nchannels, limits);
  if (spec.depth > 1) fail(name + ": volume images are not supported");
  Pixels pixels;
  pixels.width = spec.width;
  pixels.height = spec.height;
  pixels.channels = std::min(spec.nchannels, 4);
  const std::size_t row_values = static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(pixels.channels);
  if (spec.tile_width > 0) {
    pixels.values.resize(row_values * static_cast<std::size_t>(spec.height));
    if (!input.read_image(0, 0, 0, pixels.channels, OIIO::TypeDesc::FLOAT, pixels.values.data()))
      fail(name + ": cannot read the image: " + first_line(input.geterror()));
  } else {
    // Scanlines are read a band at a time, the memory growing with the rows that decode: a file of
    // a few bytes whose header claims the pixel limit (found by fuzzing: 22 bytes, 2.7 GB and 8 s
    // before "cannot read") fails at its first band instead of after allocating and filling all.
    constexpr int band_rows = 64;
    for (int y = 0; y < spec.height; y += band_rows) {
      const int rows = std::min(band_rows, spec.height - y);
      pixels.values.resize(row_values * static_cast<std::size_t>(y + rows));
      if (!input.read_scanlines(0, 0, spec.y + y, spec.y + y + rows, 0, 0, pixels.channels, OIIO::TypeDesc::FLOAT,
                                pixels.values.data() + row_values * static_cast<std::size_t>(y)))
        fail(name + ": cannot read the image: " + first_line(input.geterror()));
    }
  }
  input.close();
  return pixels;
}

Pixels decode_encoded(std::span<const std::byte> encoded, const std::string& format, const std::string& name,
                      const DecodeLimits& limits);

// The whole file, or nothing when it cannot be read (OIIO then says why).
std::optional<std::vector<std::byte>> file_bytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  if (!file) return std::nullopt;
  const std::streamoff size = file.tellg();
  if (size < 0) return std::nullopt;
  std::vector<std::byte> bytes(static_cast<std::size_t>(size));
  file.seekg(0);
  if (!file.read(reinterpret_cast<char*>(bytes.data()), size)) return std::nullopt;
  return bytes;
}

bool has_png_signature(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  char magic[8] = {};
  return file.read(magic, sizeof magic) && png_sig_cmp(reinterpret_cast<png_const_bytep>(magic), 0, 8) == 0;
}

Pixels read_file(const std::string& path, const std::string& format, const DecodeLimits& limits) {
  // A PNG is checked by libpng and decoded from the same bytes (check_png says why): one read, so
  // the file cannot change between the check and the decode.
  if ((format.empty() || format == "png") && has_png_signature(path))
    if (auto bytes = file_bytes(path)) return decode_encoded(*bytes, "png", path, limits);
  std::unique_ptr<OIIO::ImageInput> input;
  if (!format.empty()) {
    input = OIIO::ImageInput::create(format);
    OIIO::ImageSpec spec;
    if (input && !input->open(path, spec)) fail(path + ": cannot read the image: " + first_line(input->geterror()));
  } else {
    input = OIIO::ImageInput::open(path);
  }
  if (!input) fail(path + ": cannot read the image: " + first_line(OIIO::geterror()));
  return read_opened(*input, path, limits);
}

Pixels decode_encoded(std::span<const std::byte> encoded, const std::string& format, const std::string& name,
                      const DecodeLimits& limits) {
  if (is_png(encoded)) check_png(encoded, name, limits);
  OIIO::Filesystem::IOMemReader reader(encoded.data(), encoded.size());
  auto input = OIIO::ImageInput::create(format, false, nullptr, &reader);
  if (!input) fail(name + ": no " + format + " reader (" + first_line(OIIO::geterror()) + ")");
  // The reader reads from the proxy handed over in the open configuration, not from a file.
  OIIO::ImageSpec config;
  OIIO::Filesystem::IOProxy* proxy = &reader;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  OIIO::ImageSpec spec;
  if (!input->open(name, spec, config)) fail(name + ": cannot read the image: " + first_line(input->geterror()));
  return read_opened(*input, name, limits);
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
    .decode = decode_encoded,
    .has_writer = has_writer,
    .encode = encode,
    .text_size = text_size,
    .render_text = render_text,
};

}  // namespace

extern "C" __attribute__((visibility("default"))) const ModuleApi* nelf_image_library_module() { return &kApi; }

}  // namespace nelf::image_library
