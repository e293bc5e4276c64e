#pragma once
// What tracking learns of each landmark of the map, frame after frame: how often it was predicted inside an image
// and how often it was found there (culling judges a landmark by the ratio), and the frame it was last counted
// in. The tracker owns these counts; the map's Landmark holds the geometry. They are kept per landmark slot
// under the landmark's id: a slot the map gave to a new landmark starts from fresh counts.
#include <cstdint>
#include <vector>

#include "mcslam/odometry/map.hpp"

namespace mcslam {

struct LandmarkTrack {
  int64_t id = -1;                 // the landmark these counts belong to
  uint32_t visible = 0;            // frames it was predicted inside an image
  uint32_t found = 0;              // frames it was matched
  uint64_t matched_frame = ~0ull;  // last frame index it was counted as found in
  uint64_t listed_frame = ~0ull;   // last frame index it was put on the tracked list
};

class LandmarkTracks {
 public:
  explicit LandmarkTracks(int max_landmarks) : tracks_(max_landmarks) {}

  // The counts of the landmark in `slot` (fresh ones the first time the slot holds that landmark).
  LandmarkTrack& of(const Map& map, int slot) {
    LandmarkTrack& t = tracks_[slot];
    const int64_t id = map.landmark(slot).id;
    if (t.id != id) {
      t = LandmarkTrack{};
      t.id = id;
    }
    return t;
  }
  // The same without taking the slot: fresh counts when it holds another landmark.
  const LandmarkTrack& peek(const Map& map, int slot) const {
    const LandmarkTrack& t = tracks_[slot];
    return t.id == map.landmark(slot).id ? t : fresh_;
  }

 private:
  std::vector<LandmarkTrack> tracks_;
  LandmarkTrack fresh_;
};

}  // namespace mcslam
