// mcslamd machinery (docs/benchmarks/platform.md):
//  - ShmPublishToRead: latency from PoseShmWriter::publish to a polling reader in another thread seeing
//    the record whole (seqlock), p50/p99; anchor: the same record over a loopback UDP socket.
//  - TriggerToPose5Cam20Hz: the daemon in-process, 5 cameras, software trigger at 20 Hz driving a
//    preloaded replay; latency from the trigger to the pose being published (shm + UDP + trajectory),
//    p50/p99 and allocations per frame after warm-up; anchor: the pipeline's process() alone on the
//    same frames (the lower bound the machinery adds to), with the stages of its p99 frame (which stage limits
//    the tail). Input: a rendered simulator sequence, so the real pipeline initializes and tracks.
#include <benchmark/benchmark.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <random>
#include <thread>
#include <utility>
#include <vector>

#include "../platform/sim_dataset_fixture.hpp"
#include "daemon/daemon.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/pipeline/pipeline_factory.hpp"
#include "mcslam/pose_shm.hpp"
#include "shm/pose_shm_writer.hpp"
#include "test_support.hpp"

using namespace mcslam;

namespace {
constexpr int kBenchFrames = 200;

void reportPercentiles(benchmark::State& state, std::vector<int64_t>& ns) {
  if (ns.empty()) return;
  std::sort(ns.begin(), ns.end());
  state.counters["p50_us"] = static_cast<double>(ns[ns.size() / 2]) * 1e-3;
  state.counters["p99_us"] = static_cast<double>(ns[ns.size() * 99 / 100]) * 1e-3;
  state.counters["samples"] = static_cast<double>(ns.size());
}

void sleepNs(int64_t ns) { std::this_thread::sleep_for(std::chrono::nanoseconds(ns)); }

constexpr int kSamples = 20000;
constexpr int64_t kPublishPeriodNs = 50000;  // 20 kHz: faster than any camera, slow enough to not pile up

void BM_ShmPublishToRead_mcslam(benchmark::State& state) {
  const std::string name = "/mcslam-bench-" + std::to_string(getpid());
  platform::PoseShmWriter writer(name, 256, 0600);
  for (auto _ : state) {
    std::vector<int64_t> latency;
    latency.reserve(kSamples);
    std::atomic<bool> reader_ready{false};
    std::thread reader([&] {
      pose::PoseShmReader r;
      r.open(name);
      uint64_t seen = r.published();
      reader_ready = true;
      while (static_cast<int>(latency.size()) < kSamples) {
        const uint64_t p = r.published();  // poll: that is how a shared-memory consumer reads
        if (p == seen) continue;
        pose::PoseRecord rec;
        if (r.readLatest(rec) != pose::ReadStatus::Ok) continue;
        latency.push_back(monotonicNowNs() - rec.publish_time_ns);
        seen = p;
      }
    });
    while (!reader_ready) std::this_thread::yield();
    pose::PoseRecord rec;
    uint64_t seq = 0;
    while (reader.joinable() && static_cast<int>(latency.size()) < kSamples) {
      rec.sequence = ++seq;
      rec.publish_time_ns = monotonicNowNs();  // the benchmark's own stamp (the daemon uses CLOCK_REALTIME)
      writer.publish(rec);
      sleepNs(kPublishPeriodNs);
      if (seq > 50u * kSamples) break;  // bounded
    }
    reader.join();
    reportPercentiles(state, latency);
  }
}

void BM_ShmPublishToRead_udp_loopback(benchmark::State& state) {
  const int rx = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(rx, reinterpret_cast<sockaddr*>(&a), sizeof(a));
  socklen_t len = sizeof(a);
  ::getsockname(rx, reinterpret_cast<sockaddr*>(&a), &len);
  timeval tv{1, 0};
  ::setsockopt(rx, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  const int tx = ::socket(AF_INET, SOCK_DGRAM, 0);
  for (auto _ : state) {
    std::vector<int64_t> latency;
    latency.reserve(kSamples);
    std::thread reader([&] {
      uint8_t buf[256];
      while (static_cast<int>(latency.size()) < kSamples) {
        if (::recv(rx, buf, sizeof(buf), 0) <= 0) break;
        pose::PoseRecord rec;
        if (pose::decodePacket(buf, pose::kPacketSize, rec) == pose::DecodeStatus::Ok)
          latency.push_back(monotonicNowNs() - rec.publish_time_ns);
      }
    });
    pose::PoseRecord rec;
    uint8_t bytes[pose::kPacketSize];
    for (int i = 0; i < kSamples; ++i) {
      rec.sequence = static_cast<uint64_t>(i) + 1;
      rec.publish_time_ns = monotonicNowNs();
      pose::encodePacket(rec, bytes);
      ::sendto(tx, bytes, sizeof(bytes), 0, reinterpret_cast<sockaddr*>(&a), sizeof(a));
      sleepNs(kPublishPeriodNs);
    }
    reader.join();
    reportPercentiles(state, latency);
  }
  ::close(rx);
  ::close(tx);
}

// The simulator's ISEC rig (5 front cameras, 720x540) driving through the indoor world at 20 Hz: 200
// frames, so the real pipeline tracks all the way (no loop back to the start). Cached under the build tree.
std::string benchDataset() { return test::cachedSimDataset(kBenchFrames, 20.0); }

void BM_TriggerToPose5Cam20Hz_mcslam(benchmark::State& state) {
  test::TempDir dir("bench-daemon");
  const std::string data = benchDataset();
  const int frames = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const platform::DaemonConfig c = platform::parseDaemonConfig(
        "source:\n  type: dataset\n  dataset:\n    path: " + data +
            "\n    at_end: idle\n    preload: true\ntrigger:\n  mode: software\n  rate_hz: 20\n"
            "warmup_frames: 20\npublish:\n  shm:\n    name: /mcslam-bench-daemon-" +
            std::to_string(getpid()) +
            "\n  udp:\n    destinations: [\"127.0.0.1:9\"]\noutput:\n  directory: " + dir.path().string() + "\n",
        dir.file("bench.yaml"));
    platform::Daemon d(c, createPipeline(c.slam, c.file, c.rig));
    d.start();
    // One trigger per dataset frame; the frames the pipeline could not take in time are dropped.
    while (d.stats().triggers < static_cast<uint64_t>(frames) || !d.drained())
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    d.stop();
    const platform::DaemonStats s = d.stats();
    state.counters["p50_us"] = static_cast<double>(s.latency_p50_ns) * 1e-3;
    state.counters["p99_us"] = static_cast<double>(s.latency_p99_ns) * 1e-3;
    state.counters["frames"] = static_cast<double>(s.published);
    state.counters["dropped"] = static_cast<double>(s.rig_drops + s.camera_drops);
    state.counters["allocs_per_frame"] =
        s.frames_after_warmup ? static_cast<double>(s.allocations_after_warmup) / s.frames_after_warmup : -1.0;
  }
}

void BM_TriggerToPose5Cam20Hz_direct_call(benchmark::State& state) {
  const Dataset dataset = Dataset::open(benchDataset());
  std::vector<std::vector<Image>> images(dataset.size());
  std::vector<std::vector<bool>> present(dataset.size());
  for (std::size_t i = 0; i < dataset.size(); ++i) dataset.loadImages(i, images[i], present[i], nullptr);
  auto pipeline = createPipeline(YAML::Node(YAML::NodeType::Map), "bench", dataset.rig());
  const int frames = static_cast<int>(state.range(0));
  for (auto _ : state) {
    std::vector<int64_t> latency;
    std::vector<std::pair<int64_t, PipelineTiming>> stages;  // per frame
    ImageView views[5];
    bool here[5];
    PoseEstimate out;
    for (int f = 0; f < frames; ++f) {
      const std::size_t i = static_cast<std::size_t>(f) % dataset.size();
      for (int c = 0; c < 5; ++c) {
        views[c] = images[i][c].view();
        here[c] = present[i][c];
      }
      const RigFrameView view{dataset.frames()[i].t, static_cast<uint64_t>(f), 5, views, here};
      const int64_t t0 = monotonicNowNs();
      pipeline->process(view, out);
      latency.push_back(monotonicNowNs() - t0);
      stages.emplace_back(latency.back(), *pipeline->lastTiming());
      benchmark::DoNotOptimize(out);
    }
    reportPercentiles(state, latency);
    std::sort(stages.begin(), stages.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    const PipelineTiming& p99 = stages[stages.size() * 99 / 100].second;
    state.counters["p99_frame_features_ms"] = p99.features_ms;
    state.counters["p99_frame_tracking_ms"] = p99.tracking_ms;
    state.counters["p99_frame_backend_ms"] = p99.optimization_ms;  // waiting for the keyframe's solve included
    state.counters["p99_frame_places_ms"] = p99.places_ms;
  }
}

}  // namespace

BENCHMARK(BM_ShmPublishToRead_mcslam)
    ->Name("ShmPublishToRead/mcslam")
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ShmPublishToRead_udp_loopback)
    ->Name("ShmPublishToRead/udp_loopback")
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TriggerToPose5Cam20Hz_mcslam)
    ->Name("TriggerToPose5Cam20Hz/mcslam")
    ->Arg(200)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TriggerToPose5Cam20Hz_direct_call)
    ->Name("TriggerToPose5Cam20Hz/direct_call")
    ->Arg(200)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
