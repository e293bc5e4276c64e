#include "mcslam/features/multiview_matcher.hpp"

#include <string>

#include "mcslam/core/error.hpp"

namespace mcslam {

namespace {
int checkedThreads(int threads) {
  if (threads < 1) throw InputError("multi-view features: threads = " + std::to_string(threads) + ", at least 1");
  return threads;
}
}  // namespace

MultiViewMatcher::MultiViewMatcher(const Rig& rig, const OverlapMap& overlap, const MultiViewOptions& options,
                                   int max_features_per_camera, int threads)
    : rig_(rig),
      bearings_(rig),
      pairs_(overlap, options, max_features_per_camera, checkedThreads(threads)),
      tracks_(overlap, options, max_features_per_camera),
      align_subpixel_(options.align_subpixel) {}

void MultiViewMatcher::compute(FrameFeatures& f, const ImageView* images) {
  beginFrame(f, images);
  for (int c = 0; c < f.cameras(); ++c) prepareCamera(f, c);
  for (int p = 0; p < pairCount(); ++p) matchPair(f, p, 0);
  finishFrame(f);
}

void MultiViewMatcher::beginFrame(FrameFeatures& f, const ImageView* images) {
  images_ = align_subpixel_ ? images : nullptr;
  f.mv_count = 0;
  f.mv_ref_count = 0;
  pairs_.beginFrame();
}

void MultiViewMatcher::prepareCamera(FrameFeatures& f, int camera) {
  bearings_.compute(rig_, f, camera);
  pairs_.prepareCamera(rig_, f, camera);
}

void MultiViewMatcher::matchPair(const FrameFeatures& f, int pair, int thread) {
  pairs_.matchPair(rig_, f, pair, thread);
}

void MultiViewMatcher::finishFrame(FrameFeatures& f) {
  mergeFrame(f);
  for (int task = 0; task < alignTaskCount(); ++task) alignTracks(f, task);
  emitTracks(f);
}

void MultiViewMatcher::mergeFrame(FrameFeatures& f) { tracks_.merge(f, pairs_.gather(), images_ != nullptr); }

void MultiViewMatcher::alignTracks(const FrameFeatures& f, int task) {
  tracks_.alignTracks(rig_, bearings_, images_, f, task);
}

void MultiViewMatcher::emitTracks(FrameFeatures& f) {
  tracks_.emitTracks(rig_, f);
  images_ = nullptr;
}

}  // namespace mcslam
