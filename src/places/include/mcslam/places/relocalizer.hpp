#pragma once
// Finding a rig frame in the place map: the frame's words query the database; each candidate keyframe (with its
// neighbours in its segment, whose points overlap it) is verified by matching the frame's keypoints, of every
// camera, to its points within the same vocabulary node (Hamming distance, ratio test across distinct landmarks),
// generalized P3P in RANSAC over the rig's rays, then a guided search (every point of the group projected into
// every camera at that pose, matched within a radius: a wide pass for distinctive matches, then a narrow one at the
// pose they give) and refinement on all of it. The first candidate that passes
// the acceptance rule after the guided search gives the frame's world pose: repeated texture can make a wrong
// RANSAC consensus, which the guided search does not confirm (docs/design/places.md).
// Fixed memory: every buffer is sized at construction.
#include <span>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/features/frame_features.hpp"
#include "mcslam/features/octave_scales.hpp"
#include "mcslam/geometry/absolute_pose_ransac.hpp"
#include "mcslam/geometry/pose_refinement.hpp"
#include "mcslam/odometry/keypoint_grid.hpp"
#include "mcslam/places/place_map.hpp"
#include "mcslam/places/places_options.hpp"
#include "mcslam/recognition/bow_vector.hpp"
#include "mcslam/recognition/place_database.hpp"

namespace mcslam {

// A keypoint of the frame matched to a point of the place map.
struct PlaceMatch {
  int16_t cam = -1;
  int32_t kp = -1;
  Vec3 p_w = Vec3::Zero();
  const PlacePoint* point = nullptr;
  int32_t keyframe = -1;  // the place keyframe (slot) whose point it is
};

struct RelocalizationResult {
  bool ok = false;
  SE3 T_w_b;
  int keyframe = -1;  // the candidate that verified (slot)
  int inliers = 0;
  int candidates = 0;               // verified (tried)
  float score = 0;                  // the database score of the winning candidate
  Mat6 information = Mat6::Zero();  // of T_w_b given the candidate's points ([rho; phi], right perturbation)
};

// Standard deviations of a verified pose ([rho; phi]) from the refinement's information, which takes the map's
// points as exact: not below the floors of `options` (the points' own errors). Points far away leave the
// translation along the view loosely known, and the result says so.
Vec6 verifiedPoseSigma(const RelocalizationResult& result, const PlacesOptions& options);

// A correction that lies within its measurement's uncertainty (chi-square, 6 dof, 95%): applying it would only add
// the measurement's noise to every published pose.
bool withinUncertainty(const SE3& correction, const Vec6& sigma);

// Two corrections of the world found by consecutive recognitions, `distance` metres apart, agree: repeated
// texture may fool one recognition, rarely two in a row the same way.
bool sameCorrection(const SE3& a, const SE3& b, double distance);

class Relocalizer {
 public:
  Relocalizer(const Rig& rig, const PlacesOptions& options, float scale_factor, int max_features_per_camera);

  // The extrinsics to project with (the odometry's current rig state).
  void setRig(const Rig& rig);
  const Rig& rig() const { return rig_; }

  // `words` must be of `frame`. `prior` (a slot, or -1) is tried first: the keyframe where tracking was lost, near
  // which a rig that was only blinded still is. `exclude(slot)` true: the keyframe is no candidate.
  template <class Exclude>
  RelocalizationResult locate(const FrameFeatures& frame, const FrameWords& words, const PlaceMap& map,
                              const PlaceDatabase& database, int prior, const Exclude& exclude) {
    RelocalizationResult result;
    prepareFrame(frame);
    if (prior >= 0 && !exclude(prior)) {
      ++result.candidates;
      if (verify(frame, words, map, prior, result)) return result;
    }
    const int n =
        database.query(words.bow(), 0.0f, candidates_, [&](int slot) { return slot != prior && !exclude(slot); });
    if (n == 0) return result;
    const float bar = options_.candidate_share * candidates_[0].score;
    for (int i = 0; i < n && candidates_[static_cast<std::size_t>(i)].score >= bar; ++i) {
      ++result.candidates;
      if (verify(frame, words, map, candidates_[static_cast<std::size_t>(i)].place, result)) {
        result.score = candidates_[static_cast<std::size_t>(i)].score;
        return result;
      }
    }
    return result;
  }

  // The guided stage of verification alone: the pose of `frame` from the points of `keyframe` and its neighbours,
  // starting at `hypothesis` (a RANSAC consensus).
  PoseRefinementResult poseByProjection(const FrameFeatures& frame, const PlaceMap& map, int keyframe,
                                        const SE3& hypothesis);

  // The inlier matches of the last successful locate().
  std::span<const PlaceMatch> inliers() const { return {inliers_.data(), static_cast<std::size_t>(inlier_count_)}; }
  // The keyframes (slots) whose points the last verification matched: the candidate and its neighbours; those of
  // the accepted candidate right after a successful locate(), which returns at its first success.
  std::span<const int32_t> group() const { return {group_.data(), static_cast<std::size_t>(group_count_)}; }

 private:
  bool verify(const FrameFeatures& frame, const FrameWords& words, const PlaceMap& map, int keyframe,
              RelocalizationResult& result);
  void prepareFrame(const FrameFeatures& frame);  // the keypoint grids of the guided search
  // Two guided passes from `hypothesis` over the group's points: wide and distinctive, then narrow at the pose
  // refined on the first; `projected` = the narrow pass's matches, in matches_ and observations_.
  PoseRefinementResult refineByProjection(const FrameFeatures& frame, const PlaceMap& map, const SE3& hypothesis,
                                          int& projected);
  // Every point of the group projected at T_w_b into every camera and matched within radius_px (at octave 0) to a
  // similar keypoint: with ratio > 0 only to its most similar one, when that passes the ratio test against the next;
  // with ratio 0 to each, every keypoint keeping its most similar point. Fills matches_ and observations_ anew;
  // returns how many.
  int searchByProjection(const FrameFeatures& frame, const PlaceMap& map, const SE3& T_w_b, double radius_px,
                         float ratio);
  // Matches the frame's keypoints to the points of the keyframes in group_; fills matches_ and observations_.
  int match(const FrameFeatures& frame, const FrameWords& words, const PlaceMap& map);
  int gatherGroup(const PlaceMap& map, int keyframe);
  void addMatch(const FrameFeatures& frame, const PlaceMap& map, int c, int k, const PlacePoint* point, int keyframe,
                int& count);

  Rig rig_;
  PlacesOptions options_;
  OctaveScales octave_sigma_;  // keypoint sigma by octave, pixels
  std::vector<PlaceScore> candidates_;
  std::vector<int32_t> group_;
  int group_count_ = 0;
  std::vector<PlaceMatch> matches_;
  std::vector<PoseObservation> observations_;
  std::vector<PlaceMatch> inliers_;
  int inlier_count_ = 0;
  AbsolutePoseRansac ransac_;
  PoseRefiner refiner_;
  std::vector<KeypointGrid> grids_;
  std::vector<std::vector<int32_t>> best_distance_;  // per camera per keypoint, of the guided search
  std::vector<std::vector<const PlacePoint*>> best_point_;
  std::vector<std::vector<int32_t>> best_keyframe_;
};

}  // namespace mcslam
