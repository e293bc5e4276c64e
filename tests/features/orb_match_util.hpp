#pragma once
// Matching helpers shared by the ORB quality tests: brute-force Hamming matching with mutual nearest
// neighbour + ratio test, and conversions from cv::ORB's output, so both extractors are scored alike.
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include <array>
#include <climits>
#include <cstring>
#include <functional>
#include <vector>

#include "mcslam/features/keypoint.hpp"

namespace mcslam::test {

struct Match {
  int a, b;
};

// Mutual nearest neighbours whose best distance is below ratio x the second best (in both directions).
inline std::vector<Match> mutualRatioMatches(const FeatureSet& a, const FeatureSet& b, double ratio = 0.8) {
  auto nearest = [ratio](const FeatureSet& q, const FeatureSet& t, std::vector<int>& best_of) {
    best_of.assign(static_cast<size_t>(q.count), -1);
    for (int i = 0; i < q.count; ++i) {
      int best = INT_MAX, second = INT_MAX, best_j = -1;
      for (int j = 0; j < t.count; ++j) {
        const int d = hammingDistance(q.descriptors[i], t.descriptors[j]);
        if (d < best) {
          second = best;
          best = d;
          best_j = j;
        } else if (d < second) {
          second = d;
        }
      }
      if (best_j >= 0 && best < ratio * second) best_of[static_cast<size_t>(i)] = best_j;
    }
  };
  std::vector<int> ab, ba;
  nearest(a, b, ab);
  nearest(b, a, ba);
  std::vector<Match> matches;
  for (int i = 0; i < a.count; ++i) {
    const int j = ab[static_cast<size_t>(i)];
    if (j >= 0 && ba[static_cast<size_t>(j)] == i) matches.push_back({i, j});
  }
  return matches;
}

// cv::ORB keypoints and descriptors as a FeatureSet (octave, angle in radians).
inline FeatureSet toFeatureSet(const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& descriptors) {
  FeatureSet set(static_cast<int>(keypoints.size()));
  for (size_t i = 0; i < keypoints.size(); ++i) {
    Keypoint& k = set.keypoints[i];
    k.x = keypoints[i].pt.x;
    k.y = keypoints[i].pt.y;
    k.angle = keypoints[i].angle * static_cast<float>(CV_PI / 180.0);
    k.response = keypoints[i].response;
    k.octave = static_cast<int8_t>(keypoints[i].octave);
    std::memcpy(set.descriptors[i].data(), descriptors.ptr(static_cast<int>(i)), 32);
  }
  set.count = static_cast<int>(keypoints.size());
  return set;
}

// Matches whose keypoints agree with the true mapping from image a to image b within `tolerance` px.
inline int countCorrect(const FeatureSet& a, const FeatureSet& b, const std::vector<Match>& matches,
                        const std::function<bool(double, double, double&, double&)>& a_to_b, double tolerance = 3.0) {
  int correct = 0;
  for (const Match& m : matches) {
    double x, y;
    if (!a_to_b(a.keypoints[m.a].x, a.keypoints[m.a].y, x, y)) continue;
    const double dx = x - b.keypoints[m.b].x, dy = y - b.keypoints[m.b].y;
    correct += dx * dx + dy * dy <= tolerance * tolerance;
  }
  return correct;
}

}  // namespace mcslam::test
