// The daemon runs the SLAM pipeline in two stages on two threads (FrameProcessor::prepare, then finish):
// the front-end of frame i+1 is prepared before frame i is finished. The poses must be those of process().
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "mcslam/dataset/dataset.hpp"
#include "mcslam/pipeline/pipeline_factory.hpp"
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
         a.valid == b.valid && a.quality == b.quality && std::memcmp(a.T_w_b.t.data(), b.T_w_b.t.data(), 3 * sizeof(double)) == 0 &&
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

}  // namespace

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
