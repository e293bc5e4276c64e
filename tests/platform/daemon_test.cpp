// The daemon in-process: every published pose reaches shared memory, UDP and (when valid) the trajectory
// file identically; processing falling behind drops the oldest rig frames (counted) without ever
// stalling the replay; the software trigger drives the replay; and after warm-up no daemon thread
// allocates, over thousands of frames (preloaded, or PGM read from disk for every frame).
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>
#include <utility>

#include "alloc_testing.hpp"
#include "daemon/daemon.hpp"
#include "daemon/daemon_config.hpp"
#include "daemon/supervisor.hpp"
#include "daemon_fixture.hpp"
#include "emulation.hpp"
#include "mcslam/pipeline/pipeline_factory.hpp"
#include "mcslam/pose_shm.hpp"
#include "sim_dataset_fixture.hpp"
#include "test_support.hpp"

using namespace mcslam;
using namespace mcslam::platform;

namespace {

// Reports a valid pose derived from the frame, so the trajectory has content; optionally slow.
class FakeProcessor : public FrameProcessor {
 public:
  explicit FakeProcessor(int delay_ms = 0) : delay_ms_(delay_ms) {}
  void process(const RigFrameView& f, PoseEstimate& out) override {
    if (delay_ms_) std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms_));
    out = PoseEstimate{};
    out.t = f.t;
    out.sequence = f.sequence;
    out.T_w_b = SE3(so3Exp(Vec3(0, 0.01 * static_cast<double>(f.sequence), 0)),
                    Vec3(0.1 * static_cast<double>(f.sequence), -1.0 / 3.0, 0.5));
    out.state = f.sequence % 7 == 3 ? TrackingState::Lost : TrackingState::Tracking;
    out.valid = out.state == TrackingState::Tracking;
    out.quality = 0.9f;
    out.is_keyframe = f.sequence % 5 == 0;
    out.metric = f.sequence >= 20;  // as a rig without overlap before its scale converged
  }
  // Stage times as a pipeline reports them: odometry 4 ms (3 + 1), front-end 2 ms, place memory 0.5 ms.
  const PipelineTiming* lastTiming() const override { return &timing_; }

 private:
  int delay_ms_;
  PipelineTiming timing_{2.0, 3.0, 1.0, 0.5, 6.5};
};

// FNV-1a of an image's pixels.
uint64_t imageHash(const ImageView& v) {
  uint64_t h = 1469598103934665603ull;
  for (int y = 0; y < v.height; ++y)
    for (int x = 0; x < v.width; ++x) h = (h ^ v.data[static_cast<std::size_t>(y) * v.stride + x]) * 1099511628211ull;
  return h;
}

// Records what reaches the pipeline: stamps, sequence numbers and a hash per camera image.
class RecordingProcessor : public FrameProcessor {
 public:
  struct Seen {
    Timestamp t;
    uint64_t sequence;
    std::vector<uint64_t> hashes;
  };
  explicit RecordingProcessor(std::vector<Seen>& seen) : seen_(seen) {}
  void process(const RigFrameView& f, PoseEstimate& out) override {
    Seen s{f.t, f.sequence, {}};
    for (int c = 0; c < f.cameras; ++c) s.hashes.push_back(f.present[c] ? imageHash(f.images[c]) : 0);
    seen_.push_back(s);
    out = PoseEstimate{};
    out.t = f.t;
    out.sequence = f.sequence;
  }

 private:
  std::vector<Seen>& seen_;
};

std::vector<pose::PoseRecord> drainUdp(int fd) {
  std::vector<pose::PoseRecord> out;
  uint8_t buf[512];
  for (;;) {
    const ssize_t n = ::recv(fd, buf, sizeof(buf), 0);
    if (n <= 0) break;
    pose::PoseRecord r;
    if (pose::decodePacket(buf, static_cast<std::size_t>(n), r) == pose::DecodeStatus::Ok) out.push_back(r);
  }
  return out;
}

// Lines of a TUM file as (time text, 7 doubles).
std::vector<std::pair<std::string, std::vector<double>>> readTum(const std::string& path) {
  std::vector<std::pair<std::string, std::vector<double>>> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::pair<std::string, std::vector<double>> row;
    s >> row.first;
    double v;
    while (s >> v) row.second.push_back(v);
    rows.push_back(row);
  }
  return rows;
}

std::string tumTime(int64_t ns) {
  char b[32];
  std::snprintf(b, sizeof(b), "%lld.%09lld", static_cast<long long>(ns / 1000000000),
                static_cast<long long>(ns % 1000000000));
  return b;
}

template <typename Pred>
bool waitFor(Pred pred, int seconds = 60) {  // liveness only
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  while (!pred()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

class DaemonTest : public ::testing::Test {
 protected:
  DaemonConfig config(const std::string& dataset, const std::string& extra, const std::string& shm = "") {
    std::ostringstream y;
    y << "source:\n  type: dataset\n  dataset:\n    path: " << dataset << "\n" << extra;
    y << "output:\n  directory: " << dir_.path().string() << "\n";
    y << "publish:\n  shm:\n    enabled: " << (shm.empty() ? "false" : "true") << "\n";
    if (!shm.empty()) y << "    name: " << shm << "\n    ring_length: 4096\n";
    if (udp_port_) y << "  udp:\n    destinations: [\"127.0.0.1:" << udp_port_ << "\"]\n";
    return parseDaemonConfig(y.str(), dir_.file("daemon.yaml"));
  }
  test::TempDir dir_{"daemon"};
  int udp_port_ = 0;
};

}  // namespace

TEST_F(DaemonTest, EveryPoseGoesToSharedMemoryUdpAndTheTrajectoryIdentically) {
  const std::string data = test::writeSmallDataset(dir_.file("data"), 3, 40);
  const test::UdpReceiver rx(INADDR_LOOPBACK, 200, 4 << 20);  // big enough for a run's datagrams
  udp_port_ = rx.port();
  const std::string shm = "/mcslam-test-daemon-" + std::to_string(getpid());
  const DaemonConfig c = config(data, "    rate: fastest\n    at_end: idle\n", shm);
  std::vector<pose::PoseRecord> from_udp;
  std::string trajectory;
  std::vector<pose::PoseRecord> from_shm;
  {
    Daemon d(c, std::make_unique<FakeProcessor>());
    pose::PoseShmReader reader;
    ASSERT_TRUE(reader.open(shm));
    d.start();
    ASSERT_TRUE(waitFor([&] { return d.stats().published >= 40; }));
    ASSERT_TRUE(d.stop());
    for (uint64_t s = 1; s <= reader.published(); ++s) {
      pose::PoseRecord r;
      ASSERT_EQ(reader.readSequence(s, r), pose::ReadStatus::Ok);
      from_shm.push_back(r);
    }
    const DaemonStats st = d.stats();
    EXPECT_EQ(st.rig_drops, 0u);  // "fastest" is lossless
    EXPECT_EQ(st.partial_frames, 0u);
    EXPECT_FALSE(st.unscaled);  // the last pose (frame 39) is metric
    trajectory = d.trajectoryPath();
  }
  from_udp = drainUdp(rx.fd());
  ASSERT_EQ(from_shm.size(), 40u);
  ASSERT_EQ(from_udp.size(), 40u);
  const auto rows = readTum(trajectory);
  std::size_t row = 0, valid = 0;
  for (std::size_t i = 0; i < 40; ++i) {
    const pose::PoseRecord& s = from_shm[i];
    const pose::PoseRecord& u = from_udp[i];
    uint8_t a[pose::kPacketSize], b[pose::kPacketSize];
    pose::encodePacket(s, a);
    pose::encodePacket(u, b);
    EXPECT_EQ(std::memcmp(a, b, sizeof(a)), 0) << "record " << i << " differs between shm and UDP";
    EXPECT_EQ(s.sequence, i + 1);
    EXPECT_EQ(s.frame_sequence, i);
    EXPECT_EQ(s.capture_time_ns, 1000000000000ll + static_cast<int64_t>(i) * 50000000);
    EXPECT_EQ(s.unscaled(), i < 20) << i;
    if (!s.valid()) continue;
    ++valid;
    ASSERT_LT(row, rows.size());
    EXPECT_EQ(rows[row].first, tumTime(s.capture_time_ns));
    ASSERT_EQ(rows[row].second.size(), 7u);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(rows[row].second[k], s.position[k]);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(rows[row].second[3 + k], s.orientation[k]);
    ++row;
  }
  EXPECT_GT(valid, 30u);
  EXPECT_EQ(rows.size(), valid);  // nothing more, nothing less
}

TEST_F(DaemonTest, SlowProcessingDropsTheOldestRigFramesAndNeverStallsTheReplay) {
  const std::string data = test::writeSmallDataset(dir_.file("data"), 2, 40, 32, 24, 5000000);  // 200 Hz
  const DaemonConfig c = config(data, "    at_end: idle\ncapacities:\n  rig_ring_slots: 2\n");
  Daemon d(c, std::make_unique<FakeProcessor>(20));  // 50 Hz at best
  d.start();
  ASSERT_TRUE(waitFor([&] { return d.stats().source_finished; }));
  ASSERT_TRUE(waitFor([&] { return d.drained(); }));
  ASSERT_TRUE(d.stop());
  const DaemonStats s = d.stats();
  EXPECT_EQ(s.camera_frames, 80u);  // the replay delivered every image on time: nothing waited for processing
  // Every rig frame is assembled, unless the assembly thread itself was starved of CPU long enough for a camera
  // ring to overflow (a loaded machine: 200 Hz here); such a loss is counted, never silent.
  EXPECT_LE(s.rig_frames, 40u);
  EXPECT_GE(s.rig_frames + s.camera_drops, 40u) << "partial " << s.partial_frames << ", late " << s.late_images;
  EXPECT_GT(s.rig_drops, 0u);
  EXPECT_EQ(s.processed + s.rig_drops, s.rig_frames);
  EXPECT_EQ(s.published, s.processed);
}

// A pipeline whose frame outlasts the stop's grace period (slow, as under an emulator, or hung): stop() leaves its
// thread behind and says so, and the daemon is not destroyed under that thread: the pipeline is released only once
// its frame is done.
namespace {
class SlowToStopProcessor : public FrameProcessor {
 public:
  struct Flags {
    std::atomic<bool> hold{true};  // a frame waits while set
    std::atomic<bool> inside{false};
    std::atomic<bool> destroyed_inside{false};
  };
  explicit SlowToStopProcessor(Flags& flags) : flags_(flags) {}
  ~SlowToStopProcessor() override { flags_.destroyed_inside = flags_.inside.load(); }
  void process(const RigFrameView& f, PoseEstimate& out) override {
    flags_.inside = true;
    while (flags_.hold) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the rest of the frame
    out = PoseEstimate{};
    out.t = f.t;
    out.sequence = f.sequence;
    flags_.inside = false;
  }

 private:
  Flags& flags_;
};
}  // namespace

TEST_F(DaemonTest, APipelineStillInsideItsFrameAfterTheGracePeriodIsReleasedOnlyOnceItIsDone) {
  const std::string data = test::writeSmallDataset(dir_.file("data"), 1, 5);
  const DaemonConfig c = config(data, "    at_end: idle\n");
  SlowToStopProcessor::Flags flags;
  auto d = std::make_unique<Daemon>(c, std::make_unique<SlowToStopProcessor>(flags));
  d->start();
  ASSERT_TRUE(waitFor([&] { return flags.inside.load(); }));
  EXPECT_FALSE(d->stop(/*processing_grace_ns=*/10000000));  // the frame holds: left behind
  flags.hold = false;
  d.reset();
  EXPECT_FALSE(flags.inside.load());
  EXPECT_FALSE(flags.destroyed_inside.load()) << "the pipeline was destroyed inside its frame";
}

TEST_F(DaemonTest, TheNewestFrameSurvivesDropsAndPublishedFramesStayInOrder) {
  const std::string data = test::writeSmallDataset(dir_.file("data"), 2, 30, 32, 24, 5000000);
  const test::UdpReceiver rx(INADDR_LOOPBACK, 200, 4 << 20);  // big enough for a run's datagrams
  udp_port_ = rx.port();
  const DaemonConfig c = config(data, "    at_end: idle\n");
  {
    Daemon d(c, std::make_unique<FakeProcessor>(15));
    d.start();
    ASSERT_TRUE(waitFor([&] { return d.drained(); }));
    d.stop();
  }
  const auto records = drainUdp(rx.fd());
  ASSERT_FALSE(records.empty());
  for (std::size_t i = 1; i < records.size(); ++i) EXPECT_GT(records[i].frame_sequence, records[i - 1].frame_sequence);
  EXPECT_EQ(records.back().frame_sequence, 29u);  // dropping takes the oldest, never the newest
}

TEST_F(DaemonTest, SoftwareTriggerDrivesTheReplayAndLatencyIsMeasured) {
  const std::string data = test::writeSmallDataset(dir_.file("data"), 2, 10);
  const DaemonConfig c = config(data, "    at_end: loop\ntrigger:\n  mode: software\n  rate_hz: 100\n");
  Daemon d(c, std::make_unique<FakeProcessor>());
  d.start();
  ASSERT_TRUE(waitFor([&] { return d.stats().published >= 20; }));
  d.stop();
  const DaemonStats s = d.stats();
  EXPECT_GE(s.triggers, 20u);
  EXPECT_GE(s.latency_count, 20u);
  EXPECT_GT(s.latency_p50_ns, 0);
  EXPECT_LE(s.rig_frames, s.triggers);  // one frame per trigger at most
  // The processor's stage times, to the histogram's 2% bins.
  for (const auto& [time, ms] :
       {std::pair{s.front_end_time, 2.0}, {s.odometry_time, 4.0}, {s.place_memory_time, 0.5}}) {
    EXPECT_NEAR(static_cast<double>(time.p50_ns) * 1e-6, ms, 0.03 * ms);
    EXPECT_NEAR(static_cast<double>(time.p99_ns) * 1e-6, ms, 0.03 * ms);
  }
}

TEST_F(DaemonTest, NoDaemonThreadAllocatesPerFrameAfterWarmup) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  // 5 cameras, preloaded and looped, as fast as the pipeline takes them: thousands of frames quickly.
  const std::string data = test::writeSmallDataset(dir_.file("data"), 5, 20, 64, 48);
  const test::UdpReceiver rx(INADDR_LOOPBACK, 200, 4 << 20);  // big enough for a run's datagrams
  udp_port_ = rx.port();
  const std::string shm = "/mcslam-test-alloc-" + std::to_string(getpid());
  const DaemonConfig c =
      config(data, "    rate: fastest\n    at_end: loop\n    preload: true\nwarmup_frames: 100\n", shm);
  Daemon d(c, createPipeline(c.slam, c.file, c.rig));  // the real pipeline (today's stub or the odometry)
  d.start();
  ASSERT_TRUE(waitFor([&] { return d.stats().processed >= 3000; }, 100));
  d.stop();
  const DaemonStats s = d.stats();
  ASSERT_TRUE(s.warm);
  EXPECT_GE(s.frames_after_warmup, 2800u);
  EXPECT_EQ(s.allocations_after_warmup, 0u) << "over " << s.frames_after_warmup << " frames";
}

TEST_F(DaemonTest, ReplayingPgmFromDiskAllocatesNothingPerFrameAfterWarmup) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  // As above without preload: every image is read from its PGM file into the camera ring's slot, every frame.
  // (PNG decoding through the image codec module allocates, about 95 times per rig frame of 5 cameras.)
  const std::string data = test::writeSmallPgmDataset(dir_.file("data"), 5, 20, 64, 48);
  const std::string shm = "/mcslam-test-alloc-pgm-" + std::to_string(getpid());
  const DaemonConfig c = config(data, "    rate: fastest\n    at_end: loop\nwarmup_frames: 100\n", shm);
  Daemon d(c, createPipeline(c.slam, c.file, c.rig));
  d.start();
  ASSERT_TRUE(waitFor([&] { return d.stats().processed >= 3000; }, 100));
  d.stop();
  const DaemonStats s = d.stats();
  ASSERT_TRUE(s.warm);
  EXPECT_EQ(s.bad_frames, 0u);
  EXPECT_GE(s.frames_after_warmup, 2800u);
  EXPECT_EQ(s.allocations_after_warmup, 0u) << "over " << s.frames_after_warmup << " frames";
}

TEST_F(DaemonTest, PlaceMemoryAndMapSavesAllocateNothingPerFrameAfterWarmup) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  // The rendered route replayed in a loop, tracked (the odometry finds the start again at each wrap): place
  // keyframes join the map and query it for loops, and the map is saved every 0.2 s, written into the saver's
  // buffer by the processing thread and to disk by the saver's thread. After warm-up none of these threads
  // allocates. (Relocalization, culling and loop correction are counted through mcslam-run: tests/places.)
  const std::string data = test::cachedSimDataset();
  const DaemonConfig c = config(data,
                                "    rate: fastest\n    at_end: loop\n    preload: true\nwarmup_frames: 100\n"
                                "map:\n  save: " +
                                    dir_.file("robot.map") + "\n  save_interval_s: 0.2\n");
  Daemon d(c, createPipeline(c.slam, c.file, c.rig, /*live=*/true));  // as mcslamd runs it
  d.start();
  // Liveness only: under qemu-user the five cameras' pipeline runs 30-50 times slower.
  const int seconds = test::underEmulator() ? 2400 : 300;
  ASSERT_TRUE(waitFor([&] { return d.stats().processed >= 300 && d.stats().map_saves >= 3; }, seconds));
  d.stop();
  const DaemonStats s = d.stats();
  ASSERT_TRUE(s.warm);
  EXPECT_GT(s.places.keyframes, 3);
  EXPECT_GE(s.map_saves, 3u);
  EXPECT_EQ(s.map_save_failures, 0u);
  EXPECT_EQ(s.allocations_after_warmup, 0u) << "over " << s.frames_after_warmup << " frames";
}

TEST_F(DaemonTest, SimSourceDeliversTheSimulatorsFramesWholeAndInOrder) {
  // The same simulation as the cached dataset (isec, indoor, ground, 10 Hz, seed 1), two of its cameras
  // in another order: the rendered frames must equal the dataset's images byte for byte.
  const std::string data = test::cachedSimDataset();
  const int frames = 4;
  const DaemonConfig c = parseDaemonConfig(
      "source:\n  type: sim\n  sim:\n    rig: isec\n    cameras: [3, 1]\n    frames: 4\n    at_end: exit\n"
      "publish:\n  shm:\n    enabled: false\noutput:\n  directory: " +
          dir_.path().string() + "\n",
      dir_.file("sim.yaml"));
  std::vector<RecordingProcessor::Seen> seen;
  {
    Daemon d(c, std::make_unique<RecordingProcessor>(seen));
    d.start();
    ASSERT_TRUE(waitFor([&] { return d.drained(); }, 120));
    ASSERT_TRUE(d.stop());
    const DaemonStats st = d.stats();
    EXPECT_EQ(st.rig_frames, 4u);      // at_end exit: the sequence, once
    EXPECT_EQ(st.partial_frames, 0u);  // all cameras rendered before any is published
    EXPECT_EQ(st.rig_drops, 0u);       // pace fastest is lossless
  }
  DatasetOptions options;
  options.cameras = {3, 1};
  const Dataset dataset = Dataset::open(data, options);
  ASSERT_EQ(seen.size(), static_cast<std::size_t>(frames));
  std::vector<Image> images;
  std::vector<bool> present;
  for (int i = 0; i < frames; ++i) {
    EXPECT_EQ(seen[i].t, dataset.frames()[i].t);
    EXPECT_EQ(seen[i].sequence, static_cast<uint64_t>(i));
    ASSERT_EQ(seen[i].hashes.size(), 2u);
    dataset.loadImages(i, images, present, nullptr);
    for (int k = 0; k < 2; ++k)
      EXPECT_EQ(seen[i].hashes[k], imageHash(images[k].view())) << "frame " << i << " camera " << k;
  }
}

// The status line (systemd STATUS= and the log) says when the poses are not in metres.
TEST(DaemonStatus, TheStatusLineSaysWhenPositionsAreUpToScale) {
  DaemonStats s;
  s.tracking = TrackingState::Tracking;
  char line[400];
  formatStatus(s, 10.0, "ok", line, sizeof(line));
  EXPECT_EQ(std::string(line).find("up to scale"), std::string::npos) << line;
  s.unscaled = true;
  formatStatus(s, 10.0, "ok", line, sizeof(line));
  EXPECT_NE(std::string(line).find("tracking (up to scale)"), std::string::npos) << line;
  s.roughly_metric = true;  // overlapping cameras whose common points lie too far for their baseline
  formatStatus(s, 10.0, "ok", line, sizeof(line));
  EXPECT_NE(std::string(line).find("tracking (roughly metric"), std::string::npos) << line;
}

// A pose segment made anew (another process truncated it) is in the status line, and only then.
TEST(DaemonStatus, TheStatusLineCountsSegmentsMadeAnew) {
  DaemonStats s;
  char line[400];
  formatStatus(s, 10.0, "ok", line, sizeof(line));
  EXPECT_EQ(std::string(line).find("shm segments"), std::string::npos) << line;
  s.shm_replacements = 2;
  formatStatus(s, 10.0, "ok", line, sizeof(line));
  EXPECT_NE(std::string(line).find(", shm segments made anew 2"), std::string::npos) << line;
}
