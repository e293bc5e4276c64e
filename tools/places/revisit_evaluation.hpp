#pragma once
// Precision and recall of place recognition on a dataset with ground truth: keyframes are taken along the
// ground-truth path (every `keyframe_distance_m` or `keyframe_angle_deg`); each one queries the database of the
// keyframes before it (leaving out the last `exclude_recent_s` seconds, which any odometry still tracks), and its
// best candidate is right when the two poses are within `revisit_distance_m` and `revisit_angle_deg`.
#include <string>
#include <vector>

#include "mcslam/features/orb_extractor.hpp"
#include "mcslam/recognition/vocabulary.hpp"

namespace mcslam::places_tool {

struct RevisitOptions {
  double keyframe_distance_m = 0.5;
  double keyframe_angle_deg = 15;
  double exclude_recent_s = 20;
  double revisit_distance_m = 2;
  double revisit_angle_deg = 30;
  int max_words_per_place = 2000;  // PlacesOptions' default
  std::vector<int> cameras;        // subset of the rig (empty: all)
};

struct RevisitQuery {
  double t = 0;              // seconds
  bool has_revisit = false;  // some eligible keyframe is within the revisit bounds
  int candidate = -1;        // best keyframe, -1 when none shares a word
  float score = 0;           // its similarity
  float normalized = 0;      // the score over the query's similarity to the keyframe before it (DBoW2's)
  bool correct = false;      // the candidate is within the revisit bounds
};

struct RevisitResult {
  int keyframes = 0;
  std::vector<RevisitQuery> queries;
  double mean_query_ms = 0, max_query_ms = 0;  // words of every camera + database query, per keyframe
  double mean_features = 0;                    // per keyframe, all cameras
};

RevisitResult evaluateRevisits(const std::string& dataset_dir, const Vocabulary& vocabulary, const OrbOptions& orb,
                               const RevisitOptions& options);

// A point of the precision-recall curve: accepting queries whose score is at least `threshold`.
struct PrPoint {
  float threshold = 0;
  double precision = 0, recall = 0;
  int accepted = 0, correct = 0;
};
// The curve over every distinct score (by the raw score, or by the normalized one).
std::vector<PrPoint> precisionRecall(const RevisitResult& result, bool normalized);
// The point of highest recall at 100% precision (recall 0 when the best-scored query is wrong).
PrPoint bestAtFullPrecision(const std::vector<PrPoint>& curve);

}  // namespace mcslam::places_tool
