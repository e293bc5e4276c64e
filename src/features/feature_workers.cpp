#include "mcslam/features/feature_workers.hpp"

#include <algorithm>
#include <string>

#include "mcslam/core/error.hpp"

namespace mcslam {

namespace {
// threads <= 0: one per camera up to the cores; never more than the cameras (a thread without one would only wait).
int workerCount(int threads, int cameras) {
  if (threads <= 0) threads = std::min(cameras, WorkerPool::hardwareThreads());
  return std::max(0, std::min(threads, cameras));
}
}  // namespace

FeatureWorkers::FeatureWorkers(const OrbOptions& options, const std::vector<ImageSize>& max_sizes, int threads)
    : max_sizes_(max_sizes), pool_(workerCount(threads, static_cast<int>(max_sizes.size()))) {
  if (max_sizes.empty()) throw InputError("FeatureWorkers: cameras = 0: at least one camera is needed");
  ImageSize largest;
  for (const ImageSize& size : max_sizes) {
    largest.width = std::max(largest.width, size.width);
    largest.height = std::max(largest.height, size.height);
  }
  done_.assign(static_cast<size_t>(cameras()), 0);
  extractors_.reserve(static_cast<size_t>(pool_.threads()));
  for (int i = 0; i < pool_.threads(); ++i) extractors_.emplace_back(options, largest.width, largest.height);
}

void FeatureWorkers::setFollowUp(ExtractionFollowUp* follow_up) {
  follow_up_ = follow_up;
  tasks_ = follow_up != nullptr ? follow_up->taskCount() : 0;
  taken_.assign(static_cast<size_t>(tasks_), 0);
}

void FeatureWorkers::extract(const ImageView* images, const bool* present, FeatureSet* out, OrbStatus* status) {
  images_ = images;
  present_ = present;
  out_ = out;
  status_ = status;
  std::fill(done_.begin(), done_.end(), 0);
  std::fill(taken_.begin(), taken_.end(), 0);
  pool_.submit(frame_job_, cameras() + tasks_);
  pool_.wait();
}

void FeatureWorkers::runTasks(WorkerTasks& tasks) {
  const int count = tasks.taskCount();
  if (count <= 0) return;
  batch_job_.tasks = &tasks;
  pool_.submit(batch_job_, count);
  pool_.wait();
  batch_job_.tasks = nullptr;
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

void FeatureWorkers::runFrameTask(int task, int thread) {
  if (task < cameras()) {
    processCamera(task, extractors_[static_cast<size_t>(thread)]);
    if (follow_up_ == nullptr) return;
    follow_up_->afterCamera(task);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_[static_cast<size_t>(task)] = 1;
    }
    camera_done_.notify_all();
    return;
  }
  // A follow-up task: whichever is ready first (the pool counts them, the order is ours).
  int ready = -1;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    camera_done_.wait(lock, [&] { return (ready = takeReadyTask()) >= 0; });
  }
  follow_up_->runTask(ready, thread);
}

int FeatureWorkers::takeReadyTask() {
  for (int t = 0; t < tasks_; ++t) {
    if (taken_[static_cast<size_t>(t)]) continue;
    const auto [a, b] = follow_up_->taskCameras(t);
    if (!done_[static_cast<size_t>(a)] || !done_[static_cast<size_t>(b)]) continue;
    taken_[static_cast<size_t>(t)] = 1;
    return t;
  }
  return -1;
}

}  // namespace mcslam
