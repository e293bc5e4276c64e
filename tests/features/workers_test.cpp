// FeatureWorkers: same features as one extractor per camera, whatever the thread count; absent
// cameras; follow-up tasks run once each, after both of their cameras; no allocation per rig frame; clean
// start and stop.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "alloc_testing.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/features/feature_workers.hpp"
#include "orb_test_images.hpp"

namespace mcslam {
namespace {

constexpr int kCameras = 5;

struct Rig {
  std::vector<Image> images;
  std::vector<ImageView> views;
  std::vector<ImageSize> sizes;
  Rig() {
    for (int c = 0; c < kCameras; ++c) {
      // Different sizes per camera: each extractor is sized for its own camera.
      images.push_back(test::texturedFrame(320 - 16 * c, 240 - 8 * c, 100 + c));
      sizes.push_back({images.back().width(), images.back().height()});
    }
    for (const Image& image : images) views.push_back(image.view());
  }
};

const Rig& rig() {
  static const Rig r;
  return r;
}

OrbOptions options() {
  OrbOptions o;
  o.max_features = 400;
  return o;
}

std::vector<FeatureSet> makeSets() { return std::vector<FeatureSet>(kCameras, FeatureSet(options().max_features)); }

void expectSame(const FeatureSet& a, const FeatureSet& b) {
  ASSERT_EQ(a.count, b.count);
  for (int i = 0; i < a.count; ++i) {
    ASSERT_EQ(a.keypoints[i].x, b.keypoints[i].x);
    ASSERT_EQ(a.keypoints[i].y, b.keypoints[i].y);
    ASSERT_EQ(a.keypoints[i].angle, b.keypoints[i].angle);
    ASSERT_EQ(a.keypoints[i].octave, b.keypoints[i].octave);
    ASSERT_EQ(a.descriptors[i], b.descriptors[i]);
  }
}

TEST(FeatureWorkers, SameFeaturesAsSequentialExtractionForAnyThreadCount) {
  std::vector<FeatureSet> expected = makeSets();
  for (int c = 0; c < kCameras; ++c) {
    OrbExtractor extractor(options(), rig().sizes[c].width, rig().sizes[c].height);
    ASSERT_EQ(extractor.extract(rig().views[c], expected[c]), OrbStatus::kOk);
    ASSERT_GT(expected[c].count, 300);
  }
  const bool present[kCameras] = {true, true, true, true, true};
  for (int threads : {1, 2, 3, 5, 8}) {
    FeatureWorkers workers(options(), rig().sizes, threads);
    EXPECT_EQ(workers.threads(), std::min(threads, kCameras));
    std::vector<FeatureSet> out = makeSets();
    for (int frame = 0; frame < 3; ++frame) {  // the same frame again gives the same answer
      OrbStatus status[kCameras];
      workers.extract(rig().views.data(), present, out.data(), status);
      for (int c = 0; c < kCameras; ++c) {
        EXPECT_EQ(status[c], OrbStatus::kOk);
        expectSame(out[c], expected[c]);
      }
    }
  }
}

TEST(FeatureWorkers, DefaultPoolIsOneThreadPerCameraUpToTheCores) {
  FeatureWorkers workers(options(), rig().sizes);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  EXPECT_EQ(workers.threads(), std::min(kCameras, cores));
  EXPECT_EQ(workers.cameras(), kCameras);
  EXPECT_THROW(FeatureWorkers(options(), {}), InputError);
}

TEST(FeatureWorkers, AbsentCamerasGetNoFeatures) {
  FeatureWorkers workers(options(), rig().sizes, 2);
  std::vector<FeatureSet> out = makeSets();
  for (FeatureSet& set : out) set.count = 7;  // stale values must be cleared
  const bool present[kCameras] = {true, false, true, false, false};
  workers.extract(rig().views.data(), present, out.data());
  EXPECT_GT(out[0].count, 0);
  EXPECT_EQ(out[1].count, 0);
  EXPECT_GT(out[2].count, 0);
  EXPECT_EQ(out[3].count, 0);
  EXPECT_EQ(out[4].count, 0);
}

TEST(FeatureWorkers, ImageLargerThanItsCameraIsRefusedEvenIfAnotherCameraIsThatLarge) {
  // The extractors are shared and sized for the largest camera; the limit stays per camera.
  FeatureWorkers workers(options(), rig().sizes, 2);
  std::vector<FeatureSet> out = makeSets();
  std::vector<ImageView> views = rig().views;
  views[4] = rig().views[0];  // camera 0's image is larger than camera 4's size
  const bool present[kCameras] = {true, true, true, true, true};
  OrbStatus status[kCameras];
  out[4].count = 7;
  workers.extract(views.data(), present, out.data(), status);
  EXPECT_EQ(status[0], OrbStatus::kOk);
  EXPECT_GT(out[0].count, 0);
  EXPECT_EQ(status[4], OrbStatus::kImageTooLarge);
  EXPECT_EQ(out[4].count, 0);
}

TEST(FeatureWorkers, RigFramesAllocateNothingOnAnyThread) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  FeatureWorkers workers(options(), rig().sizes, 2);
  std::vector<FeatureSet> out = makeSets();
  const bool present[kCameras] = {true, true, false, true, true};
  workers.extract(rig().views.data(), present, out.data());  // warm-up
  const uint64_t before = alloc::totalCount();               // all threads of the process
  for (int frame = 0; frame < 5; ++frame) workers.extract(rig().views.data(), present, out.data());
  EXPECT_EQ(alloc::totalCount() - before, 0u);
  EXPECT_GT(out[4].count, 0);
}

// Records, per frame, when each camera's follow-up ran and whether each task saw both of its cameras done.
class RecordingFollowUp : public ExtractionFollowUp {
 public:
  explicit RecordingFollowUp(const std::vector<FeatureSet>& out) : out_(out) {
    for (int a = 0; a < kCameras; ++a) {
      for (int b = a + 1; b < kCameras; ++b) pairs_.push_back({a, b});
    }
    pairs_.push_back({4, 0});  // any order of the two cameras
  }
  void reset() {
    for (auto& d : camera_done_) d = 0;
    for (auto& r : task_runs_) r = 0;
    for (auto& ok : task_saw_cameras_) ok = 1;
  }
  void afterCamera(int camera) override {
    seen_count_[camera] = out_[static_cast<size_t>(camera)].count;  // the camera's features are final
    camera_done_[camera].store(1);
  }
  int taskCount() const override { return static_cast<int>(pairs_.size()); }
  std::pair<int, int> taskCameras(int task) const override { return pairs_[static_cast<size_t>(task)]; }
  void runTask(int task, int thread) override {
    const auto [a, b] = pairs_[static_cast<size_t>(task)];
    if (!camera_done_[a].load() || !camera_done_[b].load()) task_saw_cameras_[task].store(0);
    if (thread < 0 || thread >= 2) task_saw_cameras_[task].store(0);
    task_runs_[task].fetch_add(1);
  }

  const std::vector<FeatureSet>& out_;
  std::vector<std::pair<int, int>> pairs_;
  std::atomic<int> camera_done_[kCameras] = {};
  int seen_count_[kCameras] = {};
  std::atomic<int> task_runs_[16] = {};
  std::atomic<int> task_saw_cameras_[16] = {};
};

TEST(FeatureWorkers, FollowUpTasksRunOnceEachAfterBothOfTheirCameras) {
  FeatureWorkers workers(options(), rig().sizes, 2);
  std::vector<FeatureSet> out = makeSets();
  RecordingFollowUp follow_up(out);
  ASSERT_LE(follow_up.taskCount(), 16);
  workers.setFollowUp(&follow_up);
  bool present[kCameras] = {true, true, true, true, true};
  for (int frame = 0; frame < 40; ++frame) {
    present[frame % kCameras] = frame % 3 != 0;  // absent cameras still release their tasks
    follow_up.reset();
    workers.extract(rig().views.data(), present, out.data());
    for (int c = 0; c < kCameras; ++c) {
      ASSERT_EQ(follow_up.camera_done_[c].load(), 1) << "frame " << frame << " camera " << c;
      ASSERT_EQ(follow_up.seen_count_[c], out[c].count) << "frame " << frame << " camera " << c;
    }
    for (int t = 0; t < follow_up.taskCount(); ++t) {
      ASSERT_EQ(follow_up.task_runs_[t].load(), 1) << "frame " << frame << " task " << t;
      ASSERT_EQ(follow_up.task_saw_cameras_[t].load(), 1) << "frame " << frame << " task " << t;
    }
  }
  workers.setFollowUp(nullptr);  // and without it again
  follow_up.reset();
  workers.extract(rig().views.data(), present, out.data());
  EXPECT_EQ(follow_up.task_runs_[0].load(), 0);
}

TEST(FeatureWorkers, FollowUpAllocatesNothingPerFrame) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  FeatureWorkers workers(options(), rig().sizes, 2);
  std::vector<FeatureSet> out = makeSets();
  RecordingFollowUp follow_up(out);
  workers.setFollowUp(&follow_up);
  const bool present[kCameras] = {true, true, false, true, true};
  workers.extract(rig().views.data(), present, out.data());  // warm-up
  const uint64_t before = alloc::totalCount();
  for (int frame = 0; frame < 5; ++frame) workers.extract(rig().views.data(), present, out.data());
  EXPECT_EQ(alloc::totalCount() - before, 0u);
}

TEST(FeatureWorkers, StartsAndStopsCleanly) {
  // Destroyed right after construction, after one frame, and with more threads than cameras asked.
  for (int round = 0; round < 20; ++round) {
    FeatureWorkers workers(options(), rig().sizes, 1 + round % 6);
    if (round % 2 == 0) {
      std::vector<FeatureSet> out = makeSets();
      const bool present[kCameras] = {true, true, true, true, true};
      workers.extract(rig().views.data(), present, out.data());
      EXPECT_GT(out[0].count, 0);
    }
  }
}

}  // namespace
}  // namespace mcslam
