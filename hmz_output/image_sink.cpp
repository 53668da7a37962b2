#include "hmz_output/image_sink.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "core/image_library.hpp"

namespace nelf {
namespace {

namespace fs = std::filesystem;

enum class FileFormat { png, tiff, exr, jpeg };

std::optional<FileFormat> format_for(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".png") return FileFormat::png;
  if (ext == ".tif" || ext == ".tiff") return FileFormat::tiff;
  if (ext == ".exr") return FileFormat::exr;
  if (ext == ".jpg" || ext == ".jpeg") return FileFormat::jpeg;
  return std::nullopt;
}

const char* oiio_format_name(FileFormat f) {
  switch (f) {
    case FileFormat::png:
      return "png";
    case FileFormat::tiff:
      return "tiff";
    case FileFormat::exr:
      return "openexr";
    case FileFormat::jpeg:
      return "jpeg";
  }
  return "png";
}

fs::path directory_of(const fs::path& path) { return path.has_parent_path() ? path.parent_path() : fs::path("."); }

// A temporary file next to the final one. Removed on destruction unless it was renamed into place.
class TemporaryFile {
 public:
  explicit TemporaryFile(const fs::path& final_path) {
    std::string pattern = (directory_of(final_path) / ("." + final_path.filename().string() + ".nelf-XXXXXX")).string();
    std::vector<char> buffer(pattern.begin(), pattern.end());
    buffer.push_back('\0');
    const int fd = ::mkstemp(buffer.data());
    if (fd < 0)
      throw ImageWriteError(fmt::format("cannot write {}: cannot create a file in {} ({})", final_path.string(),
                                        directory_of(final_path).string(), std::strerror(errno)));
    path_ = buffer.data();
    // mkstemp makes the file private (0600); give it the permissions a newly created file gets.
    const mode_t mask = ::umask(0);
    ::umask(mask);
    ::fchmod(fd, static_cast<mode_t>(0666 & ~mask));
    ::close(fd);
  }
  ~TemporaryFile() {
    if (!path_.empty()) ::unlink(path_.c_str());
  }
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;

  const fs::path& path() const { return path_; }

  // Moves the file to `final_path`; refuses to replace an existing file unless `overwrite`.
  void commit(const fs::path& final_path, bool overwrite) {
    if (overwrite) {
      if (::rename(path_.c_str(), final_path.c_str()) != 0)
        throw ImageWriteError(
            fmt::format("cannot write {}: rename failed ({})", final_path.string(), std::strerror(errno)));
    } else {
      // No-clobber without a window between the existence check and the rename.
      if (::renameat2(AT_FDCWD, path_.c_str(), AT_FDCWD, final_path.c_str(), RENAME_NOREPLACE) != 0) {
        const int error = errno;
        if (error == EEXIST) throw ImageWriteError(fmt::format("{} exists; pass -y to overwrite", final_path.string()));
        if (error != EINVAL && error != ENOSYS)
          throw ImageWriteError(
              fmt::format("cannot write {}: rename failed ({})", final_path.string(), std::strerror(error)));
        // The file system has no RENAME_NOREPLACE: check, then rename.
        if (fs::exists(final_path))
          throw ImageWriteError(fmt::format("{} exists; pass -y to overwrite", final_path.string()));
        if (::rename(path_.c_str(), final_path.c_str()) != 0)
          throw ImageWriteError(
              fmt::format("cannot write {}: rename failed ({})", final_path.string(), std::strerror(errno)));
      }
    }
    path_.clear();
  }

 private:
  fs::path path_;
};

// Holds back SIGINT, SIGTERM, SIGHUP and SIGQUIT of the calling thread while the file is written and renamed,
// so that Ctrl-C cannot leave a temporary file behind; a pending signal is delivered when the block
// ends, after the file is complete (or removed). Lasts a fraction of a second for a frame.
class DeferredTermination {
 public:
  DeferredTermination() {
    sigset_t block;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    sigaddset(&block, SIGHUP);
    sigaddset(&block, SIGQUIT);
    active_ = ::pthread_sigmask(SIG_BLOCK, &block, &previous_) == 0;
  }
  ~DeferredTermination() {
    if (active_) ::pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
  }
  DeferredTermination(const DeferredTermination&) = delete;
  DeferredTermination& operator=(const DeferredTermination&) = delete;

 private:
  sigset_t previous_{};
  bool active_ = false;
};

}  // namespace

bool is_image_file_name(const fs::path& path) { return format_for(path).has_value(); }

void check_image_writable(const fs::path& path, const ImageWriteOptions& options) {
  const auto format = format_for(path);
  if (!format)
    throw ImageWriteError(fmt::format("cannot write {}: unknown image extension '{}' (use .png, .tif, .exr or .jpg)",
                                      path.string(), path.extension().string()));
  if (options.bits != 8 && options.bits != 16)
    throw ImageWriteError(
        fmt::format("cannot write {}: bit depth must be 8 or 16, got {}", path.string(), options.bits));
  if (options.bits == 16 && (*format == FileFormat::jpeg || *format == FileFormat::exr))
    throw ImageWriteError(fmt::format("cannot write {}: 16-bit output needs .png or .tif", path.string()));
  std::error_code ec;
  // symlink_status: a dangling symlink is an existing name too, replaced only with `overwrite`.
  if (!options.overwrite && fs::exists(fs::symlink_status(path, ec)))
    throw ImageWriteError(fmt::format("{} exists; pass -y to overwrite", path.string()));
  if (fs::is_directory(path, ec))
    throw ImageWriteError(fmt::format("cannot write {}: it is a directory", path.string()));
  const fs::path dir = directory_of(path);
  if (!fs::is_directory(dir, ec))
    throw ImageWriteError(fmt::format("cannot write {}: directory {} does not exist", path.string(), dir.string()));
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw ImageWriteError(fmt::format("cannot write {}: directory {} is not writable ({})", path.string(), dir.string(),
                                      std::strerror(errno)));
}

namespace {

// Writes `bytes` over the file at `path` with every write checked: a full disk (ENOSPC) or a file
// size limit (EFBIG) is an error, not a silently truncated file.
void write_bytes(const fs::path& path, const std::vector<unsigned char>& bytes, const fs::path& shown) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  if (fd < 0) throw ImageWriteError(fmt::format("cannot write {}: {}", shown.string(), std::strerror(errno)));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n < 0 ? errno : EIO;
      ::close(fd);
      throw ImageWriteError(fmt::format("cannot write {}: {}", shown.string(), std::strerror(error)));
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) throw ImageWriteError(fmt::format("cannot write {}: {}", shown.string(), std::strerror(errno)));
}

}  // namespace

void write_image_file(const Image& image, const fs::path& path, const ImageWriteOptions& options) {
  check_image_writable(path, options);
  if (image.empty()) throw ImageWriteError(fmt::format("cannot write {}: empty image", path.string()));
  const FileFormat format = *format_for(path);
  // libjpeg's limit; OIIO 2.4 lets libjpeg's error handler exit the process beyond it.
  constexpr int kMaxJpegDimension = 65500;
  if (format == FileFormat::jpeg && (image.width() > kMaxJpegDimension || image.height() > kMaxJpegDimension))
    throw ImageWriteError(fmt::format("cannot write {}: {}x{} exceeds JPEG's limit of {} pixels per side",
                                      path.string(), image.width(), image.height(), kMaxJpegDimension));

  write_file_atomically(path, options.overwrite, [&](const fs::path& temporary) {
    image_library::EncodeOptions encode{
        .format = oiio_format_name(format),
        .sample = options.bits == 16 ? image_library::SampleType::uint16 : image_library::SampleType::uint8,
        .jpeg_quality = 95};
    if (format == FileFormat::exr) encode.sample = image_library::SampleType::half;
    // RGB out of the RGBA floats: a pixel stride of four floats skips alpha.
    write_picture(
        temporary, path,
        {.values = image.data(), .width = image.width(), .height = image.height(), .channels = 3, .pixel_stride = 4},
        encode);
  });
}

void write_picture(const fs::path& temporary, const fs::path& shown, const image_library::Picture& picture,
                   const image_library::EncodeOptions& options) {
  std::optional<std::vector<unsigned char>> encoded;
  try {
    encoded = image_library::encode(picture, options, temporary.string());
  } catch (const image_library::ImageLibraryError& e) {
    throw ImageWriteError(fmt::format("cannot write {}: {}", shown.string(), e.what()));
  }
  if (encoded) write_bytes(temporary, *encoded, shown);
}

void write_file_atomically(const fs::path& path, bool overwrite, const std::function<void(const fs::path&)>& write) {
  const DeferredTermination no_interruptions;  // declared first: ends after the temporary file is gone
  TemporaryFile temp(path);
  write(temp.path());
  temp.commit(path, overwrite);
}

}  // namespace nelf
