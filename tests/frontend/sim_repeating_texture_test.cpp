// Multi-view points on renders of worlds textured with strongly repeating patterns (repeating_textures.hpp),
// against the renderer's depth: a keypoint there has lookalikes along its epipolar curve, and a partner taken
// from the wrong repetition gives a wrong depth. The judged points are the ones the odometry takes as map
// points with a well-known depth (has_point, depth sigma at most 6%, as in sim_multiview_depth_test.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "mcslam/pipeline/pipeline_config.hpp"
#include "repeating_textures.hpp"
#include "sim_frames.hpp"

using namespace mcslam;

namespace {

constexpr double kWellKnownDepthSigma = 0.06;

struct Counts {
  int points = 0, within = 0, off = 0;  // within 2% of the true depth, more than 5% off
  int two_view = 0, two_view_off = 0;
  void add(const Counts& c) {
    points += c.points;
    within += c.within;
    off += c.off;
    two_view += c.two_view;
    two_view_off += c.two_view_off;
  }
  double withinShare() const { return points > 0 ? static_cast<double>(within) / points : 0.0; }
  double offShare() const { return points > 0 ? static_cast<double>(off) / points : 0.0; }
};

struct WorldFigures {
  Counts total;
  double worst_frame_within = 1.0, worst_frame_off = 0.0;
};

Counts countFrame(sim::Simulation& sim, const PipelineConfig& config, int frame) {
  Counts c;
  test::forEachFrontCameraDepth(sim, config, frame, kWellKnownDepthSigma,
                                [&](const MultiViewFeature& mv, double error, bool /*edge*/) {
                                  ++c.points;
                                  c.within += error < 0.02 ? 1 : 0;
                                  c.off += error > 0.05 ? 1 : 0;
                                  c.two_view += mv.size == 2 ? 1 : 0;
                                  c.two_view_off += mv.size == 2 && error > 0.05 ? 1 : 0;
                                });
  return c;
}

// Four places of the route (a quarter apart) of one world and seed, every texture a repeating one.
WorldFigures measure(const std::string& world, unsigned seed) {
  sim::SimulationConfig cfg;
  cfg.world = world;
  cfg.seed = seed;
  cfg.textures_dir = test::writeRepeatingTextures(testing::TempDir() + "mcslam_repeating_textures");
  sim::Simulation sim(cfg);
  const Rig rig = sim.rig().subset({0, 1, 2, 3, 4});
  PipelineConfig config = parsePipelineConfig(YAML::Node(), "defaults", rig);
  config.multiview.unique_two_view = true;  // off by default (BENCHMARKS.md section 3, "Repeating texture")
  WorldFigures w;
  const int n = sim.frameCount();
  for (const int frame : {n / 8, 3 * n / 8, 5 * n / 8, 7 * n / 8}) {
    const Counts c = countFrame(sim, config, frame);
    w.total.add(c);
    w.worst_frame_within = std::min(w.worst_frame_within, c.withinShare());
    w.worst_frame_off = std::max(w.worst_frame_off, c.offShare());
  }
  std::printf(
      "%s seed %u: %d points, within 2%% %.3f, more than 5%% off %.4f (%d; two-view %d of %d); worst frame "
      "%.3f within, %.4f off\n",
      world.c_str(), seed, w.total.points, w.total.withinShare(), w.total.offShare(), w.total.off, w.total.two_view_off,
      w.total.two_view, w.worst_frame_within, w.worst_frame_off);
  return w;
}

}  // namespace

// The regression guard on one world (indoor, seed 1); the study over several worlds and seeds is the disabled
// test below. Measured 2248 points, 0.978 within 2%, 0.0156 more than 5% off (35, 22 of them two-view) on x86-64,
// 2276 points, 0.967 within, 0.0207 off (47) on arm64, whose render and floating point differ in the last bits;
// before two-view tracks were checked for a repetition along the curve (multiview: unique_two_view): 2463 points,
// 0.909 within 2%, 0.0857 off (211, 198 two-view). The bound sits between the two, not at one machine's figure.
// Study figures: BENCHMARKS.md section 3, "Repeating texture".
TEST(SimRepeatingTexture, FewMultiViewPointsTakeTheWrongRepetition) {
  const WorldFigures w = measure("indoor", 1);
  ASSERT_GT(w.total.points, 1000);
  EXPECT_GE(w.total.within, 0.95 * w.total.points);
  EXPECT_LE(w.total.off, 0.035 * w.total.points);
}

// Run with --gtest_also_run_disabled_tests --gtest_filter='*RepeatingTextureStudy*': the three worlds, two seeds
// each (the seed also decides which texture lands on which face).
TEST(SimRepeatingTexture, DISABLED_RepeatingTextureStudy) {
  Counts all;
  for (const char* world : {"indoor", "corridor", "courtyard"}) {
    for (const unsigned seed : {1u, 2u}) all.add(measure(world, seed).total);
  }
  std::printf("all: %d points, within 2%% %.3f, more than 5%% off %.4f\n", all.points, all.withinShare(),
              all.offShare());
}
