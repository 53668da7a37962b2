#pragma once
// Everything nelf does with OpenImageIO: reading and writing image files, and drawing text.
//
// OpenImageIO is not linked into nelf but loaded the first time one of these functions is called,
// from a module built with nelf (nelf-oiio.so, core/oiio/module.cpp). Linking it cost every
// nelf command ~0.3 s in the dynamic loader before main() (it pulls in ~260 libraries: DICOM, RAW,
// HEIF, OpenVDB, …), as long as a whole second conversion's compositing; most commands (a video
// conversion, `probe`, `play` until a message shows) never touch an image file or draw text.
//
// Every function throws ImageLibraryError, one line, on failure, including when the module cannot
// be loaded (the message names the file and why).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace nelf::image_library {

class ImageLibraryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Loads the module now rather than at the first call (for `play`: not as a hitch at its first
// on-screen message).
void preload();

// Interleaved float pixels, `channels` a pixel, row 0 the top row.
struct Pixels {
  int width = 0, height = 0, channels = 0;
  std::vector<float> values;
};

// Reads the first subimage of a file as float. `format` ("jpeg") overrides the format OpenImageIO
// would choose from the name; "" leaves it to OpenImageIO. The header is checked before any pixel
// is decoded or allocated: no pixels, more than `limits.max_dimension` a side, more than
// `limits.max_pixels` in all (core/pixel_limit.hpp) or a volume image is an error. At most four
// channels are read, so memory is bounded by the pixel count. Messages start with `path`, and
// OpenImageIO's (libpng's, libjpeg's) own complaint is folded into them: nothing else is printed.
struct DecodeLimits {
  int max_dimension = 0;
  std::int64_t max_pixels = 0;
};
Pixels read_file(const std::string& path, const std::string& format, const DecodeLimits& limits);
// The same for an image held in memory, in the given format; messages start with `name`.
Pixels decode(std::span<const std::byte> encoded, const std::string& format, const std::string& name,
              const DecodeLimits& limits);

// Whether OpenImageIO has a writer for this format name or file name.
bool has_writer(const std::string& format_or_file_name);

enum class SampleType { uint8, uint16, half };
// Pixels to encode: the first `channels` floats of every `pixel_stride` floats, rows tightly packed.
struct Picture {
  const float* values = nullptr;
  int width = 0, height = 0, channels = 3, pixel_stride = 3;
};
struct EncodeOptions {
  std::string format;  // OpenImageIO's name: "png", "tiff", "openexr", "jpeg"
  SampleType sample = SampleType::uint8;
  int jpeg_quality = 95;
};
// Encodes `picture`. Writers that can encode into memory return the bytes (so that the caller can
// check every write: OpenImageIO's PNG writer ignores a full disk); the others write the file at
// `path` themselves and return nullopt. Messages say why, without the file name.
std::optional<std::vector<unsigned char>> encode(const Picture& picture, const EncodeOptions& options,
                                                 const std::string& path);

// Text in a font file or font name OpenImageIO can find (core/chart_style.hpp).
enum class AlignX { left, right, center };
enum class AlignY { baseline, top, bottom, center };
// The box the text covers relative to its origin on the baseline; nullopt when the font cannot
// be used.
struct TextBox {
  int x_begin = 0, x_end = 0, y_begin = 0, y_end = 0;
  int width() const { return x_end - x_begin; }
  int height() const { return y_end - y_begin; }
};
std::optional<TextBox> text_size(const std::string& text, int size, const std::string& font);
// A float canvas owned by the caller: `channels` floats a pixel, rows tightly packed.
struct Canvas {
  float* values = nullptr;
  int width = 0, height = 0, channels = 0;
};
// Draws `text` onto `canvas` (antialiased, clipped to it) in `colour` (`canvas.channels` values),
// positioned at (x, y) as the alignments say; with `shadow` > 0 a dark halo that many pixels wide.
// Throws with OpenImageIO's reason, e.g. when the font cannot be found.
void render_text(const Canvas& canvas, int x, int y, const std::string& text, int size, const std::string& font,
                 std::span<const float> colour, AlignX align_x = AlignX::left, AlignY align_y = AlignY::baseline,
                 int shadow = 0);

}  // namespace nelf::image_library
