#pragma once
// Whether a test can count heap allocations. The counting hooks replace malloc, which the sanitizers own: sanitizer
// builds leave the hooks out (GCC says so with __SANITIZE_*__) and the counting assertions skip there. In every other
// build a test without the hooks is a mistake in its CMake (ALLOC_HOOKS missing) and fails.
#include <gtest/gtest.h>

#include <string>

#include "mcslam/core/alloc_counter.hpp"

namespace mcslam::test {

inline bool countsAllocations() {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  return false;
#else
  if (!alloc::available()) ADD_FAILURE() << "allocation hooks not linked: give the test ALLOC_HOOKS in its CMakeLists";
  return alloc::available();
#endif
}

// The stats of a mcslam-run (its --stats JSON): after the warm-up, none of the pipeline's threads allocated.
// mcslam-run counts when it was built with the hooks, as this test was.
inline void expectRunAllocatedNothing(const std::string& stats) {
  if (!countsAllocations()) return;
  const std::size_t at = stats.find("\"allocations_after_warmup\"");
  ASSERT_NE(at, std::string::npos) << stats;
  const std::string part = stats.substr(at, stats.find('}', at) - at);
  EXPECT_NE(part.find("\"counted\": true"), std::string::npos) << part;
  for (const char* zero : {"\"front_end_thread\": 0", "\"tracking_thread\": 0", "\"background_threads\": 0"})
    EXPECT_NE(part.find(zero), std::string::npos) << part;
}

}  // namespace mcslam::test

// For a test that asserts nothing but allocation counts.
#define SKIP_UNLESS_COUNTING_ALLOCATIONS() \
  if (!::mcslam::test::countsAllocations()) GTEST_SKIP() << "sanitizer build: allocation hooks left out"
