#include "mcslam/places/loop_scale.hpp"

#include <algorithm>
#include <cmath>

#include "mcslam/core/median.hpp"

namespace mcslam {

namespace {

// Fewer depths than this give no median worth a loop: a loop holds the whole map's unit.
constexpr int kMinSamples = 20;

}  // namespace

LoopScale loopScale(std::span<const PlaceMatch> inliers, std::span<const Eigen::Vector3f> own_points, int per_camera,
                    const SE3& T_w_b, const Rig& rig, std::vector<double>& scratch, int keyframe, int cam) {
  LoopScale result;
  const SE3 T_b_w = T_w_b.inverse();
  std::size_t n = 0;
  for (const PlaceMatch& m : inliers) {
    if ((keyframe >= 0 && m.keyframe != keyframe) || (cam >= 0 && m.cam != cam)) continue;
    const auto index =
        static_cast<std::size_t>(m.cam) * static_cast<std::size_t>(per_camera) + static_cast<std::size_t>(m.kp);
    if (index >= own_points.size() || n == scratch.size()) continue;
    const Eigen::Vector3f& own = own_points[index];
    if (!own.allFinite()) continue;
    const Vec3 centre = rig.T_b_c(m.cam).t;
    const double theirs = (T_b_w * m.p_w - centre).norm();
    const double mine = (own.cast<double>() - centre).norm();
    if (!(mine > 0) || !(theirs > 0)) continue;
    scratch[n++] = std::log(theirs / mine);
  }
  result.samples = static_cast<int>(n);
  if (result.samples < kMinSamples) return result;
  const double log_scale = medianOf(scratch, result.samples);
  for (std::size_t i = 0; i < n; ++i) scratch[i] = std::abs(scratch[i] - log_scale);
  const double mad = medianOf(scratch, result.samples);
  result.ok = true;
  result.scale = std::exp(log_scale);
  // The median's standard error: 1.4826 MAD is the spread of one ratio, and the median of n has about 1.25 times
  // the mean's error.
  result.sigma_log_scale = 1.25 * 1.4826 * mad / std::sqrt(static_cast<double>(n));
  return result;
}

PlaceUnit placeUnit(double place_unit_sigma, double keyframe_unit_sigma, const LoopScale& scale) {
  if (place_unit_sigma < kUncertainUnit) return PlaceUnit::Known;
  if (keyframe_unit_sigma >= kUncertainUnit || !scale.ok) return PlaceUnit::Unmeasured;
  const double allowed = 3 * std::max(scale.sigma_log_scale, kLoopLogScaleSigmaFloor);
  return std::abs(std::log(scale.scale)) <= allowed ? PlaceUnit::Known : PlaceUnit::Other;
}

}  // namespace mcslam
