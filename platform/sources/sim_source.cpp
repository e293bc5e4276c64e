#include "sources/sim_source.hpp"

#include <cstdio>

#include <spdlog/spdlog.h>

#include "mcslam/core/error.hpp"
#include "realtime/scheduling.hpp"
#include "sources/replay_pacing.hpp"

namespace mcslam::platform {

namespace {
sim::SimulationConfig simulationConfig(const SimSourceConfig& s) {
  sim::SimulationConfig c;
  c.rig = s.rig;
  c.world = s.world;
  c.trajectory = s.trajectory;
  c.rate_hz = s.rate_hz;
  c.frames = s.frames;
  c.seed = s.seed;
  c.render.threads = s.render_threads;
  c.render.anti_aliasing = s.anti_aliasing;
  return c;
}
}  // namespace

SimSource::SimSource(const SimSourceConfig& config, const SourceContext& context)
    : cfg_(config), software_(context.trigger.mode == TriggerMode::Software) {
  try {
    sim_ = std::make_unique<sim::Simulation>(simulationConfig(cfg_));
  } catch (const InputError& e) {
    throw InputError(context.file + ": source.sim: " + e.what());
  }
  for (int c = 0; c < context.rig.size(); ++c) sim_cameras_.push_back(cfg_.cameras.empty() ? c : cfg_.cameras[c]);
  frames_ = static_cast<uint64_t>(sim_->frameCount());
  loop_period_ns_ = sim_->frameStamp(sim_->frameCount()) - sim_->frameStamp(0);
  spdlog::info("sim: {} world, {}, {} frames at {} Hz, {} cameras", cfg_.world, sim_->trajectory().description(),
               frames_, cfg_.rate_hz, sim_cameras_.size());
}

bool SimSource::fire(uint64_t) {
  triggered_.fetch_add(1, std::memory_order_release);
  trigger_bell_.ring();
  return true;
}

void SimSource::start(const SourceLinks& links) {
  links_ = links;
  rings_ = links.rings;
  stop_ = false;
  thread_ = std::thread([this] { run(); });
}

void SimSource::stop() {
  stop_ = true;
  trigger_bell_.ring();
  if (thread_.joinable()) thread_.join();
}

void SimSource::health(char* out, std::size_t size) const {
  const uint64_t skipped = skipped_.load(std::memory_order_relaxed);
  if (skipped == 0)
    std::snprintf(out, size, "ok");
  else
    std::snprintf(out, size, "ok, %llu sim frames skipped (rendering behind rate_hz)",
                  static_cast<unsigned long long>(skipped));
}

bool SimSource::waitTurn(uint64_t next, int64_t start_mono, uint64_t& frame) {
  // The newest trigger; the ones missed while rendering are skipped.
  if (software_) return waitForNewestTrigger(stop_, triggered_, trigger_bell_, next, frame);
  if (cfg_.pace == SimPace::Fastest) {
    frame = next;
    return links_.pressure->waitForRoom(emitted_.load(std::memory_order_relaxed), stop_);
  }
  const double period_ns = 1e9 / cfg_.rate_hz;
  while (!stop_.load(std::memory_order_relaxed)) {
    const int64_t now = monotonicNowNs();
    const int64_t due = start_mono + static_cast<int64_t>(static_cast<double>(next) * period_ns);
    if (now >= due) {
      frame = std::max(next, static_cast<uint64_t>(static_cast<double>(now - start_mono) / period_ns));
      return true;
    }
    sleepUntil(std::min(due, now + 100000000));  // wake at least every 100 ms to notice stop()
  }
  return false;
}

void SimSource::emit(uint64_t frame, int64_t trigger_mono) {
  const int index = static_cast<int>(frame % frames_);
  const int64_t stamp = sim_->frameStamp(index) + static_cast<int64_t>(frame / frames_) * loop_period_ns_;
  // Render every camera first, publish them together: the assembler sees the whole rig frame at once.
  for (int c = 0; c < rings_->cameras(); ++c) {
    if (stop_.load(std::memory_order_relaxed)) return;  // a stop does not wait for the whole rig frame
    CameraFrame& slot = rings_->slot(c);
    sim_->render(index, sim_cameras_[c], slot.image);
    slot.capture_ns = stamp;
    slot.trigger_index = frame;
    slot.trigger_mono_ns = trigger_mono;
  }
  for (int c = 0; c < rings_->cameras(); ++c) {
    rings_->publish(c);
    counters_.frames.fetch_add(1, std::memory_order_relaxed);
  }
  emitted_.fetch_add(1, std::memory_order_release);
}

void SimSource::run() {
  nameThisThread("mcslam-sim");
  const int64_t start_mono = monotonicNowNs();
  const bool bounded = cfg_.at_end != AtEnd::Loop;
  uint64_t next = 0;
  while (!stop_.load(std::memory_order_relaxed)) {
    uint64_t frame = 0;
    if (!waitTurn(next, start_mono, frame)) return;
    if (bounded && frame >= frames_) break;
    if (frame > next) skipped_.fetch_add(frame - next, std::memory_order_relaxed);
    const int64_t trigger_mono = software_ ? links_.triggers->lookup(frame) : monotonicNowNs();
    emit(frame, trigger_mono ? trigger_mono : monotonicNowNs());
    next = frame + 1;
    meter_.note(links_.warm_up->warm());
    if (bounded && next >= frames_) break;
  }
  finished_.store(true, std::memory_order_release);
  spdlog::info("sim: finished after {} frames ({} skipped)", emitted(), skipped());
}

}  // namespace mcslam::platform
