#include "mcslam/eval/alignment.hpp"

#include <Eigen/SVD>
#include <limits>

#include "mcslam/core/error.hpp"

namespace mcslam {

AlignMode parseAlignMode(const std::string& name) {
  if (name == "none") return AlignMode::None;
  if (name == "se3") return AlignMode::SE3;
  if (name == "sim3") return AlignMode::Sim3;
  throw InputError("alignment '" + name + "' is unknown (expected se3, sim3 or none)");
}

const char* alignModeName(AlignMode mode) {
  switch (mode) {
    case AlignMode::None: return "none";
    case AlignMode::SE3: return "se3";
    case AlignMode::Sim3: return "sim3";
  }
  return "?";
}

Similarity umeyamaAlignment(const std::vector<Vec3>& from, const std::vector<Vec3>& to, bool with_scale) {
  if (from.size() != to.size()) throw InputError("alignment: point sets differ in size");
  if (from.empty()) throw InputError("alignment: no points to align");
  const double n = static_cast<double>(from.size());
  Vec3 mean_from = Vec3::Zero(), mean_to = Vec3::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) {
    mean_from += from[i];
    mean_to += to[i];
  }
  mean_from /= n;
  mean_to /= n;
  // Umeyama (1991) eq. 36 and 38: variance of the source, covariance to-from.
  double var_from = 0;
  Mat3 cov = Mat3::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) {
    const Vec3 a = from[i] - mean_from;
    var_from += a.squaredNorm();
    cov += (to[i] - mean_to) * a.transpose();
  }
  var_from /= n;
  cov /= n;

  const Eigen::JacobiSVD<Mat3> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 d = svd.singularValues();
  int rank = 0;
  for (int k = 0; k < 3; ++k) rank += d[k] > std::numeric_limits<double>::epsilon() ? 1 : 0;
  if (rank < 2) {
    throw InputError("alignment is not possible: the associated positions are degenerate (" +
                     std::string(from.size() < 3 ? "fewer than 3 poses" : "all on one line or one point") + ")");
  }
  // Eq. 43: flip the last axis when needed so that R is a rotation, not a reflection.
  Mat3 S = Mat3::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1;

  Similarity out;
  out.R = svd.matrixU() * S * svd.matrixV().transpose();
  out.s = with_scale ? (d.asDiagonal() * S).trace() / var_from : 1.0;
  out.t = mean_to - out.s * (out.R * mean_from);
  return out;
}

Trajectory transformTrajectory(const Trajectory& traj, const Similarity& S) {
  Trajectory out = traj;
  for (StampedPose& p : out) p.T_w_b = S.apply(p.T_w_b);
  return out;
}

std::vector<Vec3> positionsOf(const Trajectory& traj) {
  std::vector<Vec3> out;
  out.reserve(traj.size());
  for (const StampedPose& p : traj) out.push_back(p.T_w_b.t);
  return out;
}

}  // namespace mcslam
