// Finding the image codec module: relative to the executable first (/proc/self/exe, so that a relocated install
// or build tree works), then the build tree's and the install's paths fixed at configure time
// (src/dataset/CMakeLists.txt).
#include "image_codec_loader.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <mutex>

#include "mcslam/core/error.hpp"
#include "mcslam/dataset/image_file.hpp"

namespace mcslam {

namespace fs = std::filesystem;

std::vector<std::string> imageCodecModuleCandidates() {
  std::vector<std::string> out;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path beside = exe.parent_path() / MCSLAM_IMAGE_CODEC_RELATIVE_DIR / MCSLAM_IMAGE_CODEC_FILE_NAME;
    out.push_back(beside.lexically_normal().string());
  }
  for (const char* fixed : {MCSLAM_IMAGE_CODEC_BUILD_PATH, MCSLAM_IMAGE_CODEC_INSTALL_PATH}) {
    if (std::find(out.begin(), out.end(), fixed) == out.end()) out.push_back(fixed);
  }
  return out;
}

namespace detail {

ImageCodecModule loadImageCodecModule(const std::vector<std::string>& candidates) {
  ImageCodecModule module;
  std::string tried;
  for (const std::string& path : candidates) {
    std::string reason;
    std::error_code ec;
    if (!fs::exists(path, ec)) {
      reason = "no such file";
    } else if (void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) {
      const auto abi = reinterpret_cast<mcslam_image_codec_abi_fn>(dlsym(handle, MCSLAM_IMAGE_CODEC_ABI_SYMBOL));
      const auto read = reinterpret_cast<mcslam_image_codec_read_fn>(dlsym(handle, MCSLAM_IMAGE_CODEC_READ_SYMBOL));
      if (abi && read && abi() == MCSLAM_IMAGE_CODEC_ABI_VERSION) {
        module.read = read;
        module.path = path;
        return module;
      }
      reason = abi ? "ABI version " + std::to_string(abi()) + ", this program needs " +
                         std::to_string(MCSLAM_IMAGE_CODEC_ABI_VERSION) + " (stale module: rebuild or reinstall)"
                   : "not an mcslam image codec module";
      dlclose(handle);
    } else {
      const char* why = dlerror();
      reason = why ? why : "dlopen failed";
    }
    tried += (tried.empty() ? "" : "; ") + path + " (" + reason + ")";
  }
  module.failure = "decoding it needs the image codec module " MCSLAM_IMAGE_CODEC_FILE_NAME
                   ", which did not load: tried " +
                   (tried.empty() ? std::string("no path") : tried) +
                   ". Binary PGM needs no module: mcslam-dataset convert --images pgm writes a dataset's images so";
  return module;
}

mcslam_image_codec_read_fn imageCodecReader(const std::string& image) {
  static std::atomic<mcslam_image_codec_read_fn> loaded{nullptr};
  static std::mutex mutex;
  static bool tried = false;
  static std::string failure;
  if (const auto read = loaded.load(std::memory_order_acquire)) return read;
  std::lock_guard<std::mutex> lock(mutex);
  if (!tried) {
    tried = true;
    const ImageCodecModule module = loadImageCodecModule(imageCodecModuleCandidates());
    failure = module.failure;
    loaded.store(module.read, std::memory_order_release);
  }
  if (const auto read = loaded.load(std::memory_order_acquire)) return read;
  throw InputError(image + ": not a binary 8-bit PGM, and " + failure);
}

}  // namespace detail
}  // namespace mcslam
