#include "sources/dataset_source.hpp"

#include <cstring>

#include <spdlog/spdlog.h>

#include "mcslam/core/error.hpp"
#include "realtime/scheduling.hpp"
#include "sources/replay_pacing.hpp"

namespace mcslam::platform {

namespace {
DatasetOptions optionsOf(const DatasetSourceConfig& c, const SourceContext& context) {
  DatasetOptions o;
  o.calibration_override = context.calibration;
  o.cameras = c.cameras;
  return o;
}

void copyImage(const Image& from, Image& to) {
  to.resize(from.width(), from.height());
  std::memcpy(to.data(), from.data(), static_cast<std::size_t>(from.width()) * from.height());
}
}  // namespace

DatasetSource::DatasetSource(const DatasetSourceConfig& config, const SourceContext& context)
    : cfg_(config),
      software_(context.trigger.mode == TriggerMode::Software),
      dataset_(Dataset::open(config.path, optionsOf(config, context))) {
  const std::string key = context.file + ": source.dataset";
  if (dataset_.size() == 0) throw InputError(key + ".path: '" + cfg_.path + "' has no frames");
  if (dataset_.rig().size() != context.rig.size())
    throw InputError(key + ".path: the dataset has " + std::to_string(dataset_.rig().size()) +
                     " cameras but the configuration's rig has " + std::to_string(context.rig.size()));
  for (const auto& w : dataset_.warnings()) spdlog::warn("dataset: {}", w);
  const auto& frames = dataset_.frames();
  const int64_t span = frames.back().t - frames.front().t;
  const int64_t period = frames.size() > 1 ? span / static_cast<int64_t>(frames.size() - 1) : 50000000;
  loop_period_ns_ = span + period;

  const std::size_t n = cfg_.preload ? dataset_.size() : 1;
  if (cfg_.preload && dataset_.size() > cfg_.max_preload_frames)
    throw InputError(key + ".max_preload_frames: the dataset has " + std::to_string(dataset_.size()) +
                     " frames, more than the " + std::to_string(cfg_.max_preload_frames) + " allowed to preload");
  images_.resize(n);
  present_.resize(n);
  if (cfg_.preload) {
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<bool> present;
      std::string error;
      dataset_.loadImages(i, images_[i], present, &error);
      if (!error.empty()) spdlog::warn("dataset frame {}: {}", i, error);
      present_[i] = present;
    }
    spdlog::info("dataset: preloaded {} rig frames", n);
  }
}

bool DatasetSource::fire(uint64_t) {
  triggered_.fetch_add(1, std::memory_order_release);
  trigger_bell_.ring();
  return true;
}

void DatasetSource::start(const SourceLinks& links) {
  links_ = links;
  rings_ = links.rings;
  stop_ = false;
  thread_ = std::thread([this] { run(); });
}

void DatasetSource::stop() {
  stop_ = true;
  trigger_bell_.ring();
  if (thread_.joinable()) thread_.join();
}

// Waits until frame i is due. False when stopping.
bool DatasetSource::waitTurn(std::size_t i, uint64_t loop, int64_t start_mono, uint64_t& trigger_index) {
  if (software_) return waitForNewestTrigger(stop_, triggered_, trigger_bell_, trigger_index, trigger_index);
  if (cfg_.rate == ReplayRate::Fastest)
    return links_.pressure->waitForRoom(emitted_.load(std::memory_order_relaxed), stop_);
  const auto& frames = dataset_.frames();
  const int64_t offset = static_cast<int64_t>(loop) * loop_period_ns_ + (frames[i].t - frames.front().t);
  const int64_t due = start_mono + static_cast<int64_t>(static_cast<double>(offset) / cfg_.speed);
  while (!stop_.load(std::memory_order_relaxed)) {
    const int64_t now = monotonicNowNs();
    if (now >= due) return true;
    sleepUntil(std::min(due, now + 100000000));  // wake at least every 100 ms to notice stop()
  }
  return false;
}

void DatasetSource::emit(std::size_t i, uint64_t loop, uint64_t trigger_index, int64_t trigger_mono) {
  std::vector<Image>& images = images_[cfg_.preload ? i : 0];
  std::vector<bool>& present = present_[cfg_.preload ? i : 0];
  if (!cfg_.preload) {
    // Decoded straight into the cameras' write slots (their buffers lent to `images` for the call): no
    // staging copy of a whole rig frame is kept, and no copy is made below.
    images.resize(static_cast<std::size_t>(rings_->cameras()));
    for (int c = 0; c < rings_->cameras(); ++c) std::swap(images[c], rings_->slot(c).image);
    load_error_.clear();
    dataset_.loadImages(i, images, present, &load_error_);
    for (int c = 0; c < rings_->cameras(); ++c) std::swap(images[c], rings_->slot(c).image);
    if (!load_error_.empty()) {
      counters_.bad_frames.fetch_add(1, std::memory_order_relaxed);
      spdlog::warn("dataset frame {}: {}", i, load_error_);
    }
  }
  const RigFrameEntry& entry = dataset_.frames()[i];
  const int64_t offset = static_cast<int64_t>(loop) * loop_period_ns_;
  int delivered = 0;
  for (int c = 0; c < rings_->cameras(); ++c) {
    if (c >= static_cast<int>(present.size()) || !present[c]) continue;
    const auto [w, h] = rings_->size(c);
    CameraFrame& slot = rings_->slot(c);
    const Image& image = cfg_.preload ? images[c] : slot.image;
    if (image.width() != w || image.height() != h) {
      if (counters_.bad_frames.fetch_add(1, std::memory_order_relaxed) < 10)
        spdlog::warn("dataset frame {} cam{}: image is {}x{}, the calibration says {}x{}; skipped", i, c, image.width(),
                     image.height(), w, h);
      if (!cfg_.preload) slot.image.resize(w, h);  // the slot keeps its size (no allocation when it grew)
      continue;
    }
    if (cfg_.preload) copyImage(images[c], slot.image);
    const Timestamp stamp = entry.camera_stamps.size() > static_cast<std::size_t>(c) && entry.camera_stamps[c] != 0
                                ? entry.camera_stamps[c]
                                : entry.t;
    slot.capture_ns = stamp + offset;
    slot.trigger_index = trigger_index;
    slot.trigger_mono_ns = trigger_mono;
    rings_->publish(c);
    ++delivered;
    counters_.frames.fetch_add(1, std::memory_order_relaxed);
  }
  if (delivered > 0) emitted_.fetch_add(1, std::memory_order_release);  // a frame without images never arrives
}

void DatasetSource::run() {
  nameThisThread("mcslam-replay");
  const int64_t start_mono = monotonicNowNs();
  uint64_t trigger_index = 0;  // software mode: the next trigger to serve
  uint64_t frame_number = 0;   // free-running: frames emitted so far
  for (uint64_t loop = 0; !stop_.load(std::memory_order_relaxed); ++loop) {
    for (std::size_t i = 0; i < dataset_.size(); ++i) {
      if (!waitTurn(i, loop, start_mono, trigger_index)) return;
      const uint64_t index = software_ ? trigger_index : frame_number;
      const int64_t trigger_mono = software_ ? links_.triggers->lookup(index) : monotonicNowNs();
      emit(i, loop, index, trigger_mono ? trigger_mono : monotonicNowNs());
      ++frame_number;
      if (software_) ++trigger_index;
      meter_.note(links_.warm_up->warm());
    }
    if (cfg_.at_end != AtEnd::Loop) break;
  }
  finished_.store(true, std::memory_order_release);
  spdlog::info("dataset: replay finished after {} frames", emitted());
}

}  // namespace mcslam::platform
