#pragma once
// Keyframe insertion (paper IV-C, last paragraph) and the back-end (V): a new keyframe takes the
// landmarks tracked in it, new landmarks come from its metric multi-view features and from its
// unmatched keypoints matched along epipolar curves into the previous keyframes (any camera to any
// camera), weak landmarks are culled, and the sliding window is optimized.
#include <memory>
#include <vector>

#include "mcslam/features/octave_scales.hpp"
#include "mcslam/backend/sliding_window_solver.hpp"
#include "mcslam/odometry/epipolar_band_index.hpp"
#include "mcslam/odometry/landmark_tracks.hpp"
#include "mcslam/odometry/map.hpp"
#include "mcslam/odometry/odometry_options.hpp"
#include "mcslam/odometry/projection_search.hpp"
#include "mcslam/odometry/rig_state.hpp"

namespace mcslam {

class BackendWorker;

class LocalMapper {
 public:
  LocalMapper(const Rig& rig, const OdometryOptions& options, Map& map, int max_features_per_camera);
  ~LocalMapper();

  // Inserts the frame as a keyframe at T_w_b, linking the keypoints matched in `matches`. With
  // `create_multiview_points`, metric multi-view features without a landmark become landmarks.
  // Returns the keyframe slot (-1 when the map cannot take it).
  int insertKeyframe(const FrameFeatures& frame, const FrameMatches* matches, const SE3& T_w_b, uint64_t frame_index,
                     bool create_multiview_points = true);

  // New landmarks from keyframe `slot`'s unmatched keypoints and those of the previous keyframes.
  int triangulateWithPrevious(int slot);
  // Whether the map's unit rests on the points triangulated across keyframes (one camera, a rig without overlap):
  // then they are accepted on an unbiased rule (triangulateWithPrevious()).
  void setSceneReferencedPoints(bool on) { scene_referenced_points_ = on; }

  // Runs the sliding-window optimization including keyframe `slot` and writes the results back into
  // the map. Returns false when the back-end is off or failed.
  bool optimize(int slot);
  // optimize() in two halves. beginOptimize() adds keyframe `slot` to the window and starts the solve (on the
  // back-end thread when options.backend_thread); until finishOptimize() the map may be read and tracked
  // against, but the back-end's landmarks may not be erased. finishOptimize() waits for the solve and applies
  // it (outliers leave the map; poses and points are written back); it returns false when none was pending
  // or it failed.
  bool beginOptimize(int slot);
  bool finishOptimize();
  bool optimizing() const { return solving_; }

  // Erases landmarks that are rarely found where predicted (the tracker's counts, a view for the call), or that
  // never got a second keyframe.
  int cull(int newest_slot, const LandmarkTracks& tracks);

  void reset();
  // Multiplies every keyframe position and landmark, in the map and in the back-end's window, about `center`
  // (a new metric scale). No solve may be in flight.
  void rescale(double s, const Vec3& center);
  // Whether the back-end's window holds its scale (OdometryOptions::hold_window_scale, else its two oldest
  // keyframes fixed) instead of letting its reprojections pull it: for a map whose unit only explicit rescales
  // may change (a rig without overlap). No solve may be in flight; reset() lets it go.
  void holdScale(bool hold);
  Rig refinedRig() const;
  // The rig state tracking and the front-end follow (this is its producer).
  const RigState& rigState() const { return rig_state_; }
  // The last applied solve's extrinsics become the rig state's (with extrinsic refinement on).
  void adoptSolvedExtrinsics();
  // Camera `cam`'s extrinsic re-estimated (ExtrinsicCheck): the rig state's and the back-end's estimate, whose
  // calibration prior is then dropped (SlidingWindowSolver::setExtrinsic). No solve may be in flight.
  void reestimateExtrinsic(int cam, const SE3& T_b_c);
  void setScaleStatus(ScaleStatus s) { rig_state_.setScale(s); }
  // Heap allocations made by the back-end thread, all solves (0 without it): for the fixed-memory tests.
  uint64_t backendThreadAllocations() const;
  uint64_t backendSolves() const { return backend_solves_; }

 private:
  int allocateKeyframe();
  void linkMultiViewPartners(int slot, const FrameFeatures& frame);
  void touch(int lm);
  void finishTouched();
  void backendRemoveLandmark(int lm);
  int keyframeSlotOfId(int64_t id) const;
  // Median inverse distance (1/m) from keyframe `slot` to the landmarks it observes; 0 with too few of them.
  double sceneInverseDepth(int slot);

  RigState rig_state_;   // with refinement on, its extrinsics follow the estimates
  Rig calibration_;      // the back-end's prior, also for a new window after a reset
  std::vector<uint8_t> calibration_dropped_;  // per camera: setExtrinsic() showed its calibration wrong
  OdometryOptions options_;
  Map& map_;
  std::unique_ptr<backend::SlidingWindowSolver> solver_;
  std::unique_ptr<BackendWorker> worker_;  // null: the solve runs inside beginOptimize()
  bool solving_ = false;
  backend::SolveSummary inline_summary_;
  std::vector<int32_t> touched_;
  std::vector<uint8_t> touched_flag_;
  int touched_count_ = 0;
  std::vector<double> half_fov_;  // per camera: CameraModel::imageHalfAngle()
  // Scratch for epipolar matching into a previous keyframe.
  struct Candidate {
    int16_t cam_new, cam_old;
    int32_t kp_new, kp_old;
    int16_t distance;
  };
  std::vector<Candidate> candidates_;
  std::vector<int32_t> claim_;       // per (camera, keypoint) of the old keyframe: best candidate index
  struct Best {                      // per keypoint of the new keyframe's camera: its best old partner
    int distance = 257, second = 257;
    int cam = -1;
    int32_t kp = -1;
    bool free = false;               // without a landmark yet (the others only compete)
  };
  std::vector<Best> best_;
  EpipolarBandIndex band_index_;     // the old camera's keypoints, by epipolar half-plane
  std::vector<double> gate_;         // per octave: sine distance to the epipolar plane allowed
  bool scene_referenced_points_ = false;
  std::vector<double> inverse_ranges_;  // scratch of sceneInverseDepth(): one per keypoint of a keyframe
  std::vector<TriangulationObservation> tri_obs_;
  std::vector<KeypointRef> tri_refs_;  // keyframe-tagged refs in tri_obs_ order (cam, index)
  std::vector<int32_t> tri_kf_;        // keyframe slot of each tri_obs_ entry
  std::vector<backend::ObservationKey> outliers_;
  int capacity_;
  OctaveScales octave_scale_{options_.scale_factor};
  bool monocular_ = false;
  uint64_t backend_solves_ = 0;
};

}  // namespace mcslam
