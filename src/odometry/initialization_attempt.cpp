#include "mcslam/odometry/initialization_attempt.hpp"

namespace mcslam {

InitializationAttempt::InitializationAttempt(Initializer& initializer, int cameras, int max_features_per_camera,
                                             bool on_thread) {
  job_.initializer = &initializer;
  job_.frame.allocate(cameras, max_features_per_camera);
  if (on_thread) task_ = std::make_unique<BackgroundTask>();
}

InitializationAttempt::~InitializationAttempt() {
  if (task_) task_->wait();  // the job reads the initializer and writes itself
}

void InitializationAttempt::submit(const FrameFeatures& frame, uint64_t frame_index) {
  cancel();
  job_.frame = frame;  // within the capacity allocated: the caller's frame buffer may be reused meanwhile
  job_.frame_index = frame_index;
  job_.result = Initializer::TwoFrame::Waiting;
  pending_ = true;
  if (task_) {
    task_->start(job_);
  } else {
    job_.run();
  }
}

Initializer::TwoFrame InitializationAttempt::collect(SE3& T_ref_cur) {
  if (!pending_) return Initializer::TwoFrame::Waiting;
  cancel();  // waits for it; its result stays in the job
  T_ref_cur = job_.T_ref_cur;
  return job_.result;
}

void InitializationAttempt::cancel() {
  if (task_) task_->collect();
  pending_ = false;
}

}  // namespace mcslam
