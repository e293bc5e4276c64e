#include "mcslam/eval/trajectory_metrics.hpp"

#include <cmath>
#include <cstdio>

#include "first_nearest.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/eval/association.hpp"

namespace mcslam {

namespace {

std::string describeSpan(const std::string& name, const Trajectory& traj) {
  char buf[128];
  std::snprintf(buf, sizeof(buf), " (%zu poses, %.3f .. %.3f s)", traj.size(), toSeconds(traj.front().t),
                toSeconds(traj.back().t));
  return name + buf;
}

std::string formatSeconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", s);
  return buf;
}

}  // namespace

AlignedTrajectories associateAndAlign(const Trajectory& ref, const Trajectory& est, const EvalOptions& options) {
  if (ref.empty()) throw InputError(options.reference_name + ": the reference trajectory has no poses");
  if (est.empty()) throw InputError(options.estimate_name + ": the estimated trajectory has no poses");
  if (!(options.max_diff_s >= 0))
    throw InputError("max. time difference must be >= 0 s, got " + formatSeconds(options.max_diff_s));
  const TimeAssociation assoc = associateByTime(ref, est, options.max_diff_s, options.t_offset_s);
  if (assoc.size() == 0) {
    throw InputError("no matching timestamps between " + describeSpan(options.reference_name, ref) + " and " +
                     describeSpan(options.estimate_name, est) + " with max. time difference " +
                     formatSeconds(options.max_diff_s) + " s" +
                     (options.t_offset_s != 0 ? " and time offset " + formatSeconds(options.t_offset_s) + " s" : ""));
  }
  AlignedTrajectories out;
  out.ref.reserve(assoc.size());
  out.est.reserve(assoc.size());
  for (std::size_t k = 0; k < assoc.size(); ++k) {
    out.ref.push_back(ref[assoc.ref[k]]);
    out.est.push_back(est[assoc.est[k]]);
  }
  if (options.align != AlignMode::None) {
    try {
      out.alignment = umeyamaAlignment(positionsOf(out.est), positionsOf(out.ref), options.align == AlignMode::Sim3);
    } catch (const InputError& e) {
      throw InputError(options.estimate_name + ": " + e.what() + " after association with " + options.reference_name +
                       " (" + std::to_string(assoc.size()) + " pairs); try --align none");
    }
    out.est = transformTrajectory(out.est, out.alignment);
  }
  out.ref_path_length = pathLength(out.ref);
  return out;
}

ApeResult computeApe(const Trajectory& ref, const Trajectory& est, const EvalOptions& options) {
  ApeResult r;
  r.data = associateAndAlign(ref, est, options);
  r.errors.reserve(r.data.ref.size());
  for (std::size_t i = 0; i < r.data.ref.size(); ++i)
    r.errors.push_back((r.data.est[i].T_w_b.t - r.data.ref[i].T_w_b.t).norm());
  r.stats = computeErrorStats(r.errors);
  r.rmse_percent = r.data.ref_path_length > 0 ? 100.0 * r.stats.rmse / r.data.ref_path_length : 0.0;
  return r;
}

IndexPairs rpePairs(const Trajectory& traj, double delta, DeltaUnit unit, bool all_pairs, double rel_delta_tol) {
  IndexPairs pairs;
  const std::size_t n = traj.size();
  if (unit == DeltaUnit::Frames) {
    if (!(delta >= 1) || delta != std::floor(delta)) {
      throw InputError("RPE delta in frames must be a whole number >= 1, got " + formatSeconds(delta));
    }
    const std::size_t d = static_cast<std::size_t>(delta);
    if (all_pairs) {
      for (std::size_t i = 0; i + d < n; ++i) pairs.emplace_back(i, i + d);
    } else {
      for (std::size_t i = 0; i + d < n; i += d) pairs.emplace_back(i, i + d);
    }
    return pairs;
  }
  if (!(delta > 0) || !std::isfinite(delta))
    throw InputError("RPE delta in metres must be > 0, got " + formatSeconds(delta));
  if (all_pairs) {
    std::vector<double> travelled(n, 0.0);
    for (std::size_t i = 1; i < n; ++i)
      travelled[i] = travelled[i - 1] + (traj[i].T_w_b.t - traj[i - 1].T_w_b.t).norm();
    const double tol = delta * rel_delta_tol;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      const auto from_here = [&](std::size_t k) { return travelled[k] - travelled[i]; };
      const std::size_t j = detail::firstNearest(i + 1, n, from_here, delta);
      if (std::abs(from_here(j) - delta) <= tol) pairs.emplace_back(i, j);
    }
    return pairs;
  }
  // Consecutive: an index is kept each time the path since the last kept one reaches delta; the first pose
  // is not itself kept (evo's filter_pairs_by_path).
  std::vector<std::size_t> ids;
  double travelled = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) travelled += (traj[i].T_w_b.t - traj[i - 1].T_w_b.t).norm();
    if (travelled >= delta) {
      ids.push_back(i);
      travelled = 0;
    }
  }
  for (std::size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return pairs;
}

RpeResult computeRpe(const Trajectory& ref, const Trajectory& est, const RpeOptions& options) {
  RpeResult r;
  r.data = associateAndAlign(ref, est, options.eval);
  const Trajectory& pairing = options.pairs_from_reference ? r.data.ref : r.data.est;
  r.pairs = rpePairs(pairing, options.delta, options.unit, options.all_pairs, options.rel_delta_tol);
  if (r.pairs.empty()) {
    throw InputError("RPE: delta " + formatSeconds(options.delta) +
                     (options.unit == DeltaUnit::Frames ? " frames" : " m") + " gives no pair of poses among the " +
                     std::to_string(pairing.size()) + " associated poses of " +
                     (options.pairs_from_reference ? options.eval.reference_name : options.eval.estimate_name) +
                     "; try a smaller delta");
  }
  r.translation_errors.reserve(r.pairs.size());
  r.rotation_errors_deg.reserve(r.pairs.size());
  for (const auto& [i, j] : r.pairs) {
    const SE3 Q = r.data.ref[i].T_w_b.inverse() * r.data.ref[j].T_w_b;
    const SE3 P = r.data.est[i].T_w_b.inverse() * r.data.est[j].T_w_b;
    const SE3 E = Q.inverse() * P;
    r.translation_errors.push_back(E.t.norm());
    r.rotation_errors_deg.push_back(so3Log(E.R).norm() * 180.0 / M_PI);
  }
  r.translation = computeErrorStats(r.translation_errors);
  r.rotation_deg = computeErrorStats(r.rotation_errors_deg);
  r.rmse_percent = r.data.ref_path_length > 0 ? 100.0 * r.translation.rmse / r.data.ref_path_length : 0.0;
  return r;
}

}  // namespace mcslam
