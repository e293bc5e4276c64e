#include "map_summary.hpp"

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <tuple>

#include "mcslam/core/json_writer.hpp"
#include "mcslam/eval/error_stats.hpp"
#include "mcslam/recognition/bow_vector.hpp"

namespace mcslam::map_tool {

namespace {

Vec3 worldPoint(const PlaceKeyframe& k, const PlacePoint& p) { return k.T_w_k * p.p_k.cast<double>(); }

Extent robustExtent(std::vector<Vec3> points, double share) {
  Extent e;
  if (points.empty()) return e;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> v;
    v.reserve(points.size());
    for (const Vec3& p : points) v.push_back(p[axis]);
    std::tie(e.lo[axis], e.hi[axis]) = centralRange(std::move(v), share);
  }
  return e;
}

std::vector<SegmentSummary> segmentsOf(const MapContents& c) {
  const PlaceMap& map = *c.map;
  std::vector<SegmentSummary> segments(static_cast<std::size_t>(map.segments()));
  for (int32_t s = 0; s < map.segments(); ++s) {
    SegmentSummary& out = segments[static_cast<std::size_t>(s)];
    out.segment = s;
    out.placed = map.placed(s);
    int32_t root = s;  // union-find parents in the file hang below their segment: this ends
    while (c.segment_roots[static_cast<std::size_t>(root)] != root)
      root = c.segment_roots[static_cast<std::size_t>(root)];
    out.joined_to = root;
  }
  for (int slot = 0; slot < map.size(); ++slot) {
    const PlaceKeyframe& k = map.keyframe(slot);
    SegmentSummary& out = segments[static_cast<std::size_t>(k.segment)];
    out.t_first = out.keyframes == 0 ? k.t : std::min(out.t_first, k.t);
    out.t_last = out.keyframes == 0 ? k.t : std::max(out.t_last, k.t);
    ++out.keyframes;
    if (k.next >= 0) out.path_m += (map.keyframe(k.next).T_w_k.t - k.T_w_k.t).norm();
  }
  return segments;
}

}  // namespace

MapSummary summarize(const MapContents& c, const std::string& file) {
  const PlaceMap& map = *c.map;
  MapSummary s;
  s.file = file;
  s.file_bytes = c.file_bytes;
  s.header = c.header;
  s.keyframes = map.size();
  s.loops = static_cast<int>(c.loops.size());
  s.points_per_camera.assign(c.header.cameras.size(), 0);
  std::vector<int64_t> landmark_ids;
  std::vector<Vec3> keyframe_positions, points;
  for (int slot = 0; slot < map.size(); ++slot) {
    const PlaceKeyframe& k = map.keyframe(slot);
    keyframe_positions.push_back(k.T_w_k.t);
    for (const PlacePoint& p : map.points(slot)) {
      ++s.points_per_camera[static_cast<std::size_t>(p.cam)];
      landmark_ids.push_back(p.landmark_id);
      points.push_back(worldPoint(k, p));
    }
    s.words += c.words[static_cast<std::size_t>(slot)];
    s.most_words = std::max(s.most_words, c.words[static_cast<std::size_t>(slot)]);
  }
  s.points = landmark_ids.size();
  std::sort(landmark_ids.begin(), landmark_ids.end());
  s.landmarks = static_cast<uint64_t>(std::unique(landmark_ids.begin(), landmark_ids.end()) - landmark_ids.begin());
  s.segments = segmentsOf(c);
  for (const SegmentSummary& seg : s.segments) {
    s.path_m += seg.path_m;
    s.placed_segments += seg.placed ? 1 : 0;
    s.loop_groups += seg.joined_to == seg.segment ? 1 : 0;
  }
  s.keyframe_extent = robustExtent(keyframe_positions, 0);
  s.point_extent = robustExtent(points, 0.02);
  s.memory_bytes = static_cast<std::size_t>(s.keyframes) * sizeof(PlaceKeyframe) +
                   static_cast<std::size_t>(s.keyframes) * c.header.max_points_per_keyframe * sizeof(PlacePoint) +
                   s.words * sizeof(BowEntry);
  return s;
}

namespace {

std::string camerasText(const MapFileHeader& h) {
  std::string out;
  for (std::size_t i = 0; i < h.cameras.size(); ++i)
    out += (i ? ", " : "") + std::to_string(h.cameras[i].width) + "x" + std::to_string(h.cameras[i].height);
  return out;
}

std::string extentText(const Extent& e) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), "x %.2f .. %.2f, y %.2f .. %.2f, z %.2f .. %.2f m", e.lo.x(), e.hi.x(), e.lo.y(),
                e.hi.y(), e.lo.z(), e.hi.z());
  return buf;
}

double seconds(Timestamp t) { return static_cast<double>(t) * 1e-9; }

double mib(std::size_t bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); }

}  // namespace

void printSummary(const MapSummary& s) {
  const MapFileHeader& h = s.header;
  std::printf("%s: mcslam map, version %u, %.2f MiB\n", s.file.c_str(), h.version, mib(s.file_bytes));
  std::printf("  cameras     %zu (%s)\n", h.cameras.size(), camerasText(h).c_str());
  std::printf("  vocabulary  %u words, fingerprint %u\n", h.vocabulary_words, h.vocabulary_fingerprint);
  std::printf("  keyframes   %d, %.1f m of path\n", s.keyframes, s.path_m);
  std::printf("  points      %llu (%llu landmarks), by camera:", static_cast<unsigned long long>(s.points),
              static_cast<unsigned long long>(s.landmarks));
  for (uint64_t n : s.points_per_camera) std::printf(" %llu", static_cast<unsigned long long>(n));
  std::printf("\n");
  std::printf("  segments    %zu, %d placed in the world frame; %d loop%s, joining them into %d group%s\n",
              s.segments.size(), s.placed_segments, s.loops, s.loops == 1 ? "" : "s", s.loop_groups,
              s.loop_groups == 1 ? "" : "s");
  for (const SegmentSummary& seg : s.segments) {
    std::printf("    %3d: %5d keyframes, %8.1f m, t %.3f .. %.3f s%s", seg.segment, seg.keyframes, seg.path_m,
                seconds(seg.t_first), seconds(seg.t_last), seg.placed ? "" : ", not placed");
    if (seg.joined_to != seg.segment) std::printf(", joined to %d", seg.joined_to);
    std::printf("\n");
  }
  std::printf("  extent      keyframes %s\n", extentText(s.keyframe_extent).c_str());
  std::printf("              points    %s (outermost 2%% left out)\n", extentText(s.point_extent).c_str());
  std::printf(
      "  memory      %.2f MiB to hold it; it needs places.max_keyframes >= %d, max_points_per_keyframe >= %u,"
      " max_words_per_keyframe >= %u, max_loops >= %d\n",
      mib(s.memory_bytes), s.keyframes, h.max_points_per_keyframe, s.most_words, s.loops);
}

void printSummaryJson(const MapSummary& s) {
  JsonWriter j(std::cout);
  j.beginObject();
  j.key("file").value(s.file);
  j.key("version").value(s.header.version);
  j.key("file_bytes").value(static_cast<unsigned long long>(s.file_bytes));
  j.key("cameras").beginArray();
  for (const MapFileHeader::Camera& c : s.header.cameras) {
    j.beginObject();
    j.key("width").value(c.width);
    j.key("height").value(c.height);
    j.endObject();
  }
  j.endArray();
  j.key("vocabulary_words").value(s.header.vocabulary_words);
  j.key("vocabulary_fingerprint").value(s.header.vocabulary_fingerprint);
  j.key("keyframes").value(s.keyframes);
  j.key("points").value(static_cast<unsigned long long>(s.points));
  j.key("landmarks").value(static_cast<unsigned long long>(s.landmarks));
  j.key("words").value(static_cast<unsigned long long>(s.words));
  j.key("path_m").value(s.path_m);
  j.key("loops").value(s.loops);
  j.key("placed_segments").value(s.placed_segments);
  j.key("loop_groups").value(s.loop_groups);
  j.key("segments").beginArray();
  for (const SegmentSummary& seg : s.segments) {
    j.beginObject();
    j.key("segment").value(seg.segment);
    j.key("keyframes").value(seg.keyframes);
    j.key("placed").value(seg.placed);
    j.key("joined_to").value(seg.joined_to);
    j.key("path_m").value(seg.path_m);
    j.key("t_first_s").value(seconds(seg.t_first));
    j.key("t_last_s").value(seconds(seg.t_last));
    j.endObject();
  }
  j.endArray();
  j.key("keyframe_extent").beginObject();
  j.key("lo").vector(s.keyframe_extent.lo, 3);
  j.key("hi").vector(s.keyframe_extent.hi, 3);
  j.endObject();
  j.key("point_extent").beginObject();
  j.key("lo").vector(s.point_extent.lo, 3);
  j.key("hi").vector(s.point_extent.hi, 3);
  j.endObject();
  j.key("memory_bytes").value(static_cast<unsigned long long>(s.memory_bytes));
  j.endObject();
  std::cout << "\n";
}

}  // namespace mcslam::map_tool
