// mcslam-init-probe: how well can this rig initialize from two frames? For reference frames along a dataset
// and several frame gaps, runs the two-frame initialization's matching and generalized relative pose (as the
// odometry does), and compares the metric translation with the ground truth. Prints one line per pair and a
// summary: pairs the observability check accepts, and of those how many have the scale within 5%.
// Written for non-overlapping rigs, whose scale comes only from the lever arms between the cameras.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/odometry/initializer.hpp"
#include "mcslam/pipeline/dataset_frame.hpp"
#include "mcslam/pipeline/front_end.hpp"
#include "mcslam/pipeline/pipeline_config.hpp"

using namespace mcslam;

namespace {

class FeatureSource {
 public:
  FeatureSource(const Dataset& ds, const PipelineConfig& config) : ds_(ds), front_end_(ds.rig(), config) {}
  int capacity() const { return front_end_.capacityPerCamera(); }
  void compute(std::size_t i, FrameFeatures& out) {
    frame_.load(ds_, i);
    front_end_.compute(frame_.view(), out);
  }

 private:
  const Dataset& ds_;
  FrontEnd front_end_;
  DatasetFrame frame_;
};

const SE3* poseAt(const Trajectory& gt, Timestamp t) {
  const auto it = std::lower_bound(gt.begin(), gt.end(), t, [](const StampedPose& p, Timestamp s) { return p.t < s; });
  return it != gt.end() && std::llabs(it->t - t) < 1000000 ? &it->T_w_b : nullptr;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mcslam-init-probe: two-frame generalized relative pose against ground truth along a dataset"};
  std::string dataset_dir, cameras;
  std::size_t first = 0, step = 40;
  std::vector<int> gaps{5, 10, 15, 20};
  app.add_option("--dataset", dataset_dir, "Dataset folder with ground truth")->required();
  app.add_option("--cameras", cameras, "Cameras of the rig, e.g. 2,5,6 (default: all)");
  app.add_option("--first", first, "First reference frame")->capture_default_str();
  app.add_option("--step", step, "Frames between reference frames")->capture_default_str();
  app.add_option("--gaps", gaps, "Frame gaps to the second frame")->delimiter(',')->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    DatasetOptions options;
    if (!cameras.empty()) options.cameras = parseCameraList(cameras);
    const Dataset ds = Dataset::open(dataset_dir, options);
    ds.requireGroundTruth();  // the pairs are compared with it
    const PipelineConfig config = parsePipelineConfig(YAML::Node(), "defaults", ds.rig());
    FeatureSource source(ds, config);
    FrameFeatures ref(ds.rig().size(), source.capacity()), cur(ds.rig().size(), source.capacity());
    const int max_gap = *std::max_element(gaps.begin(), gaps.end());
    int pairs = 0, accepted = 0, accepted_good = 0, good = 0;
    std::printf("#  ref  gap  rot_deg  |t|_true  |t|_est  scale  scale_sigma  status  inliers/matches\n");
    for (std::size_t r = first; r + max_gap < ds.size(); r += step) {
      source.compute(r, ref);
      for (const int gap : gaps) {
        source.compute(r + gap, cur);
        Initializer init(ds.rig(), config.odometry, source.capacity());
        SE3 T;
        init.feed(ref, r, T);  // the reference
        init.matchToReference(cur);
        // The estimate feed() would make from these matches, with the check that decides shown instead of applied.
        RelativePoseOptions ro = init.relativePoseOptions(r + gap);
        const double bar = ro.max_relative_scale_sigma;
        ro.max_relative_scale_sigma = INFINITY;
        const RelativePoseResult res = estimateGeneralizedRelativePose(ds.rig(), init.lastCorrespondences(), ro);
        const SE3* a = poseAt(*ds.groundTruth(), ds.frames()[r].t);
        const SE3* b = poseAt(*ds.groundTruth(), ds.frames()[r + gap].t);
        if (!a || !b) continue;
        const SE3 truth = a->inverse() * *b;
        const double scale = res.T_1_2.t.norm() / std::max(1e-9, truth.t.norm());
        const bool observable = res.relative_scale_sigma <= bar;
        const bool ok = res.ok() && observable;
        const bool within = std::abs(scale - 1.0) <= 0.05;
        ++pairs;
        accepted += ok ? 1 : 0;
        accepted_good += ok && within ? 1 : 0;
        good += within ? 1 : 0;
        std::printf("%5zu %4d %8.1f %9.3f %8.3f %6.3f %12.3f  %s  %d/%zu\n", r, gap,
                    Eigen::AngleAxisd(truth.R).angle() * 180.0 / M_PI, truth.t.norm(), res.T_1_2.t.norm(), scale,
                    res.relative_scale_sigma,
                    ok            ? "accepted"
                    : !observable ? "scale_unobservable"
                                  : relativePoseStatusName(res.status),
                    res.num_inliers, init.lastCorrespondences().size());
      }
    }
    std::printf("pairs %d: accepted %d (scale within 5%%: %d); scale within 5%% over all pairs: %d\n", pairs, accepted,
                accepted_good, good);
  } catch (const InputError& e) {
    std::fprintf(stderr, "mcslam-init-probe: %s\n", e.what());
    return 2;
  }
  return 0;
}
