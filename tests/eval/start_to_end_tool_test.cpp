// tools/eval/start_to_end.py: the start-to-end error BENCHMARKS.md gives for loop closure, in the trajectory's own
// frame (a whole trajectory turned and moved rigidly has none), and a clear error when no pose matches the ground
// truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include "test_support.hpp"

using namespace mcslam;

namespace {

std::string startToEnd(const std::string& args, int* code) {
  std::string out;
  *code = test::runCommand(
      "python3 " + std::string(MCSLAM_SOURCE_DIR) + "/tools/eval/start_to_end.py " + args + " 2>&1", &out);
  return out;
}

// 2 m along x, then 1 m along y, 0.1 m per pose 0.1 s apart (a 3 m path that does not return); the estimate is
// the same route turned by 90 deg about z and moved, its last pose `end_off` metres further along the world's y.
void writeRun(const std::string& truth, const std::string& estimate, double end_off) {
  std::ofstream t(truth), e(estimate);
  const double q = std::sqrt(0.5);
  for (int i = 0; i <= 30; ++i) {
    const double x = 0.1 * std::min(i, 20), y = 0.1 * std::max(i - 20, 0);
    t << 1.0 + 0.1 * i << " " << x << " " << y << " 0 0 0 0 1\n";
    e << 1.0 + 0.1 * i << " " << 5 - y << " " << 5 + x + (i == 30 ? end_off : 0.0) << " 0 0 0 " << q << " " << q
      << "\n";
  }
}

}  // namespace

TEST(StartToEndTool, MeasuresTheEndInTheTrajectorysOwnFrame) {
  if (test::runCommand("python3 --version") != 0) GTEST_SKIP() << "python3 is not installed";
  test::TempDir dir("start_to_end");
  int code = -1;
  writeRun(dir.file("gt.txt"), dir.file("moved.tum"), 0.0);
  std::string out = startToEnd(dir.file("gt.txt") + " " + dir.file("moved.tum"), &code);
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("start-to-end error 0.000 m (t 1.000 .. 4.000 s, 0.000% of the 3.0 m path)"), std::string::npos)
      << out;
  writeRun(dir.file("gt.txt"), dir.file("drifted.tum"), 0.2);
  out = startToEnd(dir.file("gt.txt") + " " + dir.file("drifted.tum"), &code);
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("start-to-end error 0.200 m (t 1.000 .. 4.000 s, 6.667% of the 3.0 m path)"), std::string::npos)
      << out;
}

TEST(StartToEndTool, SaysWhenNoPoseMatchesTheGroundTruth) {
  if (test::runCommand("python3 --version") != 0) GTEST_SKIP() << "python3 is not installed";
  test::TempDir dir("start_to_end_none");
  { std::ofstream(dir.file("gt.txt")) << "1.0 0 0 0 0 0 0 1\n"; }
  { std::ofstream(dir.file("run.tum")) << "7.0 0 0 0 0 0 0 1\n8.0 1 0 0 0 0 0 1\n"; }
  int code = -1;
  const std::string out = startToEnd(dir.file("gt.txt") + " " + dir.file("run.tum"), &code);
  EXPECT_NE(code, 0);
  EXPECT_NE(out.find("have a ground-truth pose at the same time (need 2)"), std::string::npos) << out;
}
