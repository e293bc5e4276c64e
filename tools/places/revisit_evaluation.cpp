#include "revisit_evaluation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/recognition/place_database.hpp"

namespace mcslam::places_tool {

namespace {

constexpr double kDeg = M_PI / 180.0;

// The ground-truth pose nearest in time to t (within 20 ms), or nullptr.
const SE3* poseAt(const Trajectory& gt, Timestamp t) {
  auto it = std::lower_bound(gt.begin(), gt.end(), t, [](const StampedPose& p, Timestamp x) { return p.t < x; });
  const StampedPose* best = nullptr;
  if (it != gt.end()) best = &*it;
  if (it != gt.begin() && (!best || t - std::prev(it)->t < best->t - t)) best = &*std::prev(it);
  if (!best || std::llabs(best->t - t) > 20'000'000) return nullptr;
  return &best->T_w_b;
}

bool within(const SE3& a, const SE3& b, double distance, double angle_deg) {
  return (a.t - b.t).norm() <= distance && rotationAngle(a.R, b.R) <= angle_deg * kDeg;
}

struct KeyframeRecord {
  Timestamp t = 0;
  SE3 pose;
};

}  // namespace

RevisitResult evaluateRevisits(const std::string& dataset_dir, const Vocabulary& vocabulary, const OrbOptions& orb,
                               const RevisitOptions& o) {
  DatasetOptions dataset_options;
  dataset_options.cameras = o.cameras;
  const Dataset dataset = Dataset::open(dataset_dir, dataset_options);
  const Trajectory& gt = dataset.requireGroundTruth();
  const int cameras = dataset.rig().size();
  int max_width = 0, max_height = 0;
  for (int c = 0; c < cameras; ++c) {
    max_width = std::max(max_width, dataset.rig().model(c).width());
    max_height = std::max(max_height, dataset.rig().model(c).height());
  }
  OrbExtractor extractor(orb, max_width, max_height);
  FrameFeatures frame(cameras, orb.max_features);
  FrameWords words(cameras, orb.max_features);
  const int capacity = static_cast<int>(dataset.size());
  PlaceDatabase database(vocabulary.wordCount(), capacity, o.max_words_per_place);
  std::vector<KeyframeRecord> keyframes;
  BowVector previous(cameras * orb.max_features);
  std::vector<PlaceScore> best(1);
  std::vector<Image> images;
  std::vector<bool> present;
  RevisitResult result;
  double features = 0;
  for (std::size_t i = 0; i < dataset.size(); ++i) {
    const RigFrameEntry& entry = dataset.frames()[i];
    const SE3* pose = poseAt(gt, entry.t);
    if (!pose) continue;
    if (!keyframes.empty() && within(*pose, keyframes.back().pose, o.keyframe_distance_m, o.keyframe_angle_deg))
      continue;
    std::string error;
    dataset.loadImages(i, images, present, &error);
    if (!error.empty()) throw InputError(error);
    for (int c = 0; c < cameras; ++c) {
      frame.present[static_cast<std::size_t>(c)] = present[static_cast<std::size_t>(c)] ? 1 : 0;
      frame.sets[static_cast<std::size_t>(c)].count = 0;
      if (present[static_cast<std::size_t>(c)])
        extractor.extract(images[static_cast<std::size_t>(c)].view(), frame.sets[static_cast<std::size_t>(c)]);
      features += frame.sets[static_cast<std::size_t>(c)].count;
    }
    const auto extracted = std::chrono::steady_clock::now();
    words.compute(vocabulary, frame);
    const double t = static_cast<double>(entry.t) * 1e-9;
    const auto eligible = [&](int k) {
      return t - static_cast<double>(keyframes[static_cast<std::size_t>(k)].t) * 1e-9 >= o.exclude_recent_s;
    };
    RevisitQuery q;
    q.t = t;
    if (database.query(words.bow(), 0.0f, best, eligible) == 1) {
      q.candidate = best[0].place;
      q.score = best[0].score;
      const float reference = bowSimilarity(words.bow(), previous);
      q.normalized = reference > 0 ? q.score / reference : 0;
      q.correct = within(*pose, keyframes[static_cast<std::size_t>(q.candidate)].pose, o.revisit_distance_m,
                         o.revisit_angle_deg);
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - extracted).count();
    result.mean_query_ms += ms;
    result.max_query_ms = std::max(result.max_query_ms, ms);
    for (std::size_t k = 0; k < keyframes.size() && !q.has_revisit; ++k)
      q.has_revisit =
          eligible(static_cast<int>(k)) && within(*pose, keyframes[k].pose, o.revisit_distance_m, o.revisit_angle_deg);
    result.queries.push_back(q);
    database.insert(static_cast<int>(keyframes.size()), words.bow());
    keyframes.push_back({entry.t, *pose});
    previous = words.bow();
  }
  result.keyframes = static_cast<int>(keyframes.size());
  if (result.keyframes > 0) {
    result.mean_query_ms /= result.keyframes;
    result.mean_features = features / result.keyframes;
  }
  return result;
}

std::vector<PrPoint> precisionRecall(const RevisitResult& result, bool normalized) {
  std::vector<const RevisitQuery*> scored;
  int revisits = 0;
  for (const RevisitQuery& q : result.queries) {
    revisits += q.has_revisit ? 1 : 0;
    if (q.candidate >= 0) scored.push_back(&q);
  }
  const auto score = [normalized](const RevisitQuery* q) { return normalized ? q->normalized : q->score; };
  std::sort(scored.begin(), scored.end(), [&](auto* a, auto* b) { return score(a) > score(b); });
  std::vector<PrPoint> curve;
  int accepted = 0, correct = 0;
  for (std::size_t i = 0; i < scored.size(); ++i) {
    ++accepted;
    correct += scored[i]->correct ? 1 : 0;
    if (i + 1 < scored.size() && score(scored[i + 1]) == score(scored[i])) continue;
    curve.push_back({score(scored[i]), static_cast<double>(correct) / accepted,
                     revisits > 0 ? static_cast<double>(correct) / revisits : 0.0, accepted, correct});
  }
  return curve;
}

PrPoint bestAtFullPrecision(const std::vector<PrPoint>& curve) {
  PrPoint best;
  best.threshold = INFINITY;
  best.precision = 1;
  for (const PrPoint& p : curve) {
    if (p.precision < 1.0) break;
    best = p;
  }
  return best;
}

}  // namespace mcslam::places_tool
