#pragma once
// Absolute and relative pose errors of an estimated trajectory against a reference, like evo_ape and
// evo_rpe: associate by time, optionally align (Umeyama SE(3) or Sim(3)), then measure.
//  - APE: |t_ref_i - t_est_i| after alignment (evo's "translation part").
//  - RPE: for index pairs (i, j), E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) with Q the reference and P the
//    estimate; the translation error is |t(E)|, the rotation error the angle of R(E) in degrees.
// Path length and "rmse as % of path" refer to the associated reference.
#include <string>
#include <utility>
#include <vector>

#include "mcslam/dataset/trajectory.hpp"
#include "mcslam/eval/alignment.hpp"
#include "mcslam/eval/error_stats.hpp"

namespace mcslam {

struct EvalOptions {
  AlignMode align = AlignMode::SE3;
  double max_diff_s = 0.01;  // largest stamp difference of an associated pair (evo's default)
  double t_offset_s = 0.0;   // added to the estimate's stamps before association
  // Names for messages (usually the file paths).
  std::string reference_name = "reference";
  std::string estimate_name = "estimate";
};

// The associated, aligned pair both metrics work on.
struct AlignedTrajectories {
  Trajectory ref;              // associated reference poses
  Trajectory est;              // associated estimate poses, aligned onto the reference
  Similarity alignment;        // what was applied to the estimate (identity for AlignMode::None)
  double ref_path_length = 0;  // of the associated reference, metres
};

// Throws InputError naming both trajectories when one is empty, nothing associates or alignment fails.
AlignedTrajectories associateAndAlign(const Trajectory& ref, const Trajectory& est, const EvalOptions& options);

struct ApeResult {
  AlignedTrajectories data;
  std::vector<double> errors;  // metres, one per associated pose
  ErrorStats stats;
  double rmse_percent = 0;  // rmse / ref_path_length * 100 (0 when the path has no length)
};

ApeResult computeApe(const Trajectory& ref, const Trajectory& est, const EvalOptions& options);

enum class DeltaUnit { Frames, Meters };

struct RpeOptions {
  EvalOptions eval;
  double delta = 1;  // frames (a whole number) or metres of travelled path
  DeltaUnit unit = DeltaUnit::Frames;
  bool all_pairs = false;             // every start index instead of consecutive, non-overlapping pairs
  bool pairs_from_reference = false;  // evo pairs on the estimate's path unless asked otherwise
  double rel_delta_tol = 0.1;         // metres with all_pairs: accept |path - delta| <= tol * delta
};

using IndexPairs = std::vector<std::pair<std::size_t, std::size_t>>;

// evo's pairing (filters.py): frames: (0,d), (d,2d), ... or with all_pairs (i, i+d); metres: indices where
// the path travelled since the last one first reaches delta, consecutive; or with all_pairs, for each i the
// later index whose path distance is nearest delta, kept within the tolerance. Throws InputError for a bad delta.
IndexPairs rpePairs(const Trajectory& traj, double delta, DeltaUnit unit, bool all_pairs, double rel_delta_tol);

struct RpeResult {
  AlignedTrajectories data;
  IndexPairs pairs;
  std::vector<double> translation_errors;   // metres, one per pair
  std::vector<double> rotation_errors_deg;  // degrees, one per pair
  ErrorStats translation;
  ErrorStats rotation_deg;
  double rmse_percent = 0;  // translation rmse / ref_path_length * 100
};

// Throws InputError when the delta gives no pair.
RpeResult computeRpe(const Trajectory& ref, const Trajectory& est, const RpeOptions& options);

}  // namespace mcslam
