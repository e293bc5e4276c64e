#include "mcslam/places/place_map.hpp"

#include <algorithm>

namespace mcslam {

PlaceMap::PlaceMap(int max_keyframes, int max_points_per_keyframe)
    : keyframes_(static_cast<std::size_t>(max_keyframes)),
      points_(static_cast<std::size_t>(max_keyframes) * static_cast<std::size_t>(max_points_per_keyframe)),
      free_(static_cast<std::size_t>(max_keyframes)),
      max_points_(max_points_per_keyframe),
      newest_of_segment_(kMaxSegments, -1),
      segment_T_w_o_(kMaxSegments) {
  clear();
}

void PlaceMap::clear() {
  for (PlaceKeyframe& k : keyframes_) k = PlaceKeyframe{};
  free_count_ = capacity();
  for (int i = 0; i < free_count_; ++i) free_[static_cast<std::size_t>(i)] = free_count_ - 1 - i;  // 0 first
  live_ = 0;
  newest_ = -1;
  std::fill(newest_of_segment_.begin(), newest_of_segment_.end(), -1);
  segment_count_ = 0;
}

int PlaceMap::createKeyframe(int32_t segment, Timestamp t, uint64_t frame_index, const SE3& T_w_k, const SE3& T_o_k) {
  if (free_count_ == 0) return -1;
  const int slot = free_[static_cast<std::size_t>(--free_count_)];
  PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(slot)];
  k = PlaceKeyframe{};
  k.alive = true;
  k.id = next_id_++;
  k.segment = segment;
  k.t = t;
  k.frame_index = frame_index;
  k.T_w_k = T_w_k;
  k.T_o_k = T_o_k;
  int32_t& newest = newest_of_segment_[static_cast<std::size_t>(segment)];
  k.previous = newest;
  if (newest >= 0) keyframes_[static_cast<std::size_t>(newest)].next = slot;
  newest = slot;
  newest_ = slot;
  ++live_;
  return slot;
}

bool PlaceMap::addPoint(int slot, const PlacePoint& point) {
  PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(slot)];
  if (k.point_count == max_points_) return false;
  points_[static_cast<std::size_t>(slot) * static_cast<std::size_t>(max_points_) +
          static_cast<std::size_t>(k.point_count++)] = point;
  return true;
}

void PlaceMap::finishKeyframe(int slot) {
  const auto first = points_.begin() + static_cast<std::ptrdiff_t>(slot) * max_points_;
  std::sort(first, first + keyframes_[static_cast<std::size_t>(slot)].point_count,
            [](const PlacePoint& a, const PlacePoint& b) { return a.node < b.node; });
}

std::span<const PlacePoint> PlaceMap::pointsOfNode(int slot, int32_t node) const {
  const std::span<const PlacePoint> all = points(slot);
  const auto lo =
      std::lower_bound(all.begin(), all.end(), node, [](const PlacePoint& p, int32_t n) { return p.node < n; });
  auto hi = lo;
  while (hi != all.end() && hi->node == node) ++hi;
  return {all.data() + (lo - all.begin()), static_cast<std::size_t>(hi - lo)};
}

void PlaceMap::eraseKeyframe(int slot) {
  PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(slot)];
  if (!k.alive) return;
  if (k.previous >= 0) keyframes_[static_cast<std::size_t>(k.previous)].next = k.next;
  if (k.next >= 0) keyframes_[static_cast<std::size_t>(k.next)].previous = k.previous;
  int32_t& newest = newest_of_segment_[static_cast<std::size_t>(k.segment)];
  if (newest == slot) newest = k.previous;
  if (newest_ == slot) newest_ = k.previous;
  k = PlaceKeyframe{};
  free_[static_cast<std::size_t>(free_count_++)] = slot;
  --live_;
}

void PlaceMap::rescaleSegment(int32_t segment, double s, const Vec3& center) {
  const SE3& T_w_o = segment_T_w_o_[static_cast<std::size_t>(segment)];
  for (int slot = 0; slot < capacity(); ++slot) {
    PlaceKeyframe& k = keyframes_[static_cast<std::size_t>(slot)];
    if (!k.alive || k.segment != segment) continue;
    k.T_o_k.t = center + s * (k.T_o_k.t - center);
    k.T_w_k = T_w_o * k.T_o_k;
    PlacePoint* points = points_.data() + static_cast<std::size_t>(slot) * static_cast<std::size_t>(max_points_);
    for (int i = 0; i < k.point_count; ++i) points[i].p_k *= static_cast<float>(s);
  }
}

int32_t PlaceMap::createSegment(const SE3& T_w_o) {
  if (segment_count_ == kMaxSegments) return -1;
  segment_T_w_o_[static_cast<std::size_t>(segment_count_)] = T_w_o;
  return segment_count_++;
}

}  // namespace mcslam
