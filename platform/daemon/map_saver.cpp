#include "daemon/map_saver.hpp"

#include <spdlog/spdlog.h>

namespace mcslam::platform {

MapSaver::MapSaver(std::string path, double interval_s, std::size_t max_bytes)
    : target_(path), interval_ns_(static_cast<int64_t>(interval_s * 1e9)) {
  buffer_.reserve(max_bytes);
}

MapSaver::~MapSaver() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void MapSaver::start() {
  thread_ = std::thread([this] { loop(); });
}

void MapSaver::afterFrame(const FrameProcessor& processor, int64_t now_ns) {
  if (interval_ns_ <= 0) return;
  if (last_ns_ == 0) last_ns_ = now_ns;  // the first save one interval after the first frame
  if (now_ns - last_ns_ < interval_ns_ || busy_.load(std::memory_order_acquire)) return;
  last_ns_ = now_ns;
  if (!processor.writeMap(buffer_)) return;
  busy_.store(true, std::memory_order_release);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = true;
  }
  wake_.notify_one();
}

void MapSaver::saveNow(const FrameProcessor& processor) {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();  // finishes a save under way
  if (!processor.writeMap(buffer_)) return;
  if (write()) spdlog::info("map saved to {} ({} bytes)", target_.path, buffer_.size());
}

void MapSaver::loop() {
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return pending_ || stop_; });
      if (!pending_) return;
      pending_ = false;
    }
    write();
    meter_.note(true);
    busy_.store(false, std::memory_order_release);
  }
}

bool MapSaver::write() {
  std::string error;
  if (writeFileSynced(target_, buffer_, &error)) {
    saves_.fetch_add(1, std::memory_order_relaxed);
    return true;
  }
  failures_.fetch_add(1, std::memory_order_relaxed);
  spdlog::error("map.save: {} (the previous map file is kept; the next save tries again)", error);
  return false;
}

}  // namespace mcslam::platform
