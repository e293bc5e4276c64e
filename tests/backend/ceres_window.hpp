#pragma once
// The same window as a Ceres problem, for the oracle test and the benchmark yardstick:
// identical residuals (our reprojection and extrinsic-prior functions), identical right
// perturbation T * exp(d) on poses and extrinsics, the same robust loss and gauge.
// Poses are stored as [t, q(x y z w)]; the manifold's PlusJacobian is [I6; 0] and the cost
// functions put d r / d(delta) in the first six columns, so Ceres sees our exact tangent
// Jacobians.
#include <ceres/ceres.h>

#include <memory>
#include <vector>

#include "backend_testkit.hpp"
#include "mcslam/backend/extrinsic_prior.hpp"
#include "mcslam/backend/reprojection_residual.hpp"

namespace mcslam::backend::testkit {

inline void toParams(const SE3& T, double* x) {
  const Eigen::Quaterniond q = T.quaternion();
  x[0] = T.t.x(), x[1] = T.t.y(), x[2] = T.t.z();
  x[3] = q.x(), x[4] = q.y(), x[5] = q.z(), x[6] = q.w();
}
inline SE3 fromParams(const double* x) { return {Eigen::Quaterniond(x[6], x[3], x[4], x[5]), Vec3(x[0], x[1], x[2])}; }

class SE3RightManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    toParams(fromParams(x) * SE3::exp(Eigen::Map<const Vec6>(delta)), x_plus_delta);
    return true;
  }
  bool PlusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.topRows<6>().setIdentity();
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    Eigen::Map<Vec6> out(y_minus_x);
    out = (fromParams(x).inverse() * fromParams(y)).log();
    return true;
  }
  bool MinusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.leftCols<6>().setIdentity();
    return true;
  }
};

class ReprojectionCost : public ceres::SizedCostFunction<2, 7, 7, 3> {
 public:
  ReprojectionCost(const CameraModel* camera, const Vec2& uv, double sigma) : camera_(camera), uv_(uv), sigma_(sigma) {}
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    Vec2 r;
    ReprojectionJacobians J;
    const bool want = jacobians != nullptr;
    if (!reprojectionResidual(*camera_, fromParams(p[0]), fromParams(p[1]), Vec3(p[2][0], p[2][1], p[2][2]), uv_,
                              sigma_, r, want ? &J : nullptr)) {
      return false;
    }
    residuals[0] = r(0), residuals[1] = r(1);
    if (!want) return true;
    if (jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> Jp(jacobians[0]);
      Jp.leftCols<6>() = J.pose;
      Jp.col(6).setZero();
    }
    if (jacobians[1]) {
      Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> Je(jacobians[1]);
      Je.leftCols<6>() = J.extrinsic;
      Je.col(6).setZero();
    }
    if (jacobians[2]) {
      Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> Jl(jacobians[2]);
      Jl = J.point;
    }
    return true;
  }

 private:
  const CameraModel* camera_;
  Vec2 uv_;
  double sigma_;
};

class ExtrinsicPriorCost : public ceres::SizedCostFunction<6, 7> {
 public:
  ExtrinsicPriorCost(const SE3& calib, const ExtrinsicPriorSigmas& sigmas) : calib_(calib), sigmas_(sigmas) {}
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    Mat6 J;
    const bool want = jacobians && jacobians[0];
    Eigen::Map<Vec6> r(residuals);
    r = extrinsicPriorResidual(calib_, fromParams(p[0]), sigmas_, nullptr, want ? &J : nullptr);
    if (want) {
      Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> Jm(jacobians[0]);
      Jm.leftCols<6>() = J;
      Jm.col(6).setZero();
    }
    return true;
  }

 private:
  SE3 calib_;
  ExtrinsicPriorSigmas sigmas_;
};

// Owns the parameter blocks and the problem.
struct CeresWindow {
  std::vector<std::array<double, 7>> poses, extrinsics;
  std::vector<std::array<double, 3>> points;
  std::unique_ptr<ceres::Problem> problem;

  SE3 pose(int k) const { return fromParams(poses[k].data()); }
  SE3 extrinsic(int c) const { return fromParams(extrinsics[c].data()); }
  Vec3 point(int l) const { return {points[l][0], points[l][1], points[l][2]}; }
};

inline ceres::LossFunction* makeLoss(const RobustLoss& loss) {
  switch (loss.kind) {
    case LossKind::Trivial: return nullptr;
    case LossKind::Huber: return new ceres::HuberLoss(loss.threshold);
    case LossKind::Cauchy: return new ceres::CauchyLoss(loss.threshold);
  }
  return nullptr;
}

// `solver_rig` is what the solver was given (calibration prior mean and initial extrinsics).
inline std::unique_ptr<CeresWindow> buildCeresWindow(const Scene& scene, const WindowGuess& guess,
                                                     const Rig& solver_rig, const SolverOptions& options) {
  auto w = std::make_unique<CeresWindow>();
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  w->problem = std::make_unique<ceres::Problem>(po);
  static SE3RightManifold manifold;
  w->poses.resize(scene.T_w_b.size());
  w->extrinsics.resize(solver_rig.size());
  w->points.resize(scene.points.size());
  for (size_t k = 0; k < scene.T_w_b.size(); ++k) toParams(guess.T_w_b[k], w->poses[k].data());
  for (int c = 0; c < solver_rig.size(); ++c) toParams(solver_rig.T_b_c(c), w->extrinsics[c].data());
  for (size_t l = 0; l < scene.points.size(); ++l) {
    for (int i = 0; i < 3; ++i) w->points[l][i] = guess.points[l](i);
  }
  for (const SceneObservation& ob : scene.observations) {
    if (scene.num_observations[ob.landmark] < 2) continue;
    w->problem->AddResidualBlock(new ReprojectionCost(&scene.rig.cameras[ob.camera].model, ob.uv, ob.sigma),
                                 makeLoss(options.loss), w->poses[ob.keyframe].data(), w->extrinsics[ob.camera].data(),
                                 w->points[ob.landmark].data());
  }
  for (auto& p : w->poses) w->problem->SetManifold(p.data(), &manifold);
  for (int c = 0; c < solver_rig.size(); ++c) {
    double* e = w->extrinsics[c].data();
    w->problem->SetManifold(e, &manifold);
    const bool variable = options.refine_extrinsics && c != options.reference_camera;
    if (variable) {
      w->problem->AddResidualBlock(new ExtrinsicPriorCost(solver_rig.T_b_c(c), options.extrinsic_prior), nullptr, e);
    } else {
      w->problem->SetParameterBlockConstant(e);
    }
  }
  for (int k = 0; k < options.gauge_fixed_oldest; ++k) w->problem->SetParameterBlockConstant(w->poses[k].data());
  return w;
}

// Landmarks first: the Schur complement eliminates exactly what ours does.
inline void setSchurOrdering(ceres::Solver::Options& o, CeresWindow& w) {
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  auto add = [&](double* block, int group) {
    if (w.problem->HasParameterBlock(block)) ordering->AddElementToGroup(block, group);
  };
  for (auto& p : w.points) add(p.data(), 0);
  for (auto& p : w.poses) add(p.data(), 1);
  for (auto& e : w.extrinsics) add(e.data(), 1);
  o.linear_solver_ordering = ordering;
}

inline ceres::Solver::Options ceresOptions(int max_iterations, double tolerance) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::SPARSE_SCHUR;
  o.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  o.minimizer_type = ceres::TRUST_REGION;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  o.num_threads = 1;
  o.max_num_iterations = max_iterations;
  o.function_tolerance = tolerance;
  o.gradient_tolerance = tolerance;
  o.parameter_tolerance = tolerance;
  o.logging_type = ceres::SILENT;
  o.minimizer_progress_to_stdout = false;
  return o;
}

}  // namespace mcslam::backend::testkit
