#include "texture_library.hpp"

#include <algorithm>
#include <filesystem>
#include <map>
#include <mutex>
#include <opencv2/imgproc.hpp>

#include "hash.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/core/worker_pool.hpp"
#include "mcslam/dataset/image_file.hpp"
#include "texture_kinds.hpp"
#include "texture_paint.hpp"

namespace mcslam::sim {

namespace fs = std::filesystem;

namespace {

constexpr int kPhotoSize = 512;  // each photo becomes kPhotoSize^2, mirrored to twice that

bool isImageFile(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg";
}

MipTexture photoTexture(const std::string& path) {
  Image photo;
  readGreyImageFile(path, photo);  // PNG and JPEG through the image codec module, loaded only here
  const cv::Mat grey(photo.height(), photo.width(), CV_8UC1, photo.data());
  const int side = std::min(grey.cols, grey.rows);  // centre square crop
  cv::Mat square = grey(cv::Rect((grey.cols - side) / 2, (grey.rows - side) / 2, side, side));
  cv::Mat small;
  cv::resize(square, small, cv::Size(kPhotoSize, kPhotoSize), 0, 0,
             side > kPhotoSize ? cv::INTER_AREA : cv::INTER_CUBIC);
  cv::Mat right, top, full;
  cv::flip(small, right, 1);
  cv::hconcat(small, right, top);
  cv::Mat bottom;
  cv::flip(top, bottom, 0);
  cv::vconcat(top, bottom, full);
  const std::vector<uint8_t> pixels(full.datastart, full.dataend);
  return MipTexture(full.cols, full.rows, pixels, true);
}

}  // namespace

TextureLibrary::TextureLibrary(uint64_t seed, const std::string& photos_dir) : seed_(seed) {
  if (photos_dir.empty()) return;
  std::error_code ec;
  if (!fs::is_directory(photos_dir, ec)) throw InputError(photos_dir + ": textures folder does not exist");
  for (const auto& entry : fs::directory_iterator(photos_dir, ec)) {
    if (entry.is_regular_file() && isImageFile(entry.path())) photos_.push_back(entry.path().string());
  }
  std::sort(photos_.begin(), photos_.end());  // directory order is not deterministic
  if (photos_.empty()) throw InputError(photos_dir + ": textures folder holds no PNG or JPG image");
}

int TextureLibrary::request(TextureKind kind, int variant) {
  const auto key = std::make_pair(static_cast<int>(kind), variant);
  const auto it = index_.find(key);
  if (it != index_.end()) return it->second;
  const int idx = static_cast<int>(requests_.size());
  index_[key] = idx;
  requests_.emplace_back(kind, variant);
  photo_of_request_.push_back(
      photos_.empty() ? -1
                      : static_cast<int>(hashOf(seed_, static_cast<uint64_t>(kind), static_cast<uint64_t>(variant)) %
                                         photos_.size()));
  return idx;
}

double TextureLibrary::photoTexelSize(int index) const {
  return photo_of_request_.at(index) < 0 ? 0.0 : 1.5 / kPhotoSize;
}

namespace {

// Painted textures are pure functions of (kind, seed): keep them for the next world built in this process (tests
// and benchmarks build the same worlds again). Bounded; texture data is shared, not copied.
class PaintCache {
 public:
  bool find(uint64_t key, MipTexture& out) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = map_.find(key);
    if (it == map_.end()) return false;
    out = it->second;
    return true;
  }
  void store(uint64_t key, const MipTexture& t) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (map_.size() >= 1024) map_.clear();
    map_.emplace(key, t);
  }

 private:
  std::mutex mutex_;
  std::map<uint64_t, MipTexture> map_;
};

PaintCache& paintCache() {
  static PaintCache cache;
  return cache;
}

}  // namespace

std::vector<MipTexture> TextureLibrary::generate(WorkerPool& pool) const {
  std::vector<MipTexture> out(requests_.size());
  std::vector<std::string> errors(requests_.size());
  pool.forEach(static_cast<int>(requests_.size()), [&](int i) {
    try {
      if (photo_of_request_[i] >= 0) {
        out[i] = photoTexture(photos_[photo_of_request_[i]]);
        return;
      }
      const auto [kind, variant] = requests_[i];
      const uint64_t seed = hashOf(seed_, static_cast<uint64_t>(kind) + 1, static_cast<uint64_t>(variant));
      const uint64_t key = hashOf(seed, static_cast<uint64_t>(kind));
      if (paintCache().find(key, out[i])) return;
      const PaintedTexture p = paintTexture(kind, seed);
      out[i] = MipTexture(p.image.cols, p.image.rows, paint::toBytes(p.image), p.tiles);
      paintCache().store(key, out[i]);
    } catch (const std::exception& e) {
      errors[i] = e.what();
    }
  });
  for (const std::string& e : errors) {
    if (!e.empty()) throw InputError(e);
  }
  return out;
}

}  // namespace mcslam::sim
