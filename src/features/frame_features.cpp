#include "mcslam/features/frame_features.hpp"

#include <algorithm>

namespace mcslam {

void FrameFeatures::allocate(int cameras, int max_features_per_camera) {
  capacity_ = max_features_per_camera;
  present.assign(cameras, 0);
  sets.assign(cameras, FeatureSet(max_features_per_camera));
  bearings.assign(cameras, std::vector<Vec3>(max_features_per_camera));
  valid.assign(cameras, std::vector<uint8_t>(max_features_per_camera));
  mv_of.assign(cameras, std::vector<int32_t>(max_features_per_camera, -1));
  mv.resize(std::max(1, cameras * max_features_per_camera / 2));
  mv_refs.resize(std::max(1, cameras * max_features_per_camera));
  clear();
}

void FrameFeatures::clear() {
  for (FeatureSet& s : sets) s.clear();
  std::fill(present.begin(), present.end(), 0);
  mv_count = 0;
  mv_ref_count = 0;
}

int FrameFeatures::keypointCount() const {
  int n = 0;
  for (const FeatureSet& s : sets) n += s.count;
  return n;
}

int FrameFeatures::monoCount() const {
  int n = 0;
  for (int c = 0; c < cameras(); ++c) {
    for (int k = 0; k < sets[c].count; ++k) n += mv_of[c][k] < 0 ? 1 : 0;
  }
  return n;
}

}  // namespace mcslam
