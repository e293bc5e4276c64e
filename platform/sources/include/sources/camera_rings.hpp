#pragma once
// One drop-oldest ring per camera from acquisition to assembly, plus the doorbell that wakes the
// assembler. Each ring has exactly one producer (the thread acquiring that camera, or the replay).
#include <memory>
#include <vector>

#include "realtime/doorbell.hpp"
#include "realtime/drop_oldest_ring.hpp"
#include "sources/camera_frame.hpp"

namespace mcslam::platform {

class CameraRings {
 public:
  CameraRings(const std::vector<std::pair<int, int>>& sizes, uint32_t slots) : sizes_(sizes) {
    for (const auto& s : sizes)
      rings_.push_back(std::make_unique<DropOldestRing<CameraFrame>>(
          slots, [&s](CameraFrame& f) { f.image.resize(s.first, s.second); }));
  }
  int cameras() const { return static_cast<int>(rings_.size()); }
  std::pair<int, int> size(int cam) const { return sizes_[cam]; }

  // Producer side of camera `cam`.
  CameraFrame& slot(int cam) { return rings_[cam]->writeSlot(); }
  void publish(int cam) {
    rings_[cam]->publish();
    bell_.ring();
  }

  DropOldestRing<CameraFrame>& ring(int cam) { return *rings_[cam]; }
  const DropOldestRing<CameraFrame>& ring(int cam) const { return *rings_[cam]; }
  Doorbell& bell() { return bell_; }
  uint64_t dropped() const {
    uint64_t n = 0;
    for (const auto& r : rings_) n += r->dropped();
    return n;
  }

 private:
  std::vector<std::pair<int, int>> sizes_;
  std::vector<std::unique_ptr<DropOldestRing<CameraFrame>>> rings_;
  Doorbell bell_;
};

}  // namespace mcslam::platform
