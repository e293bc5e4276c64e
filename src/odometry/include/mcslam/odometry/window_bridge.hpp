#pragma once
// The map-to-window bridge (paper V): it feeds the back-end's sliding window from the map (a new keyframe, its
// observations, landmarks that two window keyframes observe), starts the solve (on the back-end thread when
// OdometryOptions::backend_thread) and writes the solve back (poses, positions; outliers leave the window and the
// map; landmarks of a marginalized keyframe become frozen). The window knows keyframes and landmarks by their ids.
// It produces the rig state (RigState): the extrinsics the window refined, the per-camera re-estimates, the scale
// status. The map is handed in for each call (and kept by a solve in flight that feeds its keyframe on the back-end
// thread: beginSolveAfter); the solver and its worker are the bridge's own.
#include <cstdint>
#include <memory>
#include <vector>

#include "mcslam/backend/sliding_window_solver.hpp"
#include "mcslam/core/background_task.hpp"
#include "mcslam/features/octave_scales.hpp"
#include "mcslam/odometry/map.hpp"
#include "mcslam/odometry/odometry_options.hpp"
#include "mcslam/odometry/rig_state.hpp"

namespace mcslam {

class WindowBridge {
 public:
  WindowBridge(const Rig& calibration, const OdometryOptions& options, int max_features_per_camera);
  ~WindowBridge();
  WindowBridge(const WindowBridge&) = delete;
  WindowBridge& operator=(const WindowBridge&) = delete;

  // The rig state tracking and the front-end follow (by value).
  const RigState& rigState() const { return rig_state_; }
  // The last applied solve's extrinsics become the rig state's (with extrinsic refinement on).
  void adoptSolvedExtrinsics();
  // Camera `cam`'s extrinsic re-estimated (ExtrinsicCheck): the rig state's and the window's estimate, whose
  // calibration prior is then dropped (SlidingWindowSolver::setExtrinsic). No solve may be in flight.
  void reestimateExtrinsic(int cam, const SE3& T_b_c);
  void setScaleStatus(ScaleStatus s) { rig_state_.setScale(s); }

  // Runs the sliding-window optimization including keyframe `slot` and writes the results back into the map.
  // Returns false when the back-end is off or failed.
  bool optimize(Map& map, int slot);
  // optimize() in two halves. beginSolve() adds keyframe `slot` to the window and starts the solve; until
  // finishSolve() the map may be read and tracked against, but the window's landmarks may not be erased.
  // finishSolve() waits for the solve and applies it; it returns false when none was pending or it failed.
  bool beginSolve(Map& map, int slot);
  bool finishSolve(Map& map);
  bool solving() const { return solving_; }
  // beginSolve() after `mapping` (new landmarks for keyframe `slot`), all three in the solve's job (on the back-end
  // thread when there is one): the map and whatever `mapping` writes are then the job's until finishSolve(), which
  // returns false as well when the keyframe could not enter the window.
  bool beginSolveAfter(Map& map, int slot, BackgroundJob& mapping);
  // Blocks until the job on the back-end thread, if any, is done (without applying it).
  void wait() const;

  // Landmark `lm` leaves the window (before the map erases it).
  void removeLandmark(Map& map, int lm);
  // The map's unit changes by `s` about `center` (a new metric scale), in the map and in the window: keyframe
  // positions become center + s (p - center), and each landmark's depth from the newest camera that saw it is
  // multiplied by s (the cameras' lever arms were metric all along). No solve may be in flight.
  void rescale(Map& map, double s, const Vec3& center);
  // Whether the window holds its scale (OdometryOptions::hold_window_scale, else its two oldest keyframes fixed)
  // instead of letting its reprojections pull it: for a map whose unit only explicit rescales may change (a rig
  // without overlap, a roughly metric map). No solve may be in flight; reset() and holdScale(false) let it go.
  void holdScale(bool hold);
  // A fresh window for a new map (allocates: only after tracking was lost, never per frame).
  void reset();

  // The rig with the extrinsics the window refined (the rig state's when there is no back-end).
  Rig refinedRig() const;
  // Heap allocations made by the back-end thread, all solves (0 without it); any thread may ask.
  uint64_t backendThreadAllocations() const { return task_ ? task_->allocations() : 0; }
  uint64_t solves() const { return solves_; }

 private:
  // Keyframe `slot` and what it observes enter the window (the oldest keyframe marginalized when it is full).
  bool feed(Map& map, int slot);
  void addLandmarkObservations(Map& map, const Keyframe& kf);
  void removeOutliers(Map& map);
  void writeBack(Map& map);
  int keyframeSlotOfId(const Map& map, int64_t id) const;
  // R_w_b t_b_c of the camera of `l`'s observation in its newest keyframe (zero without one).
  Vec3 leverArmOfNewestObserver(const Map& map, const Landmark& l) const;

  struct WindowSolve final : BackgroundJob {
    void run() override;
    WindowBridge* bridge = nullptr;
    // With a keyframe to feed (slot >= 0), the mapping that must precede its entry, then the entry, then the solve.
    BackgroundJob* mapping = nullptr;
    Map* map = nullptr;
    int slot = -1;
    bool fed = true;  // false: the keyframe could not enter the window, and nothing was solved
    int iterations = 0;
    backend::SolveSummary summary;
  };
  void startSolve(Map& map, int slot, BackgroundJob* mapping);

  RigState rig_state_;                        // with refinement on, its extrinsics follow the estimates
  Rig calibration_;                           // the window's prior, also for a new window after a reset
  std::vector<uint8_t> calibration_dropped_;  // per camera: reestimateExtrinsic() showed its calibration wrong
  OdometryOptions options_;
  int capacity_;
  bool monocular_;
  std::unique_ptr<backend::SlidingWindowSolver> solver_;
  WindowSolve solve_;
  std::unique_ptr<BackgroundTask> task_;  // the back-end thread; null: the solve runs inside beginSolve()
  bool solving_ = false;
  std::vector<backend::ObservationKey> outliers_;
  OctaveScales octave_scale_{options_.scale_factor};
  uint64_t solves_ = 0;
};

}  // namespace mcslam
