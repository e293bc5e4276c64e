// Same seed, same bytes (whatever the thread count); another seed, another dataset. Runs the real tool twice
// end to end (world build, rendering, PNG writing), so nothing shared in memory can hide a difference.
#include <gtest/gtest.h>

#include <string>

#include "sim_cli_support.hpp"

namespace mcslam::sim {
namespace {

using testing::readTree;
using testing::runSim;

std::map<std::string, std::string> exportRun(const test::TempDir& tmp, const std::string& name, int seed, int threads) {
  const std::string dir = tmp.file(name);
  std::string log;
  const int code = runSim("--rig stereo --world corridor --frames 3 --quiet --seed " + std::to_string(seed) +
                              " --threads " + std::to_string(threads) + " --out " + dir,
                          &log);
  EXPECT_EQ(code, 0) << log;
  return readTree(dir);
}

TEST(SimDeterminism, SameSeedSameBytesWhateverTheThreadCountOtherSeedDiffers) {
  test::TempDir tmp("mcslam-sim-det");
  const auto one = exportRun(tmp, "seed5_t1", 5, 1);
  const auto two = exportRun(tmp, "seed5_t2", 5, 2);
  const auto other = exportRun(tmp, "seed6_t2", 6, 2);

  // 2 cameras x 3 frames of images and depth, data.csv per camera, camchain, ground truth, sim.yaml.
  ASSERT_EQ(one.size(), 2u * (3 + 3 + 1) + 3);
  ASSERT_EQ(one.size(), two.size());
  int images = 0, differing = 0;
  for (const auto& [path, bytes] : one) {
    ASSERT_TRUE(two.count(path)) << path;
    EXPECT_TRUE(bytes == two.at(path)) << path << " differs between 1 and 2 render threads";
    if (path.find("/data/") != std::string::npos) {
      ++images;
      ASSERT_TRUE(other.count(path)) << path;  // same stamps: they depend on the rate only
      if (bytes != other.at(path)) ++differing;
    }
  }
  EXPECT_EQ(images, 6);
  EXPECT_EQ(differing, images) << "seed 6 must give other images than seed 5";
  EXPECT_NE(one.at("groundtruth.txt"), other.at("groundtruth.txt")) << "the seed also varies the motion's wobble";
}

}  // namespace
}  // namespace mcslam::sim
