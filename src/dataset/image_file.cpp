// Image files: our binary PGM reader and writer, and the dispatch to the image codec module for the rest.
// The PGM path reads with open/read into the caller's Image: nothing is allocated once it has the size, so
// the daemon's replay thread stays allocation-free on a PGM dataset.
#include "mcslam/dataset/image_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "image_codec_loader.hpp"
#include "mcslam/core/error.hpp"

namespace mcslam {

namespace {

constexpr std::size_t kPgmHeaderBytes = 1024;  // read before the pixels: magic, size, maxval and comments
constexpr long kMaxPgmSide = 1 << 15;          // bounds the allocation a corrupt header could ask for
constexpr long kSaturated = 1000000000L;       // header numbers are read up to this (no overflow)

class FileDescriptor {
 public:
  explicit FileDescriptor(const std::string& path) : fd_(::open(path.c_str(), O_RDONLY | O_CLOEXEC)) {
    if (fd_ < 0) throw InputError(path + ": cannot open image: " + std::strerror(errno));
  }
  ~FileDescriptor() { ::close(fd_); }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;

  // The file's size when it is a regular file (-1 for a pipe or a device: only reading tells).
  long long regularSize() const {
    struct stat st {};
    return ::fstat(fd_, &st) == 0 && S_ISREG(st.st_mode) ? static_cast<long long>(st.st_size) : -1;
  }

  // Reads until n bytes or the end of the file; returns the bytes read.
  std::size_t read(uint8_t* out, std::size_t n, const std::string& path) const {
    std::size_t got = 0;
    while (got < n) {
      const ssize_t r = ::read(fd_, out + got, n - got);
      if (r == 0) break;
      if (r < 0 && errno == EINTR) continue;
      if (r < 0) throw InputError(path + ": cannot read image: " + std::strerror(errno));
      got += static_cast<std::size_t>(r);
    }
    return got;
  }

 private:
  int fd_;
};

bool isBinaryPgm(const uint8_t* head, std::size_t n) { return n >= 2 && head[0] == 'P' && head[1] == '5'; }

// The next decimal field of a PGM header at `pos`, after whitespace and '#' comments (which run to the line end).
long pgmField(const uint8_t* head, std::size_t n, std::size_t& pos, const char* field, const std::string& path) {
  while (pos < n && (std::isspace(head[pos]) || head[pos] == '#')) {
    if (head[pos] == '#') {
      while (pos < n && head[pos] != '\n') ++pos;
    } else {
      ++pos;
    }
  }
  long value = 0;
  const std::size_t start = pos;
  while (pos < n && std::isdigit(head[pos])) value = std::min(value * 10 + (head[pos++] - '0'), kSaturated);
  if (pos == start || pos >= n || !std::isspace(head[pos])) {
    const bool cut = pos >= n;
    throw InputError(
        path + ": PGM header: " + field +
        (cut ? (n < kPgmHeaderBytes ? " missing (file truncated)"
                                    : " not found in the first " + std::to_string(kPgmHeaderBytes) + " bytes")
             : " is not a number"));
  }
  return value;
}

InputError tooLarge(const std::string& path, long width, long height, ImageBound bound) {
  return InputError(path + ": image is " + std::to_string(width) + "x" + std::to_string(height) + ", larger than the " +
                    std::to_string(bound.width) + "x" + std::to_string(bound.height) + " this camera has; not decoded");
}

[[noreturn]] void throwTruncated(const std::string& path, long long got, long width, long height) {
  throw InputError(path + ": PGM truncated: " + std::to_string(std::max(got, 0LL)) + " of " +
                   std::to_string(width * height) + " pixel bytes (" + std::to_string(width) + "x" +
                   std::to_string(height) + ")");
}

// Parses the header in head[0, n) (magic already checked), then reads the pixels: those already in `head` and
// the rest straight from the file into `image`.
void readPgmPixels(const FileDescriptor& file, const std::string& path, const uint8_t* head, std::size_t n,
                   Image& image, ImageBound bound) {
  std::size_t pos = 2;
  const long width = pgmField(head, n, pos, "width", path);
  const long height = pgmField(head, n, pos, "height", path);
  const long maxval = pgmField(head, n, pos, "maxval", path);
  ++pos;  // the single whitespace before the pixels
  for (const auto& [name, value] : {std::pair{"width", width}, std::pair{"height", height}}) {
    if (value < 1 || value > kMaxPgmSide)
      throw InputError(path + ": PGM header: " + name + " " + std::to_string(value) +
                       (value == kSaturated ? " or more" : "") + " (expected 1 to " + std::to_string(kMaxPgmSide) +
                       ")");
  }
  if (maxval != 255)
    throw InputError(path + ": PGM header: maxval " + std::to_string(maxval) +
                     (maxval == kSaturated ? " or more" : "") + " (only 8-bit grey with maxval 255 is read" +
                     (maxval > 255 ? "; this is a 16-bit image)" : ")"));
  if (!bound.admits(static_cast<int>(width), static_cast<int>(height))) throw tooLarge(path, width, height, bound);
  const std::size_t total = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  // A short file is refused before the image grows to what its header claims (up to 1 GB for a few bytes).
  const long long size = file.regularSize();
  if (size >= 0 && static_cast<unsigned long long>(size) < pos + total)
    throwTruncated(path, size - static_cast<long long>(pos), width, height);
  image.resize(static_cast<int>(width), static_cast<int>(height));
  const std::size_t buffered = std::min(n - std::min(pos, n), total);
  std::memcpy(image.data(), head + pos, buffered);
  const std::size_t got = buffered + file.read(image.data() + buffered, total - buffered, path);
  if (got < total) throwTruncated(path, static_cast<long long>(got), width, height);
}

std::string printableMagic(const uint8_t* head, std::size_t n) {
  std::string out;
  for (std::size_t i = 0; i < std::min<std::size_t>(n, 2); ++i) {
    char c[8];
    std::snprintf(c, sizeof c, std::isprint(head[i]) ? "%c" : "\\x%02x", head[i]);
    out += c;
  }
  return out;
}

struct DecodeTarget {
  Image& image;
  ImageBound bound;
  bool refused = false;  // larger than the bound
  int width = 0, height = 0;
};

// The codec module asks for the buffer once it knows the size, before decoding where the format's header tells.
uint8_t* growImage(void* context, int width, int height, ptrdiff_t* stride) noexcept {
  DecodeTarget& target = *static_cast<DecodeTarget*>(context);
  if (width < 1 || height < 1) return nullptr;
  if (!target.bound.admits(width, height)) {
    target.refused = true;
    target.width = width;
    target.height = height;
    return nullptr;
  }
  try {
    target.image.resize(width, height);
    *stride = width;
    return target.image.data();
  } catch (...) {
    return nullptr;
  }
}

}  // namespace

void readPgmFile(const std::string& path, Image& image, ImageBound bound) {
  const FileDescriptor file(path);
  uint8_t head[kPgmHeaderBytes];
  const std::size_t n = file.read(head, sizeof head, path);
  if (!isBinaryPgm(head, n))
    throw InputError(path + ": not a binary PGM: starts with '" + printableMagic(head, n) + "' (expected 'P5')");
  readPgmPixels(file, path, head, n, image, bound);
}

void readGreyImageFile(const std::string& path, Image& image, ImageBound bound) {
  {
    const FileDescriptor file(path);
    uint8_t head[kPgmHeaderBytes];
    const std::size_t n = file.read(head, sizeof head, path);
    if (isBinaryPgm(head, n)) return readPgmPixels(file, path, head, n, image, bound);
  }
  const mcslam_image_codec_read_fn read = detail::imageCodecReader(path);
  char reason[512] = {};
  DecodeTarget target{image, bound};
  if (read(path.c_str(), growImage, &target, reason, sizeof reason) == 0) return;
  if (target.refused) throw tooLarge(path, target.width, target.height, bound);
  throw InputError(path + ": " + reason);
}

void writePgmFile(const std::string& path, const ImageView& image) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << "P5\n" << image.width << " " << image.height << "\n255\n";
  for (int y = 0; y < image.height; ++y) out.write(reinterpret_cast<const char*>(image.row(y)), image.width);
  out.flush();
  if (!out) throw InputError(path + ": cannot write image");
}

}  // namespace mcslam
