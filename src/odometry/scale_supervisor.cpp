#include "mcslam/odometry/scale_supervisor.hpp"

#include <algorithm>
#include <cmath>

#include <spdlog/spdlog.h>

#include "mcslam/odometry/odometry.hpp"
#include "mcslam/odometry/scale_estimator.hpp"

namespace mcslam {

namespace {

// The lever arms tell the scale only while the window turns: a window that turned less than this is not searched
// (its estimate would come back with a useless sigma after costing most of a frame's CPU, at every keyframe of a
// rig whose scale never converges).
constexpr double kMinWindowTurnRad = 2.0 * M_PI / 180.0;
// The profile search over the whole of OdometryOptions::scale_search_ratio runs while the unit is arbitrary. Once
// the combined windows know it to kKnownSigma, or it has converged, the refinement starts from the map's unit and
// the profile (which re-fits the window at every factor it tries, most of an estimate's cost) runs only where that
// refinement finds no minimum near the unit (ScaleEstimator::solve; BENCHMARKS.md section 7).
constexpr double kKnownSigma = 0.2;

}  // namespace

struct ScaleSupervisor::EstimateJob final : BackgroundJob {
  void run() override {
    if (prepared) estimator->solve(ratio, unit_known, result);
  }
  ScaleEstimator* estimator = nullptr;
  bool prepared = false;
  double ratio = 1;  // the profile's range (OdometryOptions::scale_search_ratio)
  bool unit_known = false;
  ScaleEstimate result;
  double rotation_travelled = 0;  // the rig's, at the copy
  uint64_t frame_index = 0;       // of the keyframe copied
};

ScaleSupervisor::ScaleSupervisor(const Rig& rig, const OdometryOptions& options, int max_features_per_camera)
    : options_(options) {
  const int cams = rig.size();
  if (cams < 2) return;
  const int scale_keyframes = std::min(options.max_keyframes, ScaleEstimator::kMaxKeyframes);
  const int window_obs = scale_keyframes * cams * max_features_per_camera;
  estimator_ = std::make_unique<ScaleEstimator>(rig, std::min(options.max_landmarks, window_obs), window_obs,
                                                options.max_keyframes, options.scale_factor, options.levels);
  filter_ = std::make_unique<ScaleFilter>();
  job_ = std::make_unique<EstimateJob>();
  job_->estimator = estimator_.get();
  job_->ratio = options.scale_search_ratio;
  if (options.backend_thread) task_ = std::make_unique<BackgroundTask>();
}

ScaleSupervisor::~ScaleSupervisor() {
  if (task_) task_->wait();  // the estimator must outlive an estimate in flight
}

void ScaleSupervisor::endEstimate() {
  if (task_) task_->collect();
  in_flight_ = false;
}

void ScaleSupervisor::start(bool unscaled) {
  unscaled_start_ = unscaled;
  ever_unscaled_ = ever_unscaled_ || unscaled;
  // An estimate in flight belonged to the old map: taken at the next settled keyframe and dropped, so that a new
  // map does not wait for it.
  stale_ = in_flight_;
  if (filter_) filter_->reset();
}

double ScaleSupervisor::unitSigma(int64_t newest_id) const {
  if (!estimator_ || !ever_unscaled_) return 0;
  if (!unscaled_start_) return options_.scale_drift_per_keyframe;
  return std::clamp(filter_->sigmaAt(newest_id), options_.scale_drift_per_keyframe, 1.0);
}

double ScaleSupervisor::windowTurn(const Map& map) {
  const int oldest = map.oldestWindowKeyframe();
  double turn = 0;
  for (int i = 0; oldest >= 0 && i < map.keyframeCapacity(); ++i) {
    const Keyframe& k = map.keyframe(i);
    if (!k.alive || !k.in_backend) continue;
    turn = std::max(turn, rotationAngle(map.keyframe(oldest).T_w_b.R, k.T_w_b.R));
  }
  return turn;
}

void ScaleSupervisor::startEstimate(const Map& map, const RigState& rig, double rotation_travelled,
                                    uint64_t frame_index) {
  // At every keyframe, before convergence and after it: the unit drifts between turns.
  if (!unscaled_start_ || !estimator_ || in_flight_) return;
  if (windowTurn(map) < kMinWindowTurnRad) return;
  const bool scale_converged = rig.scaleConverged();
  job_->unit_known = scale_converged || filter_->sigma() <= kKnownSigma;
  job_->rotation_travelled = rotation_travelled;
  job_->frame_index = frame_index;
  estimator_->follow(rig);
  job_->prepared = estimator_->prepare(map, job_->result);
  in_flight_ = true;
  if (task_) {
    task_->start(*job_);
  } else {
    job_->run();
  }
}

Vec3 ScaleSupervisor::centerNow(const Map& map, const ScaleEstimate& e) {
  if (e.oldest_slot < 0 || e.oldest_slot >= map.keyframeCapacity()) return e.center;
  const Keyframe& k = map.keyframe(e.oldest_slot);
  return k.alive && k.id == e.oldest_id ? k.T_w_b.t : e.center;
}

ScaleSupervisor::Rescale ScaleSupervisor::takeEstimate(const Map& map, const RigState& rig, uint64_t frame_index,
                                                       OdometryStats& stats) {
  Rescale r;
  if (!in_flight_) return r;
  // A live rig takes it at the first settled keyframe that finds it done; otherwise this waits for it, and what
  // follows depends on the estimate, never on the thread's timing.
  if (!options_.repeatable && task_ && !task_->ready()) return r;
  endEstimate();
  if (stale_) {
    stale_ = false;
    return r;
  }
  const ScaleEstimate& e = job_->result;
  const uint64_t window_frame = job_->frame_index;
  ++stats.scale_estimates;
  if (!e.ok) return r;
  stats.last_scale = e.scale;
  stats.last_scale_sigma = e.relative_sigma;
  if (!filter_->add(std::log(e.scale), e.relative_sigma, e.oldest_id, e.newest_id, job_->rotation_travelled)) {
    spdlog::debug("odometry: scale at frame {}: window {:.4f} sigma {:.4f} dropped as an outlier", window_frame,
                  e.scale, e.relative_sigma);
    return r;
  }
  const double x = filter_->correction(), sigma = filter_->sigma();
  stats.combined_scale_sigma = sigma;
  // One line per estimate, for studies against ground truth (mcslam-run --log-level debug).
  spdlog::debug(
      "odometry: scale at frame {}: window {:.4f} sigma {:.4f} ({} keyframes, {} landmarks, chi2/dof "
      "{:.2f}), combined {:.4f} sigma {:.4f} over {:.0f} deg",
      window_frame, e.scale, e.relative_sigma, e.keyframes, e.landmarks, e.reduced_chi2, std::exp(x), sigma,
      filter_->rotationSpan() * 180.0 / M_PI);
  // A correction 3 sigma away from 1 is applied at any time: before convergence it brings the arbitrary unit near
  // the metric one (the windows' fits then start in the basin; far off, most windows give no estimate), the poses
  // staying flagged unscaled until the combined sigma reaches the bound.
  const bool scale_converged = rig.scaleConverged();
  const bool converges = !scale_converged && sigma <= options_.scale_max_sigma &&
                         filter_->rotationSpan() >= options_.scale_min_rotation_deg * M_PI / 180.0;
  // Once converged the map follows the combined estimate as the unit drifts, whenever it is 2 sigma off.
  const double significant = scale_converged ? 2.0 : 3.0;
  if (!converges && !(std::abs(x) > significant * sigma)) return r;
  r.apply = true;
  r.s = std::exp(x);
  r.center = centerNow(map, e);
  r.from_frame = scale_converged ? e.oldest_frame : 0;
  r.converged = converges;
  spdlog::debug("odometry: map rescaled by {:.4f} at frame {}", r.s, frame_index);
  filter_->applied();
  ++stats.scale_rescales;
  if (converges) {
    filter_->setDrift(options_.scale_drift_per_keyframe);
    stats.scale_converged_frame = static_cast<int64_t>(frame_index);
  }
  return r;
}

}  // namespace mcslam
