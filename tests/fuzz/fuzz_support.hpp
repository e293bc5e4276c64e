#pragma once
// Helpers shared by the fuzz targets: the input as text, and a private temporary folder for readers that only
// take a path (each input is written to a file there and read back through the reader's own path).
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace mcslam::fuzz {

inline std::string text(const uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// One folder per process under $TMPDIR (or /tmp), removed at exit.
class TempFolder {
 public:
  TempFolder() {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/mcslam-fuzz-XXXXXX";
    if (!::mkdtemp(pattern.data())) std::abort();  // no place for the inputs: nothing can be fuzzed
    dir_ = pattern;
  }
  ~TempFolder() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;

  const std::string& dir() const { return dir_; }
  // Writes `bytes` to <dir>/<name> (folders created) and returns its path.
  std::string write(const std::string& name, std::string_view bytes) const {
    const std::filesystem::path path = std::filesystem::path(dir_) / name;
    std::filesystem::create_directories(path.parent_path());
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) std::abort();
    return path.string();
  }

 private:
  std::string dir_;
};

// The process's folder (a function-local static: destroyed, and removed, at exit).
inline const TempFolder& tempFolder() {
  static const TempFolder folder;
  return folder;
}

}  // namespace mcslam::fuzz
