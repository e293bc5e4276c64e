#include "mcslam/backend/sliding_window_solver.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>

#include "marginalizer.hpp"
#include "mcslam/backend/levenberg_marquardt.hpp"
#include "mcslam/backend/reprojection_residual.hpp"
#include "mcslam/core/error.hpp"
#include "reduced_system_solver.hpp"
#include "window_linearization.hpp"
#include "window_storage.hpp"

namespace mcslam::backend {

const char* statusName(Status s) {
  switch (s) {
    case Status::Ok: return "ok";
    case Status::UnknownKeyframe: return "unknown keyframe";
    case Status::UnknownLandmark: return "unknown landmark";
    case Status::UnknownObservation: return "unknown observation";
    case Status::DuplicateId: return "duplicate id";
    case Status::CapacityExceeded: return "capacity exceeded";
    case Status::InvalidCamera: return "invalid camera";
    case Status::InvalidValue: return "invalid value";
    case Status::EmptyWindow: return "empty window";
  }
  return "?";
}

namespace {
// Configuration errors surface at construction, never in the hot path.
const Rig& validated(const Rig& rig, const WindowCapacity& cap, const SolverOptions& o) {
  auto fail = [](const std::string& field, double value) {
    throw InputError("SlidingWindowSolver: invalid " + field + " = " + std::to_string(value));
  };
  if (rig.size() < 1) fail("rig camera count", rig.size());
  if (cap.max_keyframes < 1) fail("capacity.max_keyframes", cap.max_keyframes);
  if (cap.max_landmarks < 1) fail("capacity.max_landmarks", cap.max_landmarks);
  if (cap.max_observations < 1) fail("capacity.max_observations", cap.max_observations);
  if (o.reference_camera < 0 || o.reference_camera >= rig.size()) fail("reference_camera", o.reference_camera);
  if (!(o.loss.threshold > 0)) fail("loss.threshold", o.loss.threshold);
  if (!(o.outlier_chi2 > 0)) fail("outlier_chi2", o.outlier_chi2);
  if (!(o.extrinsic_prior.translation > 0)) fail("extrinsic_prior.translation", o.extrinsic_prior.translation);
  if (!(o.extrinsic_prior.rotation > 0)) fail("extrinsic_prior.rotation", o.extrinsic_prior.rotation);
  if (o.gauge_fixed_oldest < 0) fail("gauge_fixed_oldest", o.gauge_fixed_oldest);
  if (!(o.initial_trust_radius > 0)) fail("initial_trust_radius", o.initial_trust_radius);
  return rig;
}
}  // namespace

struct SlidingWindowSolver::Impl {
  Impl(const Rig& rig, const WindowCapacity& capacity, const SolverOptions& opts)
      : initial_options(opts),
        options(opts),
        window(validated(rig, capacity, opts), capacity, opts),
        prior(window),
        linearization(window, opts),
        reduced(capacity.max_keyframes + rig.size()),
        marginalizer(window, opts) {
    outliers.reserve(capacity.max_observations);
    marginalized.reserve(capacity.max_landmarks);
    T_b_w.resize(capacity.max_keyframes);
    T_c_b.resize(rig.size());
  }

  SolveSummary solve(int max_iterations);
  void classifyOutliers();
  const SolverOptions initial_options;
  SolverOptions options;
  WindowStorage window;
  MarginalizationPrior prior;
  WindowLinearization linearization;
  ReducedSystemSolver reduced;
  Marginalizer marginalizer;
  std::vector<ObservationKey> outliers;
  std::vector<int64_t> marginalized;
  std::vector<SE3> T_b_w;  // outlier test scratch
  std::vector<SE3> T_c_b;
};

namespace {
// The window's Levenberg-Marquardt problem: the linearization's reduced system, solved by CHOLMOD.
class WindowProblem final : public LeastSquaresProblem {
 public:
  WindowProblem(WindowStorage& window, MarginalizationPrior& prior, WindowLinearization& lin,
                ReducedSystemSolver& reduced)
      : window_(window), prior_(prior), lin_(lin), reduced_(reduced) {}
  bool linearize() override {
    lin_.linearize(window_, prior_, /*select_landmarks=*/first_);
    first_ = false;
    return true;
  }
  double cost() const override { return lin_.cost(); }
  void buildDampedSystem(double mu) override { lin_.buildReducedSystem(window_, mu, prior_); }
  double maxGradient() const override { return lin_.maxGradient(); }
  bool solveStep() override {
    if (lin_.numBlocks() > 0) reduced_.setStructure(lin_.numBlocks(), lin_.blockPattern());
    const bool solved =
        lin_.numBlocks() == 0 || reduced_.solve(lin_.reducedMatrix(), lin_.reducedRhs(), lin_.cameraStep());
    if (solved) lin_.backSubstitute();
    return solved;
  }
  double stepNorm() const override { return std::sqrt(lin_.stepSquaredNorm()); }
  double stateNorm() const override { return std::sqrt(lin_.stateSquaredNorm(window_)); }
  double modelCostDecrease(double mu) const override { return lin_.modelCostDecrease(mu); }
  bool evaluateTrial(double& cost) override { return lin_.evaluateTrial(window_, prior_, cost); }
  void acceptTrial() override { lin_.commitTrial(window_); }

 private:
  WindowStorage& window_;
  MarginalizationPrior& prior_;
  WindowLinearization& lin_;
  ReducedSystemSolver& reduced_;
  bool first_ = true;
};
}  // namespace

SolveSummary SlidingWindowSolver::Impl::solve(int max_iterations) {
  SolveSummary summary;
  const int analyses_before = reduced.analyses();
  WindowLinearization& lin = linearization;
  if (!lin.prepare(window, options.gauge_fixed_oldest, options.hold_window_scale)) {
    summary.failed = true;
    classifyOutliers();
    summary.outliers = static_cast<int>(outliers.size());
    return summary;
  }
  // Levenberg-Marquardt in trust-region form: mu = 1 / radius, the radius grows with good
  // steps (by the gain ratio) and shrinks by a growing factor after rejected ones.
  LoopOptions loop;
  loop.damping = DampingPolicy::trustRegion(options.initial_trust_radius);
  loop.max_solves = max_iterations;
  loop.gradient_tolerance = options.gradient_tolerance;
  loop.parameter_tolerance = options.parameter_tolerance;
  loop.function_tolerance = options.function_tolerance;
  WindowProblem problem(window, prior, lin, reduced);
  const LoopSummary s = minimize(problem, loop);
  summary.iterations = s.solves;
  summary.accepted_steps = s.steps;
  summary.initial_cost = s.initial_cost;
  summary.final_cost = s.final_cost;
  summary.converged = s.converged;
  summary.symbolic_analyses = reduced.analyses() - analyses_before;
  summary.landmarks_used = lin.landmarksUsed();
  summary.landmarks_skipped = lin.landmarksSkipped();
  summary.residuals_used = lin.residualsUsed();
  classifyOutliers();
  summary.outliers = static_cast<int>(outliers.size());
  return summary;
}

void SlidingWindowSolver::Impl::classifyOutliers() {
  outliers.clear();
  for (size_t s = 0; s < window.keyframes.size(); ++s) {
    if (window.keyframes[s].used) T_b_w[s] = window.keyframes[s].T_w_b.inverse();
  }
  for (int c = 0; c < window.numCameras(); ++c) T_c_b[c] = window.extrinsics[c].T.inverse();
  for (const ObservationState& ob : window.observations) {
    if (!ob.used) continue;
    const KeyframeState& kf = window.keyframes[ob.keyframe];
    const LandmarkState& lm = window.landmarks[ob.landmark];
    Vec2 r;
    const bool ok = reprojectionResidualInverse(window.rig().model(ob.camera), T_b_w[ob.keyframe], T_c_b[ob.camera],
                                                lm.p_w, ob.uv, ob.inv_sigma, r, nullptr);
    if (!ok || r.squaredNorm() > options.outlier_chi2) outliers.push_back({kf.id, lm.id, ob.camera});
  }
}

SlidingWindowSolver::SlidingWindowSolver(const Rig& rig, const WindowCapacity& capacity, const SolverOptions& options)
    : impl_(std::make_unique<Impl>(rig, capacity, options)) {}
SlidingWindowSolver::~SlidingWindowSolver() = default;

Status SlidingWindowSolver::addKeyframe(int64_t id, const SE3& T_w_b) {
  impl_->outliers.clear();
  return impl_->window.addKeyframe(id, T_w_b);
}
Status SlidingWindowSolver::addLandmark(int64_t id, const Vec3& p_w) {
  impl_->outliers.clear();
  return impl_->window.addLandmark(id, p_w);
}
Status SlidingWindowSolver::addObservation(int64_t keyframe_id, int64_t landmark_id, int camera, const Vec2& uv,
                                           double sigma_px) {
  return impl_->window.addObservation(keyframe_id, landmark_id, camera, uv, sigma_px);
}
Status SlidingWindowSolver::removeObservation(const ObservationKey& key) {
  return impl_->window.removeObservation(key);
}
Status SlidingWindowSolver::removeLandmark(int64_t id) { return impl_->window.removeLandmark(id); }

void SlidingWindowSolver::clear() {
  Impl& m = *impl_;
  m.window.clear();
  m.prior.clear();
  m.options = m.initial_options;
  m.outliers.clear();
  m.marginalized.clear();
}

Status SlidingWindowSolver::setKeyframeFixed(int64_t id, bool fixed) {
  const int s = impl_->window.keyframeSlot(id);
  if (s < 0) return Status::UnknownKeyframe;
  impl_->window.keyframes[s].fixed_by_caller = fixed;
  return Status::Ok;
}
Status SlidingWindowSolver::setGaugeFixedOldest(int count) {
  if (count < 0) return Status::InvalidValue;
  impl_->options.gauge_fixed_oldest = count;
  return Status::Ok;
}
void SlidingWindowSolver::setHoldWindowScale(bool hold) { impl_->options.hold_window_scale = hold; }

Status SlidingWindowSolver::setKeyframePose(int64_t id, const SE3& T_w_b) {
  const int s = impl_->window.keyframeSlot(id);
  if (s < 0) return Status::UnknownKeyframe;
  if (!T_w_b.R.allFinite() || !T_w_b.t.allFinite()) return Status::InvalidValue;
  impl_->window.keyframes[s].T_w_b = T_w_b;
  return Status::Ok;
}
Status SlidingWindowSolver::setLandmarkPosition(int64_t id, const Vec3& p_w) {
  const int s = impl_->window.landmarkSlot(id);
  if (s < 0) return Status::UnknownLandmark;
  if (!p_w.allFinite()) return Status::InvalidValue;
  impl_->window.landmarks[s].p_w = p_w;
  return Status::Ok;
}

Status SlidingWindowSolver::setExtrinsic(int camera, const SE3& T_b_c, bool keep_calibration_prior) {
  if (camera < 0 || camera >= impl_->window.numCameras() || !impl_->window.extrinsics[camera].variable) {
    return Status::InvalidCamera;
  }
  if (!T_b_c.R.allFinite() || !T_b_c.t.allFinite()) return Status::InvalidValue;
  ExtrinsicState& e = impl_->window.extrinsics[camera];
  if (e.in_prior) impl_->prior.forgetExtrinsic(camera, impl_->window);
  e.T = T_b_c;
  e.T.normalize();
  e.T_lin = e.T;
  e.d.setZero();
  e.calibration_prior = e.calibration_prior && keep_calibration_prior;
  return Status::Ok;
}

SolveSummary SlidingWindowSolver::solve(int max_iterations) { return impl_->solve(max_iterations); }
std::span<const ObservationKey> SlidingWindowSolver::outliers() const { return impl_->outliers; }

Status SlidingWindowSolver::marginalizeOldest() {
  impl_->outliers.clear();
  return impl_->marginalizer.marginalizeOldest(impl_->window, impl_->prior, impl_->marginalized);
}
std::span<const int64_t> SlidingWindowSolver::marginalizedLandmarks() const { return impl_->marginalized; }

bool SlidingWindowSolver::keyframePose(int64_t id, SE3& T_w_b) const {
  const int s = impl_->window.keyframeSlot(id);
  if (s < 0) return false;
  T_w_b = impl_->window.keyframes[s].T_w_b;
  return true;
}
bool SlidingWindowSolver::landmarkPosition(int64_t id, Vec3& p_w) const {
  const int s = impl_->window.landmarkSlot(id);
  if (s < 0) return false;
  p_w = impl_->window.landmarks[s].p_w;
  return true;
}
const SE3& SlidingWindowSolver::extrinsic(int camera) const { return impl_->window.extrinsics.at(camera).T; }
Rig SlidingWindowSolver::refinedRig() const {
  Rig rig = impl_->window.rig();
  for (int c = 0; c < rig.size(); ++c) rig.cameras[c].T_b_c = impl_->window.extrinsics[c].T;
  return rig;
}
std::optional<int64_t> SlidingWindowSolver::oldestKeyframe() const {
  const int s = impl_->window.oldestKeyframe();
  if (s < 0) return std::nullopt;
  return impl_->window.keyframes[s].id;
}
int SlidingWindowSolver::numKeyframes() const { return impl_->window.num_keyframes; }
int SlidingWindowSolver::numLandmarks() const { return impl_->window.num_landmarks; }
int SlidingWindowSolver::numObservations() const { return impl_->window.num_observations; }
bool SlidingWindowSolver::isFull() const {
  return impl_->window.num_keyframes >= impl_->window.capacity().max_keyframes;
}
const Eigen::MatrixXd& SlidingWindowSolver::priorInformation() const { return impl_->prior.H; }
bool SlidingWindowSolver::hasCalibrationPrior(int camera) const {
  return impl_->window.extrinsics.at(camera).variable && impl_->window.extrinsics.at(camera).calibration_prior;
}
bool SlidingWindowSolver::extrinsicInPrior(int camera) const { return impl_->window.extrinsics.at(camera).in_prior; }
size_t SlidingWindowSolver::cholmodArenaPeakBytes() const { return impl_->reduced.arena().peakBytes(); }
size_t SlidingWindowSolver::cholmodArenaOverflows() const { return impl_->reduced.arena().overflows(); }

}  // namespace mcslam::backend
