#pragma once
// Marginalization of the oldest keyframe (see sliding_window_solver.hpp for the policy).
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <vector>

#include "marginalization_prior.hpp"
#include "mcslam/backend/schur_accumulator.hpp"
#include "window_storage.hpp"

namespace mcslam::backend {

class Marginalizer {
 public:
  Marginalizer(const WindowStorage& window, const SolverOptions& options);

  // Folds the oldest keyframe and the landmarks only it observes into `prior`, then removes them
  // and the keyframe's other observations from the window. Ids of removed landmarks go to
  // `removed` (whose capacity the caller reserved).
  Status marginalizeOldest(WindowStorage& window, MarginalizationPrior& prior, std::vector<int64_t>& removed);

 private:
  // Linearizes the exclusive landmarks' observations at the current state into H_, g_, c_ over
  // [oldest pose | free extrinsics], eliminating each landmark.
  void accumulateExclusiveLandmarks(const WindowStorage& window, int keyframe);
  // Eliminates the pose block and adds the result to the prior (around its fixed linearization
  // point), keeping the prior symmetric positive semi-definite.
  void foldIntoPrior(WindowStorage& window, MarginalizationPrior& prior);
  bool isExclusiveTo(const WindowStorage& window, int landmark, int keyframe) const;

  struct ObservationLin {
    Vec2 r;
    Mat26 Jp;
    Mat26 Je;
    Mat23 Jl;
    int ext_var;
  };

  const SolverOptions options_;
  int num_ext_vars_ = 0;
  std::vector<int> ext_var_of_camera_;
  std::vector<ObservationLin> obs_;  // one landmark's observations (at most one per camera)
  SchurAccumulator schur_;           // eliminates the exclusive landmarks
  Eigen::MatrixXd H_;                // (6 + 6 n) square: [pose | extrinsics]
  Eigen::VectorXd g_;
  double c_ = 0;
  double pose_scale_ = 0;  // largest diagonal of the pose block before eliminating landmarks
  Eigen::MatrixXd K_;      // H_e0 * H_00^+
  Eigen::MatrixXd Hn_;
  Eigen::VectorXd gn_;
};

}  // namespace mcslam::backend
