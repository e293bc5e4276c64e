// tools/eval/local_scale.py --span: the unit of one stretch of a run (the path the estimate travelled over the
// true one), the figure BENCHMARKS.md gives for how a rig without overlap finishes; --from: the spans after a pose.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "test_support.hpp"

using namespace mcslam;

namespace {

std::string localScale(const std::string& args, int* code) {
  std::string out;
  *code = test::runCommand("python3 " + std::string(MCSLAM_SOURCE_DIR) + "/tools/eval/local_scale.py " + args + " 2>&1",
                           &out);
  return out;
}

// 60 poses 0.1 s apart along x, 0.1 m per pose; the estimate's unit is 1.0 for the first 30, `late` after.
void writeRun(const std::string& truth, const std::string& estimate, double late) {
  std::ofstream t(truth), e(estimate);
  double x = 0;
  for (int i = 0; i < 60; ++i) {
    t << 1.0 + 0.1 * i << " " << 0.1 * i << " 0 0 0 0 0 1\n";
    e << 1.0 + 0.1 * i << " " << x << " 0 0 0 0 0 1\n";
    x += i < 30 ? 0.1 : 0.1 * late;
  }
}

}  // namespace

TEST(LocalScaleTool, SpanGivesTheUnitOfOneStretchAndNamesABadSpan) {
  if (test::runCommand("python3 --version") != 0) GTEST_SKIP() << "python3 is not installed";
  test::TempDir dir("local_scale");
  writeRun(dir.file("gt.txt"), dir.file("run.tum"), 1.1);
  const std::string files = dir.file("gt.txt") + " " + dir.file("run.tum") + " --frames 10";
  int code = -1;
  std::string out = localScale(files + " --span -20 -1", &code);
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("unit over poses 40-59: 1.100"), std::string::npos) << out;
  out = localScale(files + " --span 0 29", &code);
  EXPECT_NE(out.find("unit over poses 0-29: 1.000"), std::string::npos) << out;
  out = localScale(files + " --span 40 10", &code);
  EXPECT_NE(code, 0);
  EXPECT_NE(out.find("--span 40 10: needs two poses in order among the 60 matched"), std::string::npos) << out;
}

TEST(LocalScaleTool, FromCountsOnlyTheSpansAfterAPose) {
  if (test::runCommand("python3 --version") != 0) GTEST_SKIP() << "python3 is not installed";
  test::TempDir dir("local_scale_from");
  writeRun(dir.file("gt.txt"), dir.file("run.tum"), 1.1);
  const std::string files = dir.file("gt.txt") + " " + dir.file("run.tum") + " --frames 10";
  int code = -1;
  std::string out = localScale(files, &code);
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("(50 spans)"), std::string::npos) << out;
  out = localScale(files + " --from 30", &code);  // only the stretch at 1.1
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("(20 spans): min 1.100"), std::string::npos) << out;
  EXPECT_NE(out.find("within 5%: 0.0% of the spans"), std::string::npos) << out;
  out = localScale(files + " --from 55", &code);
  EXPECT_NE(code, 0);
  EXPECT_NE(out.find("--from 55: needs a pose more than 10 before the last of the 60 matched"), std::string::npos)
      << out;
}
