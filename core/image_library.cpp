#include "core/image_library.hpp"

#include <dlfcn.h>
#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "core/module_path.hpp"
#include "core/oiio/module_api.hpp"

namespace nelf::image_library {
namespace {

namespace fs = std::filesystem;

struct CloseLibrary {
  void operator()(void* handle) const { dlclose(handle); }
};

// The loaded module, for the rest of the process. RTLD_NODELETE: OpenImageIO keeps threads and
// static state, so it stays mapped even when the handle is closed at exit.
class Module {
 public:
  Module() {
    const fs::path path =
        find_module("NELF_IMAGE_LIBRARY", "nelf-oiio.so", NELF_IMAGE_LIBRARY_INSTALLED, NELF_IMAGE_LIBRARY_BUILT);
    handle_.reset(dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE));
    if (!handle_) {
      std::string why = dlerror();
      if (why.starts_with(path.string() + ": ")) why.erase(0, path.string().size() + 2);
      throw ImageLibraryError(
          fmt::format("cannot load nelf's image library {}: {} (reinstall nelf)", path.string(), why));
    }
    using Entry = const ModuleApi* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle_.get(), NELF_IMAGE_LIBRARY_ENTRY));
    api_ = entry ? entry() : nullptr;
    if (!api_ || api_->abi != ModuleApi::kAbi || api_->size != sizeof(ModuleApi))
      throw ImageLibraryError(fmt::format(
          "{} is not the image library of this nelf build (another version?); reinstall nelf", path.string()));
  }
  const ModuleApi& api() const { return *api_; }

 private:
  std::unique_ptr<void, CloseLibrary> handle_;
  const ModuleApi* api_ = nullptr;
};

const ModuleApi& api() {
  // A failed load throws out of the initialisation, so the next call tries again.
  static const Module module;
  return module.api();
}

// Calls into the module with its std::runtime_error turned into ImageLibraryError.
template <typename Call>
auto guarded(Call call) {
  const ModuleApi& table = api();
  try {
    return call(table);
  } catch (const ImageLibraryError&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw ImageLibraryError(e.what());
  }
}

}  // namespace

void preload() { api(); }

Pixels read_file(const std::string& path, const std::string& format, const DecodeLimits& limits) {
  return guarded([&](const ModuleApi& m) { return m.read_file(path, format, limits); });
}

Pixels decode(std::span<const std::byte> encoded, const std::string& format, const std::string& name,
              const DecodeLimits& limits) {
  return guarded([&](const ModuleApi& m) { return m.decode(encoded, format, name, limits); });
}

bool has_writer(const std::string& format_or_file_name) {
  return guarded([&](const ModuleApi& m) { return m.has_writer(format_or_file_name); });
}

std::optional<std::vector<unsigned char>> encode(const Picture& picture, const EncodeOptions& options,
                                                 const std::string& path) {
  return guarded([&](const ModuleApi& m) { return m.encode(picture, options, path); });
}

std::optional<TextBox> text_size(const std::string& text, int size, const std::string& font) {
  return guarded([&](const ModuleApi& m) { return m.text_size(text, size, font); });
}

void render_text(const Canvas& canvas, int x, int y, const std::string& text, int size, const std::string& font,
                 std::span<const float> colour, AlignX align_x, AlignY align_y, int shadow) {
  guarded([&](const ModuleApi& m) { m.render_text(canvas, x, y, text, size, font, colour, align_x, align_y, shadow); });
}

}  // namespace nelf::image_library
