#pragma once
// New landmarks across time (paper IV-C, last paragraph): a new keyframe's keypoints without a landmark are matched
// along epipolar curves into the previous keyframes' free keypoints (any camera to any camera), and every match
// that survives the ratio test and the one-partner-per-keypoint rule is triangulated from all its rays (both
// keypoints and their multi-view partners). Holds only scratch, sized at construction; the map and the rig are
// handed in for each call.
#include <cstdint>
#include <span>
#include <vector>

#include "mcslam/features/octave_scales.hpp"
#include "mcslam/geometry/triangulation.hpp"
#include "mcslam/odometry/epipolar_band_index.hpp"
#include "mcslam/odometry/map.hpp"
#include "mcslam/odometry/odometry_options.hpp"

namespace mcslam {

class TemporalTriangulator {
 public:
  TemporalTriangulator(const Rig& rig, const OdometryOptions& options, int max_features_per_camera);

  // Whether the map's unit rests on these points (one camera, a rig without overlap, a roughly metric map): then they
  // are accepted on an unbiased rule (see the .cpp).
  void setSceneReferencedPoints(bool on) { scene_referenced_points_ = on; }

  // New landmarks from keyframe `slot`'s unmatched keypoints and those of the previous keyframes, with the
  // extrinsics of `rig`. Returns how many; created() lists their slots. mapFull(): the map ran out of landmarks.
  int triangulate(Map& map, const Rig& rig, int slot);
  std::span<const int32_t> created() const { return {created_.data(), static_cast<std::size_t>(created_count_)}; }
  bool mapFull() const { return map_full_; }

 private:
  struct Candidate {
    int16_t cam_new, cam_old;
    int32_t kp_new, kp_old;
    int16_t distance;  // -1: beaten by a closer one for the same old keypoint
  };
  struct Best {  // per keypoint of the new keyframe's camera: its best old partner
    int distance = 257, second = 257;
    int cam = -1;
    int32_t kp = -1;
    bool free = false;  // without a landmark yet (the others only compete)
  };
  // The keyframes before `slot`, newest first (at most options.temporal_keyframes). Returns how many.
  int previousKeyframes(const Map& map, int slot, int* previous) const;
  // Candidates between the new keyframe kn and the old one ko into candidates_; returns how many.
  int matchKeyframes(const Rig& rig, const Keyframe& kn, const Keyframe& ko);
  // Best old partners in camera c1 of ko for the free keypoints of camera c2 of kn (into best_).
  void matchCameras(const Rig& rig, const Keyframe& kn, int c2, const SE3& T_w_c2, const Keyframe& ko, int c1);
  // Keeps the partner b (bearing d1, world frame) of new keypoint a (bearing d2) when it is the best so far.
  void consider(const Keyframe& kn, int c2, int a, const Vec3& d2, const Keyframe& ko, int c1, int32_t b,
                const Vec3& d1, const Vec3& baseline);
  // Triangulates the surviving candidates of the pair (slot, po); false when the map is full.
  bool triangulateCandidates(Map& map, const Rig& rig, int slot, int po, int nc, const TriangulationOptions& tri);
  // Appends the rays of keypoint (cam, kp) of keyframe `kf_slot`, or of its multi-view feature, to tri_obs_.
  void addRays(const Map& map, const Rig& rig, int kf_slot, int cam, int kp, int& n);
  // Median inverse distance (1/m) from keyframe `slot` to the landmarks it observes; 0 with too few of them.
  double sceneInverseDepth(const Map& map, const Rig& rig, int slot);

  OdometryOptions options_;
  int capacity_;
  double min_depth_;
  bool scene_referenced_points_ = false;
  bool landmarks_compete_ = false;  // of the call in progress
  std::vector<double> half_fov_;    // per camera: CameraModel::imageHalfAngle()
  std::vector<Candidate> candidates_;
  std::vector<int32_t> claim_;  // per (camera, keypoint) of the old keyframe: best candidate index
  std::vector<Best> best_;
  EpipolarBandIndex band_index_;        // the old camera's keypoints, by epipolar half-plane
  std::vector<double> gate_;            // per octave: sine distance to the epipolar plane allowed
  std::vector<double> inverse_ranges_;  // scratch of sceneInverseDepth(): one per keypoint of a keyframe
  std::vector<TriangulationObservation> tri_obs_;
  std::vector<KeypointRef> tri_refs_;  // keyframe-tagged refs in tri_obs_ order (cam, index)
  std::vector<int32_t> tri_kf_;        // keyframe slot of each tri_obs_ entry
  std::vector<int32_t> created_;
  int created_count_ = 0;
  bool map_full_ = false;
  OctaveScales octave_scale_{options_.scale_factor};
};

}  // namespace mcslam
