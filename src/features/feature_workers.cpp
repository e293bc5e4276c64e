#include "mcslam/features/feature_workers.hpp"

#include <algorithm>
#include <string>

#include "mcslam/core/error.hpp"

namespace mcslam {

FeatureWorkers::FeatureWorkers(const OrbOptions& options, const std::vector<ImageSize>& max_sizes, int threads) {
  if (max_sizes.empty()) throw InputError("FeatureWorkers: cameras = 0: at least one camera is needed");
  extractors_.reserve(max_sizes.size());
  for (const ImageSize& size : max_sizes) extractors_.emplace_back(options, size.width, size.height);
  if (threads <= 0) {
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    threads = std::min(cameras(), cores);
  }
  threads = std::min(threads, cameras());  // a thread without a camera would only wait
  threads_.reserve(static_cast<size_t>(threads));
  for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { run(); });
}

FeatureWorkers::~FeatureWorkers() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  work_ready_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void FeatureWorkers::extract(const ImageView* images, const bool* present, FeatureSet* out, OrbStatus* status) {
  std::unique_lock<std::mutex> lock(mutex_);
  images_ = images;
  present_ = present;
  out_ = out;
  status_ = status;
  next_camera_ = 0;
  remaining_ = cameras();
  ++frame_;
  work_ready_.notify_all();
  work_done_.wait(lock, [this] { return remaining_ == 0; });
}

void FeatureWorkers::processCamera(int camera) {
  FeatureSet& out = out_[camera];
  OrbStatus result = OrbStatus::kOk;
  if (present_[camera]) {
    result = extractors_[static_cast<size_t>(camera)].extract(images_[camera], out);
  } else {
    out.clear();
  }
  if (status_ != nullptr) status_[camera] = result;
}

void FeatureWorkers::run() {
  uint64_t seen = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    work_ready_.wait(lock, [&] { return stopping_ || frame_ != seen; });
    if (stopping_) return;
    seen = frame_;
    // Take cameras until none is left for this frame; extract outside the lock.
    while (next_camera_ < cameras()) {
      const int camera = next_camera_++;
      lock.unlock();
      processCamera(camera);
      lock.lock();
      if (--remaining_ == 0) work_done_.notify_one();
    }
  }
}

}  // namespace mcslam
