// mcslamd and mcslam-run run the SLAM pipeline in two stages (FrameProcessor::prepare, then finish) with
// StageRunner, on two threads (the front-end of frame i+1 is prepared before frame i is finished) or on one.
// The poses must be those of process() either way.
#include <gtest/gtest.h>

#include <cstring>
#include <thread>
#include <vector>

#include "mcslam/dataset/dataset.hpp"
#include "mcslam/pipeline/pipeline_factory.hpp"
#include "mcslam/pipeline/stage_runner.hpp"
#include "sim_dataset_fixture.hpp"

using namespace mcslam;

namespace {

struct LoadedFrame {
  std::vector<Image> images;
  std::vector<bool> present;
  bool here[8] = {};
  ImageView views[8];
  RigFrameView view(const Dataset& d, std::size_t i) {
    for (std::size_t c = 0; c < images.size(); ++c) {
      views[c] = images[c].view();
      here[c] = present[c];
    }
    return RigFrameView{d.frames()[i].t, i, static_cast<int>(images.size()), views, here};
  }
};

bool samePose(const PoseEstimate& a, const PoseEstimate& b) {
  return a.t == b.t && a.sequence == b.sequence && a.state == b.state && a.is_keyframe == b.is_keyframe &&
         a.valid == b.valid && a.quality == b.quality &&
         std::memcmp(a.T_w_b.t.data(), b.T_w_b.t.data(), 3 * sizeof(double)) == 0 &&
         std::memcmp(a.T_w_b.R.data(), b.T_w_b.R.data(), 9 * sizeof(double)) == 0;
}

// The daemon's order, prepare(i + 1) before finish(i) with the slots in turn, against process().
void expectStagesGiveTheSamePosesAsProcess(const YAML::Node& slam, const Rig& rig) {
  const Dataset dataset = Dataset::open(test::cachedSimDataset());
  const std::size_t n = dataset.size();
  std::vector<LoadedFrame> frames(n);
  for (std::size_t i = 0; i < n; ++i) dataset.loadImages(i, frames[i].images, frames[i].present, nullptr);
  auto whole = createPipeline(slam, "test", rig);
  auto staged = createPipeline(slam, "test", rig);
  ASSERT_GE(staged->stageSlots(), 2);

  std::vector<PoseEstimate> expected(n), got(n);
  for (std::size_t i = 0; i < n; ++i) whole->process(frames[i].view(dataset, i), expected[i]);
  const int slots = staged->stageSlots();
  staged->prepare(frames[0].view(dataset, 0), 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (i + 1 < n) staged->prepare(frames[i + 1].view(dataset, i + 1), static_cast<int>((i + 1) % slots));
    staged->finish(static_cast<int>(i % slots), got[i]);
  }
  int tracked = 0;
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_TRUE(samePose(expected[i], got[i])) << "frame " << i;
    tracked += got[i].state == TrackingState::Tracking ? 1 : 0;
  }
  EXPECT_GT(tracked, static_cast<int>(n) - 3);  // the comparison is between real estimates
}

// StageRunner with the prepare side on a thread of its own (overlap) or on the caller's (without).
std::vector<PoseEstimate> runWithStageRunner(FrameProcessor& processor, const Dataset& dataset,
                                             std::vector<LoadedFrame>& frames, bool overlap) {
  StageRunner<std::size_t> runner(processor);
  const std::size_t n = frames.size();
  std::vector<PoseEstimate> poses(n);
  std::thread front_end;
  if (overlap) {
    front_end = std::thread([&] {
      for (std::size_t i = 0; i < n; ++i) runner.prepare(frames[i].view(dataset, i), i);
      runner.close();
    });
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!overlap) runner.prepare(frames[i].view(dataset, i), i);
    std::size_t tag = n;
    EXPECT_TRUE(runner.finish(poses[i], tag));
    EXPECT_EQ(tag, i);
  }
  if (front_end.joinable()) front_end.join();
  return poses;
}

}  // namespace

TEST(PipelineStages, TheStageRunnerGivesTheSamePosesWithAndWithoutOverlapAsProcess) {
  const Dataset dataset = Dataset::open(test::cachedSimDataset());
  const std::size_t n = dataset.size();
  std::vector<LoadedFrame> frames(n);
  for (std::size_t i = 0; i < n; ++i) dataset.loadImages(i, frames[i].images, frames[i].present, nullptr);
  const YAML::Node defaults(YAML::NodeType::Map);
  auto whole = createPipeline(defaults, "test", dataset.rig());
  auto overlapped = createPipeline(defaults, "test", dataset.rig());
  auto one_thread = createPipeline(defaults, "test", dataset.rig());
  std::vector<PoseEstimate> expected(n);
  for (std::size_t i = 0; i < n; ++i) whole->process(frames[i].view(dataset, i), expected[i]);
  const std::vector<PoseEstimate> with = runWithStageRunner(*overlapped, dataset, frames, true);
  const std::vector<PoseEstimate> without = runWithStageRunner(*one_thread, dataset, frames, false);
  int tracked = 0;
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_TRUE(samePose(expected[i], with[i])) << "overlapped, frame " << i;
    EXPECT_TRUE(samePose(expected[i], without[i])) << "one thread, frame " << i;
    tracked += with[i].state == TrackingState::Tracking ? 1 : 0;
  }
  EXPECT_GT(tracked, static_cast<int>(n) - 3);  // the comparison is between real estimates
}

TEST(PipelineStages, PreparingTheNextFrameBeforeFinishingThisOneGivesTheSamePosesAsProcess) {
  const YAML::Node defaults(YAML::NodeType::Map);
  expectStagesGiveTheSamePosesAsProcess(defaults, Dataset::open(test::cachedSimDataset()).rig());
}

// With refinement on, the odometry re-estimates and refines extrinsics while the next frame is prepared: the
// stages must still give process()'s poses, also when a camera's calibration is off by a degree.
TEST(PipelineStages, WithExtrinsicRefinementGivesTheSamePosesAsProcess) {
  const YAML::Node slam = YAML::Load("backend:\n  refine_extrinsics: on\n");
  Rig rig = Dataset::open(test::cachedSimDataset()).rig();
  SE3& T = rig.cameras[3].T_b_c;
  T.t += Vec3(0.012, -0.01, 0.012);
  T.R = so3Exp(Vec3(0.2, 1.0, -0.4).normalized() * M_PI / 180.0) * T.R;
  expectStagesGiveTheSamePosesAsProcess(slam, rig);
}
