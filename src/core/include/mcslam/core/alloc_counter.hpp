#pragma once
// Heap allocation counting, to prove the fixed-memory rule. The counters exist only in programs
// that link the mcslam_alloc_hooks object library (tests, benchmarks, the daemon); elsewhere
// available() is false and the counts stay zero.
#include <cstdint>

namespace mcslam::alloc {

bool available();
// Allocations made by the calling thread since it started.
uint64_t threadCount();
// Allocations made by all threads since the process started.
uint64_t totalCount();
// For C libraries whose allocator we route through our own functions (CHOLMOD): count one.
void noteAllocation();

// Counts the calling thread's allocations over a scope.
class ThreadScope {
 public:
  ThreadScope() : start_(threadCount()) {}
  uint64_t count() const { return threadCount() - start_; }

 private:
  uint64_t start_;
};

}  // namespace mcslam::alloc
