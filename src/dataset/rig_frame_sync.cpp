#include "mcslam/dataset/rig_frame_sync.hpp"

#include <algorithm>
#include <tuple>

namespace mcslam {

std::vector<RigFrameEntry> assembleRigFrames(const std::vector<std::vector<CameraImage>>& per_camera,
                                             Timestamp tolerance_ns) {
  struct Event {
    Timestamp t;
    int cam;
    std::size_t index;
  };
  std::vector<Event> events;
  for (int c = 0; c < static_cast<int>(per_camera.size()); ++c) {
    for (std::size_t i = 0; i < per_camera[c].size(); ++i) events.push_back({per_camera[c][i].t, c, i});
  }
  std::sort(events.begin(), events.end(),
            [](const Event& a, const Event& b) { return std::tie(a.t, a.cam) < std::tie(b.t, b.cam); });

  const std::size_t cameras = per_camera.size();
  std::vector<RigFrameEntry> frames;
  bool open = false;
  for (const Event& e : events) {
    if (open) {
      RigFrameEntry& f = frames.back();
      if (e.t - f.t > tolerance_ns || !f.image_paths[e.cam].empty()) open = false;
    }
    if (!open) {
      RigFrameEntry f;
      f.t = e.t;
      f.image_paths.assign(cameras, std::string());
      f.camera_stamps.assign(cameras, 0);
      frames.push_back(std::move(f));
      open = true;
    }
    frames.back().image_paths[e.cam] = per_camera[e.cam][e.index].path;
    frames.back().camera_stamps[e.cam] = e.t;
  }
  return frames;
}

Timestamp automaticSyncTolerance(const std::vector<std::vector<CameraImage>>& per_camera, Timestamp max_ns) {
  Timestamp shortest_period = -1;
  for (const auto& images : per_camera) {
    if (images.size() < 2) continue;
    std::vector<Timestamp> periods;
    for (std::size_t i = 1; i < images.size(); ++i) periods.push_back(images[i].t - images[i - 1].t);
    std::nth_element(periods.begin(), periods.begin() + periods.size() / 2, periods.end());
    const Timestamp median = periods[periods.size() / 2];
    if (shortest_period < 0 || median < shortest_period) shortest_period = median;
  }
  if (shortest_period <= 0) return std::min<Timestamp>(max_ns, 5000000);
  return std::min(max_ns, shortest_period / 3);
}

}  // namespace mcslam
