#pragma once
// The features of one rig frame (paper section IV-A): per camera the ORB keypoints with their
// bearings, and the multi-view features — one 3D point seen by several cameras of the same frame,
// as a bundle of keypoints (at most one per camera) with a triangulated point in the body frame and a
// representative descriptor. Keypoints in no multi-view feature are mono features.
// All storage is sized at construction; filling a frame does not allocate.
#include <cstdint>
#include <vector>

#include "mcslam/core/se3.hpp"
#include "mcslam/core/time.hpp"
#include "mcslam/features/keypoint.hpp"

namespace mcslam {

struct KeypointRef {
  int16_t cam = -1;
  int32_t index = -1;  // keypoint index within that camera's FeatureSet
};

struct MultiViewFeature {
  int32_t first = 0;               // first of its observations in FrameFeatures::mv_refs
  int16_t size = 0;                // number of observations (cameras)
  bool has_point = false;          // triangulated: in front of every camera, consistent with every keypoint
  bool metric = false;             // and its depth is certain (relative sigma below the configured bound)
  Vec3 p_b = Vec3::Zero();         // point in the body frame, when has_point
  float relative_depth_sigma = 0;  // standard deviation of the depth over the depth
  Descriptor descriptor{};         // representative (medoid) descriptor
};

class FrameFeatures {
 public:
  FrameFeatures() = default;
  FrameFeatures(int cameras, int max_features_per_camera) { allocate(cameras, max_features_per_camera); }
  void allocate(int cameras, int max_features_per_camera);

  int cameras() const { return static_cast<int>(sets.size()); }
  int capacityPerCamera() const { return capacity_; }
  void clear();

  // Total keypoints over all cameras.
  int keypointCount() const;
  // Keypoints in no multi-view feature.
  int monoCount() const;

  Timestamp t = 0;
  std::vector<uint8_t> present;             // per camera: the image was there
  std::vector<FeatureSet> sets;             // per camera keypoints and descriptors
  std::vector<std::vector<Vec3>> bearings;  // per camera per keypoint: unit bearing (camera frame)
  std::vector<std::vector<uint8_t>> valid;  // per camera per keypoint: the bearing could be computed
  std::vector<std::vector<int32_t>> mv_of;  // per camera per keypoint: multi-view feature index or -1

  std::vector<MultiViewFeature> mv;  // capacity: cameras * max_features / 2
  int mv_count = 0;
  std::vector<KeypointRef> mv_refs;  // observations of the multi-view features
  int mv_ref_count = 0;

 private:
  int capacity_ = 0;
};

}  // namespace mcslam
