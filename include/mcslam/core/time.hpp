#pragma once
// Time stamps are integer nanoseconds everywhere inside mcslam; seconds (double) only at file edges.
#include <chrono>
#include <cstdint>

namespace mcslam {

using Timestamp = int64_t;  // nanoseconds

inline double toSeconds(Timestamp ns) { return static_cast<double>(ns) * 1e-9; }
inline Timestamp fromSeconds(double s) { return static_cast<Timestamp>(s * 1e9 + (s >= 0 ? 0.5 : -0.5)); }

inline Timestamp monotonicNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace mcslam
