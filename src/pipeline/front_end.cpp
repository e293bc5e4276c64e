#include "mcslam/pipeline/front_end.hpp"

#include <chrono>

namespace mcslam {

namespace {
std::vector<ImageSize> imageSizes(const Rig& rig) {
  std::vector<ImageSize> sizes;
  for (const RigCamera& c : rig.cameras) sizes.push_back({c.model.width(), c.model.height()});
  return sizes;
}
using Clock = std::chrono::steady_clock;
double msBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}
}  // namespace

FrontEnd::FrontEnd(const Rig& rig, const PipelineConfig& config)
    : rig_(rig),
      capacity_(config.orb.max_features),
      overlap_(rig, config.overlap),
      workers_(config.orb, imageSizes(rig), config.feature_threads),
      matcher_(rig, overlap_, config.multiview, config.orb.max_features, workers_.threads()),
      images_(rig.size()),
      present_(new bool[rig.size()]) {
  workers_.setFollowUp(&matching_tasks_);
}

void FrontEnd::compute(const RigFrameView& frame, FrameFeatures& out) {
  const auto t0 = Clock::now();
  const int cams = rig_.size();
  for (int c = 0; c < cams; ++c) {
    const bool given =
        c < frame.cameras && frame.present && frame.present[c] && frame.images && !frame.images[c].empty();
    present_[c] = false;
    images_[c] = ImageView{};
    if (!given) continue;
    const ImageView& img = frame.images[c];
    if (img.width != rig_.model(c).width() || img.height != rig_.model(c).height()) {
      ++rejected_images_;
      continue;
    }
    images_[c] = img;
    present_[c] = true;
  }
  out.t = frame.t;
  for (int c = 0; c < cams; ++c) out.present[c] = present_[c] ? 1 : 0;  // read by the matching tasks
  matcher_.beginFrame(out, images_.data());                             // the caller's images, alive for the call
  matching_tasks_.setFrame(&out);
  workers_.extract(images_.data(), present_.get(), out.sets.data());  // an absent camera gets no keypoints
  const auto t1 = Clock::now();
  matcher_.mergeFrame(out);
  alignment_tasks_.setFrame(&out);
  workers_.runTasks(alignment_tasks_);  // nothing when the alignment is off
  matcher_.emitTracks(out);
  const auto t2 = Clock::now();
  timing_.extraction_ms = msBetween(t0, t1);
  timing_.multiview_ms = msBetween(t1, t2);
}

}  // namespace mcslam
