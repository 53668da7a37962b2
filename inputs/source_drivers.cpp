#include "inputs/source_drivers.hpp"

#include <stdexcept>

namespace nelf {

// Each driver's two functions, defined in its own file.
namespace drivers {
bool accepts_synthetic(const SourceRequest& request);
std::unique_ptr<Source> open_synthetic(const SourceRequest& request);
bool accepts_x11(const SourceRequest& request);
std::unique_ptr<Source> open_x11(const SourceRequest& request);
bool accepts_pipewire(const SourceRequest& request);
std::unique_ptr<Source> open_pipewire(const SourceRequest& request);
bool accepts_glx_stereo(const SourceRequest& request);
std::unique_ptr<Source> open_glx_stereo(const SourceRequest& request);
bool accepts_device(const SourceRequest& request);
std::unique_ptr<Source> open_device(const SourceRequest& request);
bool accepts_still(const SourceRequest& request);
std::unique_ptr<Source> open_still(const SourceRequest& request);
bool accepts_file(const SourceRequest& request);
std::unique_ptr<Source> open_file(const SourceRequest& request);
}  // namespace drivers

namespace {

constexpr SourceDriver kDrivers[] = {
    {"synthetic", "synthetic:[duration=S,fps=N,size=WxH]: a stereo clip nelf renders itself, with a tone",
     drivers::accepts_synthetic, drivers::open_synthetic},
    {"x11", "x11:[display=:N,fps=N,wait=S,][window=TITLE|window-id=0x…]: a live X11 window (or the screen)",
     drivers::accepts_x11, drivers::open_x11},
    {"pipewire",
     "pipewire:[node=ID|NAME,fps=N,wait=S,restore=no]: the screen or window chosen in the desktop's ScreenCast "
     "portal, or a PipeWire video node (gamescope)",
     drivers::accepts_pipewire, drivers::open_pipewire},
    {"glx-stereo",
     "glx-stereo:[wait=S,]socket=PATH: a quad-buffer OpenGL game's two eyes, from nelf's interposer in the game "
     "(nelf run starts it so)",
     drivers::accepts_glx_stereo, drivers::open_glx_stereo},
    {"device", "v4l2:/dev/videoN, device:FORMAT:INPUT: an FFmpeg capture device (a capture card, x11grab, lavfi, ...)",
     drivers::accepts_device, drivers::open_device},
    {"still", "a stereo photo OpenImageIO reads (.jps, .mpo, .png, .jpg, .tif, .exr, ...; two with --right)",
     drivers::accepts_still, drivers::open_still},
    {"file", "a video FFmpeg reads, in any layout (alt: frame-sequential; pair: the right view with --right)",
     drivers::accepts_file, drivers::open_file},
};

}  // namespace

std::span<const SourceDriver> source_drivers() { return kDrivers; }

const SourceDriver& source_driver_for(const SourceRequest& request) {
  for (const SourceDriver& driver : kDrivers)
    if (driver.accepts(request)) return driver;
  throw std::logic_error("no source driver accepts " + request.input);  // the file driver takes everything
}

std::unique_ptr<Source> open_source(const SourceRequest& request) { return source_driver_for(request).open(request); }

}  // namespace nelf
