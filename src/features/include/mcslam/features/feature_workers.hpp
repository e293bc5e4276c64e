#pragma once
// Per-camera ORB extraction on persistent worker threads (a WorkerPool), one rig frame at a time.
//
// One thread per camera, or a pool of hardware_concurrency() threads when there are more cameras than
// cores (threads take the next camera in order). One OrbExtractor per thread, sized for the
// largest camera: an extractor's buffers are scratch, so a camera's output does not depend on which
// extractor ran it, and five cameras on two threads keep two extractors' buffers, not five.
// extract() is the per-rig-frame barrier: it returns when every camera is done. The threads start in
// the constructor and stop in the destructor; a frame allocates nothing. A camera's output depends
// only on its image, never on which thread ran it.
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <utility>
#include <vector>

#include "mcslam/core/worker_pool.hpp"
#include "mcslam/features/orb_extractor.hpp"

namespace mcslam {

struct ImageSize {
  int width = 0, height = 0;
};

// Independent tasks run on the workers (FeatureWorkers::runTasks()), each once.
class WorkerTasks {
 public:
  virtual ~WorkerTasks() = default;
  virtual int taskCount() const = 0;
  // `thread` is the worker's index, so that concurrent tasks may use distinct scratch.
  virtual void runTask(int task, int thread) = 0;
};

// Work of a rig frame that depends on extracted cameras, run on the same threads so that it fills their idle
// time (five cameras on two threads leave one thread idle during the last camera). Its tasks (taskCount(),
// runTask()) are the frame's: task t starts once afterCamera() returned for both of its cameras.
class ExtractionFollowUp : public WorkerTasks {
 public:
  // On the thread that extracted `camera` (absent or not), right after it.
  virtual void afterCamera(int camera) = 0;
  virtual std::pair<int, int> taskCameras(int task) const = 0;
};

class FeatureWorkers {
 public:
  // max_sizes: the largest image of each camera. threads <= 0: min(cameras, hardware_concurrency()).
  // Throws mcslam::InputError on bad options or no camera.
  FeatureWorkers(const OrbOptions& options, const std::vector<ImageSize>& max_sizes, int threads = 0);
  FeatureWorkers(const FeatureWorkers&) = delete;
  FeatureWorkers& operator=(const FeatureWorkers&) = delete;

  // images, present and out have one entry per camera; out[c] needs capacity >= max_features.
  // An absent camera gets zero features. status (optional, one per camera) receives each result.
  void extract(const ImageView* images, const bool* present, FeatureSet* out, OrbStatus* status = nullptr);

  // Runs every task of `tasks` on the worker threads, each once, and returns when all are done (a barrier like
  // extract()). Allocates nothing.
  void runTasks(WorkerTasks& tasks);

  // Runs `follow_up` (nullptr: none) within every following extract(); call between frames. Allocates its
  // bookkeeping here, so a frame still allocates nothing.
  void setFollowUp(ExtractionFollowUp* follow_up);

  int cameras() const { return static_cast<int>(max_sizes_.size()); }
  int threads() const { return pool_.threads(); }
  // The extractor of worker thread `thread` (sized for the largest camera).
  const OrbExtractor& extractor(int thread) const { return extractors_[static_cast<size_t>(thread)]; }

 private:
  // A rig frame as one batch of the pool: tasks [0, cameras) extract the cameras, the follow-up's tasks come
  // after them. The pool hands tasks out in index order, so when a follow-up task is taken every camera has a
  // thread: it takes any follow-up task whose cameras are done, waiting for one if none is yet.
  struct FrameJob final : PoolJob {
    explicit FrameJob(FeatureWorkers& w) : workers(w) {}
    void run(int task, int thread) override { workers.runFrameTask(task, thread); }
    FeatureWorkers& workers;
  };
  struct BatchJob final : PoolJob {  // runTasks()'s
    void run(int task, int thread) override { tasks->runTask(task, thread); }
    WorkerTasks* tasks = nullptr;
  };
  void runFrameTask(int task, int thread);
  void processCamera(int camera, OrbExtractor& extractor);
  int takeReadyTask();  // -1 when no untaken task has both cameras done (caller holds mutex_)

  std::vector<ImageSize> max_sizes_;      // per camera: an image larger than this is refused
  std::vector<OrbExtractor> extractors_;  // per thread

  std::mutex mutex_;  // the follow-up's bookkeeping during a frame
  std::condition_variable camera_done_;
  ExtractionFollowUp* follow_up_ = nullptr;
  int tasks_ = 0;               // of the follow-up, per frame
  std::vector<uint8_t> done_;   // per camera, this frame (guarded by mutex_)
  std::vector<uint8_t> taken_;  // per task, this frame (guarded by mutex_)

  // The current frame's arguments, valid during extract().
  const ImageView* images_ = nullptr;
  const bool* present_ = nullptr;
  FeatureSet* out_ = nullptr;
  OrbStatus* status_ = nullptr;

  FrameJob frame_job_{*this};
  BatchJob batch_job_;
  WorkerPool pool_;  // last: its threads stop before the members above go
};

}  // namespace mcslam
