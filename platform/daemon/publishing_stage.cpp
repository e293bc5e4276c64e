#include "daemon/publishing_stage.hpp"

#include <time.h>

#include <cstdlib>
#include <filesystem>

#include <spdlog/spdlog.h>

#include "realtime/scheduling.hpp"

namespace mcslam::platform {

namespace {
std::vector<UdpDestination> destinationsOf(const DaemonConfig& c) {
  std::vector<UdpDestination> d;
  for (const auto& text : c.publish.udp_destinations)
    d.push_back(resolveUdpDestination(text, c.file + ": publish.udp.destinations"));
  return d;
}

int64_t realtimeNowNs() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}
}  // namespace

std::string outputPathFor(const DaemonConfig& c, const std::string& name) {
  std::string dir = c.output.directory;
  if (dir.empty()) {
    const char* state = std::getenv("STATE_DIRECTORY");  // systemd: StateDirectory=, maybe colon-separated
    if (state && *state) dir = std::string(state).substr(0, std::string(state).find(':'));
  }
  const std::filesystem::path base = dir.empty() ? std::filesystem::current_path() : std::filesystem::path(dir);
  return (base / name).string();
}

PublishingStage::PublishingStage(const DaemonConfig& config, PoseRing& in, const WarmUp& warm_up)
    : in_(in), warm_up_(warm_up), udp_(destinationsOf(config)), shm_config_(config.publish) {
  if (config.publish.shm_enabled)
    shm_ = std::make_unique<PoseShmWriter>(config.publish.shm_name, config.publish.shm_ring_length,
                                           config.publish.shm_mode);
  trajectory_ = std::make_unique<TrajectoryWriter>(trajectoryPathFor(config));
}

void PublishingStage::start() {
  stop_ = false;
  thread_ = std::thread([this] { run(); });
}

void PublishingStage::stop() {
  if (!thread_.joinable()) return;
  stop_ = true;
  in_.wake();
  thread_.join();
  trajectory_->close();  // fsync
  if (shm_) shm_->markStopped();
}

void PublishingStage::publish(const PoseSlot& slot) {
  const PoseEstimate& e = slot.estimate;
  pose::PoseRecord r;
  r.sequence = ++sequence_;
  r.frame_sequence = e.sequence;
  r.capture_time_ns = e.t;
  r.publish_time_ns = realtimeNowNs();
  const Eigen::Quaterniond q = e.T_w_b.quaternion();
  for (int i = 0; i < 3; ++i) r.position[i] = e.T_w_b.t[i];
  r.orientation[0] = q.x();
  r.orientation[1] = q.y();
  r.orientation[2] = q.z();
  r.orientation[3] = q.w();
  r.tracking = static_cast<pose::Tracking>(e.state);
  r.flags = static_cast<uint8_t>((e.valid ? pose::kFlagValid : 0) | (e.is_keyframe ? pose::kFlagKeyframe : 0) |
                                 (e.metric ? 0 : pose::kFlagUnscaled) | (e.unanchored ? pose::kFlagUnanchored : 0) |
                                 (e.roughly_metric ? pose::kFlagRoughlyMetric : 0));
  r.quality = e.quality;
  r.world_revision = e.world_revision;
  if (shm_) shm_->publish(r);
  if (shm_ && shm_->lost()) replaceLostShm();
  udp_.send(r);
  if (slot.trigger_mono_ns > 0) latency_.record(monotonicNowNs() - slot.trigger_mono_ns);
  if (r.valid()) trajectory_->append(r);
  published_.store(r.sequence, std::memory_order_release);
}

// Someone truncated the segment (the SIGBUS guard kept this thread alive): a new one, so that readers can
// reattach (their check() says Truncated, then Replaced). Rare, so it may allocate and log.
void PublishingStage::replaceLostShm() {
  const std::string name = shm_->name();
  shm_->markStopped();
  shm_.reset();
  ++shm_replacements_;
  try {
    shm_ = std::make_unique<PoseShmWriter>(name, shm_config_.shm_ring_length, shm_config_.shm_mode);
    spdlog::error("publish.shm: '{}' was truncated by another process; published in a new segment from now on", name);
  } catch (const std::exception& e) {
    spdlog::error(
        "publish.shm: '{}' was truncated by another process and cannot be made anew ({}); no more poses "
        "in shared memory",
        name, e.what());
  }
}

void PublishingStage::run() {
  nameThisThread("mcslam-publish");
  while (PoseSlot* s = in_.next(stop_)) {
    publish(*s);
    in_.release();
    meter_.note(warm_up_.warm());
  }
}

}  // namespace mcslam::platform
