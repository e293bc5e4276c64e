#include "mcslam/features/feature_workers.hpp"

#include <algorithm>
#include <string>

#include "mcslam/core/error.hpp"

namespace mcslam {

FeatureWorkers::FeatureWorkers(const OrbOptions& options, const std::vector<ImageSize>& max_sizes, int threads)
    : max_sizes_(max_sizes) {
  if (max_sizes.empty()) throw InputError("FeatureWorkers: cameras = 0: at least one camera is needed");
  ImageSize largest;
  for (const ImageSize& size : max_sizes) {
    largest.width = std::max(largest.width, size.width);
    largest.height = std::max(largest.height, size.height);
  }
  if (threads <= 0) {
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    threads = std::min(cameras(), cores);
  }
  threads = std::min(threads, cameras());  // a thread without a camera would only wait
  done_.assign(static_cast<size_t>(cameras()), 0);
  extractors_.reserve(static_cast<size_t>(threads));
  for (int i = 0; i < threads; ++i) extractors_.emplace_back(options, largest.width, largest.height);
  threads_.reserve(static_cast<size_t>(threads));
  for (int i = 0; i < threads; ++i) threads_.emplace_back([this, i] { run(i); });
}

FeatureWorkers::~FeatureWorkers() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  work_ready_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void FeatureWorkers::setFollowUp(ExtractionFollowUp* follow_up) {
  std::lock_guard<std::mutex> lock(mutex_);
  follow_up_ = follow_up;
  tasks_ = follow_up != nullptr ? follow_up->taskCount() : 0;
  taken_.assign(static_cast<size_t>(tasks_), 0);
}

void FeatureWorkers::extract(const ImageView* images, const bool* present, FeatureSet* out, OrbStatus* status) {
  std::unique_lock<std::mutex> lock(mutex_);
  images_ = images;
  present_ = present;
  out_ = out;
  status_ = status;
  next_camera_ = 0;
  std::fill(done_.begin(), done_.end(), 0);
  std::fill(taken_.begin(), taken_.end(), 0);
  untaken_tasks_ = tasks_;
  remaining_ = cameras() + tasks_;
  ++frame_;
  work_ready_.notify_all();
  work_done_.wait(lock, [this] { return remaining_ == 0; });
}

void FeatureWorkers::runTasks(WorkerTasks& tasks) {
  std::unique_lock<std::mutex> lock(mutex_);
  const int count = tasks.taskCount();
  if (count <= 0) return;
  batch_ = &tasks;
  batch_next_ = 0;
  batch_count_ = count;
  next_camera_ = cameras();  // no camera to extract, no follow-up task
  untaken_tasks_ = 0;
  remaining_ = count;
  ++frame_;
  work_ready_.notify_all();
  work_done_.wait(lock, [this] { return remaining_ == 0; });
  batch_ = nullptr;
}

void FeatureWorkers::processCamera(int camera, OrbExtractor& extractor) {
  FeatureSet& out = out_[camera];
  OrbStatus result = OrbStatus::kOk;
  const ImageSize& max_size = max_sizes_[static_cast<size_t>(camera)];
  if (present_[camera] && out.capacity() >= extractor.options().max_features &&
      (images_[camera].width > max_size.width || images_[camera].height > max_size.height)) {
    out.clear();  // as an extractor sized for this camera alone would answer
    result = OrbStatus::kImageTooLarge;
  } else if (present_[camera]) {
    result = extractor.extract(images_[camera], out);
  } else {
    out.clear();
  }
  if (status_ != nullptr) status_[camera] = result;
}

void FeatureWorkers::run(int thread) {
  OrbExtractor& extractor = extractors_[static_cast<size_t>(thread)];
  uint64_t seen = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    work_ready_.wait(lock, [&] { return stopping_ || frame_ != seen; });
    if (stopping_) return;
    seen = frame_;
    // Cameras first (the tasks wait for them), then the tasks whose cameras are done; work outside the lock.
    while (true) {
      if (next_camera_ < cameras()) {
        const int camera = next_camera_++;
        lock.unlock();
        processCamera(camera, extractor);
        if (follow_up_ != nullptr) follow_up_->afterCamera(camera);
        lock.lock();
        done_[static_cast<size_t>(camera)] = 1;
        camera_done_.notify_all();
      } else if (untaken_tasks_ > 0) {
        const int task = takeReadyTask();
        if (task < 0) {  // its cameras are being extracted by other threads
          camera_done_.wait(lock);
          continue;
        }
        lock.unlock();
        follow_up_->runTask(task, thread);
        lock.lock();
      } else if (batch_ != nullptr && batch_next_ < batch_count_) {
        const int task = batch_next_++;
        lock.unlock();
        batch_->runTask(task, thread);
        lock.lock();
      } else {
        break;
      }
      if (--remaining_ == 0) work_done_.notify_one();
    }
  }
}

int FeatureWorkers::takeReadyTask() {
  for (int t = 0; t < tasks_; ++t) {
    if (taken_[static_cast<size_t>(t)]) continue;
    const auto [a, b] = follow_up_->taskCameras(t);
    if (!done_[static_cast<size_t>(a)] || !done_[static_cast<size_t>(b)]) continue;
    taken_[static_cast<size_t>(t)] = 1;
    --untaken_tasks_;
    return t;
  }
  return -1;
}

}  // namespace mcslam
