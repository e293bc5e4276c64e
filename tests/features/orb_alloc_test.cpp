// Fixed memory: after the constructor, extracting allocates nothing, whatever the image.
#include <gtest/gtest.h>

#include "alloc_testing.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/features/orb_extractor.hpp"
#include "orb_test_images.hpp"

namespace mcslam {
namespace {

TEST(OrbAllocation, ExtractingAllocatesNothing) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  const Image frame = test::texturedFrame(720, 540, 3);
  const Image small = test::texturedFrame(333, 251, 4);
  for (bool simd : {true, false}) {
    OrbOptions options;
    options.use_simd = simd;
    OrbExtractor extractor(options, 720, 540);
    FeatureSet out(options.max_features);
    alloc::ThreadScope scope;  // the very first extraction too: nothing is left for it to build
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(extractor.extract(frame.view(), out), OrbStatus::kOk);
      EXPECT_EQ(out.count, options.max_features);
      EXPECT_EQ(extractor.extract(small.view(), out), OrbStatus::kOk);
      EXPECT_GT(out.count, 0);
      EXPECT_EQ(extractor.extract(ImageView{}, out), OrbStatus::kOk);
    }
    EXPECT_EQ(scope.count(), 0u) << "simd " << simd;
  }
}

}  // namespace
}  // namespace mcslam
