#pragma once
// Fixed-memory latency statistics: a log-spaced histogram (about 2% resolution from 1 us to 100 s)
// that one thread records into and another reads approximate percentiles from.
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>

namespace mcslam::platform {

class LatencyHistogram {
 public:
  static constexpr int kBins = 1024;

  void record(int64_t ns) {
    bins_[binOf(ns)].fetch_add(1, std::memory_order_relaxed);
    count_.fetch_add(1, std::memory_order_relaxed);
  }
  uint64_t count() const { return count_.load(std::memory_order_relaxed); }
  // Upper edge of the bin holding the q-quantile (0..1); 0 when empty.
  int64_t percentileNs(double q) const {
    const uint64_t n = count();
    if (n == 0) return 0;
    const uint64_t rank = static_cast<uint64_t>(std::ceil(q * static_cast<double>(n)));
    uint64_t seen = 0;
    for (int b = 0; b < kBins; ++b) {
      seen += bins_[b].load(std::memory_order_relaxed);
      if (seen >= rank && seen > 0) return upperEdgeNs(b);
    }
    return upperEdgeNs(kBins - 1);
  }
  void reset() {
    for (auto& b : bins_) b.store(0, std::memory_order_relaxed);
    count_.store(0, std::memory_order_relaxed);
  }

 private:
  static constexpr double kMinNs = 1000.0;  // 1 us
  static constexpr double kStep = 1.02;
  static int binOf(int64_t ns) {
    if (static_cast<double>(ns) <= kMinNs) return 0;
    const int b = 1 + static_cast<int>(std::log(static_cast<double>(ns) / kMinNs) / std::log(kStep));
    return b >= kBins ? kBins - 1 : b;
  }
  static int64_t upperEdgeNs(int b) { return static_cast<int64_t>(kMinNs * std::pow(kStep, b)); }

  std::array<std::atomic<uint64_t>, kBins> bins_{};
  std::atomic<uint64_t> count_{0};
};

}  // namespace mcslam::platform
