#pragma once
// Time stamps are integer nanoseconds everywhere inside mcslam; seconds (double) only at file edges.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

namespace mcslam {

using Timestamp = int64_t;  // nanoseconds

inline double toSeconds(Timestamp ns) { return static_cast<double>(ns) * 1e-9; }
inline Timestamp fromSeconds(double s) { return static_cast<Timestamp>(s * 1e9 + (s >= 0 ? 0.5 : -0.5)); }

// Exact decimal seconds, as files write time stamps ("12.300000001", "-0.000000005").
inline std::string toSecondsString(Timestamp ns) {
  char buf[48];
  const unsigned long long a =
      ns < 0 ? 0ULL - static_cast<unsigned long long>(ns) : static_cast<unsigned long long>(ns);
  std::snprintf(buf, sizeof(buf), "%s%llu.%09llu", ns < 0 ? "-" : "", a / 1000000000ULL, a % 1000000000ULL);
  return buf;
}

inline Timestamp monotonicNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace mcslam
