// mcslamd as a process, the way systemd runs it, with the real pipeline on a rendered simulator dataset:
// READY=1 and WATCHDOG=1 arrive on a test NOTIFY_SOCKET, another process (this test) reads the poses
// over shared memory and over UDP and they equal each other and the trajectory file the daemon writes;
// SIGTERM ends it cleanly within 2 s with the trajectory complete and the refined extrinsics written; the
// trajectory is within centimetres of the simulator's ground truth.
// Also: no WATCHDOG=1 while no frame is processed, a bad configuration ends start-up with one
// message naming the key (exit status 2), and OpenCV's imgcodecs (with its ~110 libraries) is mapped only when
// the replay meets a PNG, never for PGM.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include "daemon/supervisor.hpp"
#include "daemon_fixture.hpp"
#include "emulation.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/dataset/trajectory.hpp"
#include "mcslam/eval/trajectory_metrics.hpp"
#include "mcslam/pose_shm.hpp"
#include "sim_dataset_fixture.hpp"
#include "test_support.hpp"

using namespace mcslam;
using Clock = std::chrono::steady_clock;

namespace {

// Collects the datagrams sent to a NOTIFY_SOCKET.
class NotifyListener {
 public:
  explicit NotifyListener(const std::string& path) : path_(path) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::snprintf(a.sun_path, sizeof(a.sun_path), "%s", path.c_str());
    ok_ = ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0;
    timeval tv{0, 100000};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
    thread_ = std::thread([this] {
      char buf[1024];
      while (!stop_) {
        const ssize_t n = ::recv(fd_, buf, sizeof(buf), 0);
        if (n <= 0) continue;
        std::lock_guard<std::mutex> lock(m_);
        messages_.emplace_back(buf, n);
      }
    });
  }
  ~NotifyListener() {
    stop_ = true;
    thread_.join();
    ::close(fd_);
  }
  bool ok() const { return ok_; }
  int count(const std::string& prefix) {
    std::lock_guard<std::mutex> lock(m_);
    int n = 0;
    for (const auto& m : messages_) n += m.rfind(prefix, 0) == 0 ? 1 : 0;
    return n;
  }
  std::string last(const std::string& prefix) {
    std::lock_guard<std::mutex> lock(m_);
    for (auto it = messages_.rbegin(); it != messages_.rend(); ++it)
      if (it->rfind(prefix, 0) == 0) return *it;
    return {};
  }

 private:
  std::string path_;
  int fd_ = -1;
  bool ok_ = false;
  std::atomic<bool> stop_{false};
  std::mutex m_;
  std::vector<std::string> messages_;
  std::thread thread_;
};

pid_t spawnDaemon(const std::string& config, const std::string& notify, const std::string& watchdog_usec,
                  const std::string& log) {
  const pid_t pid = test::forkDyingWithParent();
  if (pid == 0) {
    ::setenv("NOTIFY_SOCKET", notify.c_str(), 1);
    ::setenv("WATCHDOG_USEC", watchdog_usec.c_str(), 1);
    ::unsetenv("WATCHDOG_PID");
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    const std::string bin = test::binPath("mcslamd");
    ::execl(bin.c_str(), bin.c_str(), "--config", config.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

// A daemon the test started does not outlive it: a failed assertion returns early, and the daemon would go on
// (replaying, holding its shared memory) after the test process is gone.
class ReapOnExit {
 public:
  explicit ReapOnExit(pid_t pid) : pid_(pid) {}
  ~ReapOnExit() {
    int status = 0;
    if (pid_ > 0 && ::waitpid(pid_, &status, WNOHANG) == 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, &status, 0);
    }
  }
  ReapOnExit(const ReapOnExit&) = delete;
  ReapOnExit& operator=(const ReapOnExit&) = delete;

 private:
  pid_t pid_;
};

// Waits (liveness bound only) for the child; returns its exit status, or -1.
int waitExit(pid_t pid, int seconds) {
  const auto deadline = Clock::now() + std::chrono::seconds(seconds);
  int status = 0;
  while (Clock::now() < deadline) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  return -1;
}

template <typename Pred>
bool waitFor(Pred pred, int seconds = 60) {
  const auto deadline = Clock::now() + std::chrono::seconds(seconds);
  while (!pred()) {
    if (Clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

struct TumRow {
  std::string stamp;           // as written
  std::vector<double> values;  // tx ty tz qx qy qz qw, parsed with strtod (exact round trip)
};

std::vector<TumRow> readTumRows(const std::string& path) {
  std::vector<TumRow> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    TumRow row;
    std::string token;
    s >> row.stamp;
    while (s >> token) row.values.push_back(std::strtod(token.c_str(), nullptr));
    rows.push_back(row);
  }
  return rows;
}

std::string tumStamp(int64_t ns) {
  char b[32];
  std::snprintf(b, sizeof(b), "%lld.%09lld", static_cast<long long>(ns / 1000000000),
                static_cast<long long>(ns % 1000000000));
  return b;
}

std::string readAll(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

// The whole chain with the real pipeline: a rendered 5-camera sequence replayed losslessly and looped,
// SIGTERM in the second pass (the pipeline is mid-frame), then every record compared across the three
// outputs and the first pass's trajectory against the simulator's ground truth.
TEST(McslamdProcess, SimulatedRigReplayPublishesAccuratePosesEverywhereAndStopsCleanlyOnSigterm) {
  const std::string data = test::cachedSimDataset();
  const uint64_t frames = test::kSimDatasetFrames;
  test::TempDir dir("mcslamd");
  NotifyListener notify(dir.file("notify.sock"));
  ASSERT_TRUE(notify.ok());
  const test::UdpReceiver rx(INADDR_LOOPBACK, 300);
  ASSERT_GE(rx.fd(), 0);

  const std::string shm = "/mcslam-test-proc-" + std::to_string(getpid());
  const std::string config = test::writeFile(dir.file("mcslamd.yaml"),
                                             "log_level: debug\nstatus_interval_s: 0.2\nwarmup_frames: 20\n"
                                             "source:\n  type: dataset\n  dataset:\n    path: " +
                                                 data +
                                                 "\n    rate: fastest\n    at_end: loop\n"
                                                 "publish:\n  shm:\n    name: " +
                                                 shm +
                                                 "\n    mode: \"0640\"\n    ring_length: 256\n"
                                                 "  udp:\n    destinations: [\"127.0.0.1:" +
                                                 std::to_string(rx.port()) +
                                                 "\"]\n"
                                                 "output:\n  directory: out\n  extrinsics: refined/extrinsics.yaml\n");
  std::filesystem::create_directories(dir.file("out/refined"));
  const pid_t pid = spawnDaemon(config, dir.file("notify.sock"), "400000", dir.file("log.txt"));
  const ReapOnExit reap_pid(pid);
  ASSERT_GT(pid, 0);

  ASSERT_TRUE(waitFor([&] { return notify.count("READY=1") == 1; })) << readAll(dir.file("log.txt"));
  pose::PoseShmReader reader;  // the segment exists before READY=1
  std::string error;
  ASSERT_TRUE(reader.open(shm, &error)) << error;
  EXPECT_EQ(reader.writerPid(), pid);
  ASSERT_TRUE(waitFor([&] { return reader.published() >= frames + 3; }, 120)) << readAll(dir.file("log.txt"));
  ASSERT_TRUE(waitFor([&] { return notify.count("WATCHDOG=1") >= 1 && notify.count("STATUS=") >= 1; }));
  EXPECT_NE(notify.last("STATUS=").find("tracking"), std::string::npos) << notify.last("STATUS=");

  const auto t0 = Clock::now();
  ASSERT_EQ(::kill(pid, SIGTERM), 0);
  const int status = waitExit(pid, 20);
  const double stop_s = std::chrono::duration<double>(Clock::now() - t0).count();
  const std::string log = readAll(dir.file("log.txt"));
  EXPECT_EQ(status, 0) << log;
  // The one timed assertion (the mcslamd issue's bound from SIGTERM to exit), for the product's build: under a
  // sanitizer every step is several times slower, so the bound there is 5x.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  constexpr double kStopBoundS = 10.0;
#else
  constexpr double kStopBoundS = 2.0;
#endif
  EXPECT_LT(stop_s, kStopBoundS) << "the issue's bound from SIGTERM to exit";
  EXPECT_FALSE(reader.writerRunning());
  EXPECT_EQ(notify.count("STOPPING=1"), 1);
  EXPECT_NE(log.find("SIGTERM: stopping"), std::string::npos) << log;

  // The segment stays mapped after the daemon unlinked it: read every record it published.
  const uint64_t published = reader.published();
  ASSERT_LE(published, 256u) << "ring_length must hold the whole run";
  std::vector<pose::PoseRecord> from_shm;
  for (uint64_t seq = 1; seq <= published; ++seq) {
    pose::PoseRecord r;
    ASSERT_EQ(reader.readSequence(seq, r), pose::ReadStatus::Ok);
    from_shm.push_back(r);
  }
  std::vector<pose::PoseRecord> from_udp;
  uint8_t buf[512];
  for (;;) {
    const ssize_t n = ::recv(rx.fd(), buf, sizeof(buf), 0);
    if (n <= 0) break;
    pose::PoseRecord r;
    ASSERT_EQ(pose::decodePacket(buf, static_cast<std::size_t>(n), r), pose::DecodeStatus::Ok);
    from_udp.push_back(r);
  }
  ASSERT_EQ(from_udp.size(), from_shm.size());
  ASSERT_GT(from_shm.size(), frames);

  // The trajectory: exactly the valid records, in order, numbers parsing back to the published doubles.
  const auto rows = readTumRows(dir.file("out/trajectory.tum"));
  std::size_t row = 0;
  Trajectory first_pass;
  for (std::size_t i = 0; i < from_shm.size(); ++i) {
    const pose::PoseRecord& r = from_shm[i];
    uint8_t x[pose::kPacketSize], y[pose::kPacketSize];
    pose::encodePacket(r, x);
    pose::encodePacket(from_udp[i], y);
    EXPECT_EQ(std::memcmp(x, y, sizeof(x)), 0) << "record " << i << " differs between shm and UDP";
    EXPECT_EQ(r.sequence, i + 1);
    EXPECT_EQ(r.frame_sequence, i);  // fastest replay is lossless
    if (!r.valid()) continue;
    ASSERT_LT(row, rows.size()) << "valid record " << i << " missing in the trajectory";
    EXPECT_EQ(rows[row].stamp, tumStamp(r.capture_time_ns)) << "row " << row;
    ASSERT_EQ(rows[row].values.size(), 7u);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(rows[row].values[k], r.position[k]) << "row " << row;
    for (int k = 0; k < 4; ++k) EXPECT_EQ(rows[row].values[3 + k], r.orientation[k]) << "row " << row;
    ++row;
    if (r.frame_sequence < frames) {
      const Eigen::Quaterniond q(r.orientation[3], r.orientation[0], r.orientation[1], r.orientation[2]);
      first_pass.push_back(
          {r.capture_time_ns, SE3(q.toRotationMatrix(), Vec3(r.position[0], r.position[1], r.position[2]))});
    }
  }
  EXPECT_EQ(rows.size(), row) << "the trajectory holds a line that was never published";

  // The poses are right: the first pass against the simulator's ground truth (SE(3)-aligned).
  ASSERT_GE(first_pass.size(), frames * 9 / 10) << "the pipeline initialized late or lost track";
  const ApeResult ape = computeApe(readTumTrajectory(data + "/groundtruth.txt"), first_pass, EvalOptions{});
  std::printf("ATE rmse %.4f m over %zu poses, stop %.3f s after SIGTERM\n", ape.stats.rmse, ape.errors.size(), stop_s);
  EXPECT_EQ(ape.errors.size(), first_pass.size());
  EXPECT_LT(ape.stats.rmse, 0.03);
  EXPECT_LT(ape.stats.max, 0.08);

  // The refined extrinsics, written at stop: a Kalibr camchain of the same rig, close to the calibration.
  ASSERT_NE(log.find("refined extrinsics written"), std::string::npos) << log;
  const Rig written = loadKalibrRig(dir.file("out/refined/extrinsics.yaml"));
  const Rig calibrated = loadKalibrRig(data + "/camchain.yaml");
  ASSERT_EQ(written.size(), calibrated.size());
  for (int c = 0; c < written.size(); ++c) {
    const SE3 d = calibrated.T_b_c(c).inverse() * written.T_b_c(c);
    EXPECT_LT(d.t.norm(), 0.02) << "cam" << c;
    EXPECT_LT(so3Log(d.R).norm(), 1.0 * M_PI / 180) << "cam" << c;
    EXPECT_EQ(written.model(c).width(), calibrated.model(c).width());
  }
}

namespace {
// A daemon that waits for its first frame: a small replay behind a software trigger at 0.1 Hz, whose first pulse
// (and so the first frame) is 10 s away; no shared memory. Its configuration file in `dir`.
std::string idleDaemonConfig(const test::TempDir& dir, const std::string& status_interval_s) {
  test::writeSmallDataset(dir.file("data"), 2, 5);
  return test::writeFile(dir.file("mcslamd.yaml"),
                         "status_interval_s: " + status_interval_s +
                             "\nsource:\n  type: dataset\n  dataset:\n    path: data\n"
                             "trigger:\n  mode: software\n  rate_hz: 0.1\n"
                             "publish:\n  shm:\n    enabled: false\noutput:\n  directory: .\n");
}
}  // namespace

TEST(McslamdProcess, NoWatchdogWhileNoFrameIsProcessed) {
  test::TempDir dir("mcslamd-wd");
  NotifyListener notify(dir.file("notify.sock"));
  ASSERT_TRUE(notify.ok());
  const std::string config = idleDaemonConfig(dir, "0.1");
  const pid_t pid = spawnDaemon(config, dir.file("notify.sock"), "100000", dir.file("log.txt"));
  const ReapOnExit reap_pid(pid);
  ASSERT_TRUE(waitFor([&] { return notify.count("READY=1") == 1; })) << readAll(dir.file("log.txt"));
  ASSERT_TRUE(waitFor([&] { return notify.count("STATUS=") >= 5; }));  // ticks happened (every 50 ms)
  EXPECT_EQ(notify.count("WATCHDOG=1"), 0) << "watchdog kept alive without progress";
  ::kill(pid, SIGINT);
  EXPECT_EQ(waitExit(pid, 20), 0) << readAll(dir.file("log.txt"));
}

// Signals other than the stopping ones neither kill the daemon (their default action) nor stop it; SIGQUIT stops it
// as SIGTERM does, through the clean stop.
namespace {
// The log lines of the daemon's threads while it lives (read it once they are joined).
class LogCapture {
 public:
  LogCapture() : previous_(spdlog::default_logger()) {
    spdlog::set_default_logger(
        std::make_shared<spdlog::logger>("capture", std::make_shared<spdlog::sinks::ostream_sink_mt>(text_)));
  }
  ~LogCapture() { spdlog::set_default_logger(previous_); }
  LogCapture(const LogCapture&) = delete;
  LogCapture& operator=(const LogCapture&) = delete;
  std::string text() const { return text_.str(); }

 private:
  std::ostringstream text_;
  std::shared_ptr<spdlog::logger> previous_;
};

// A pipeline that hangs for 3 s on its 10th frame, saying when the hang begins and ends.
class HangingProcessor : public FrameProcessor {
 public:
  explicit HangingProcessor(std::function<void(bool)> hanging) : hanging_(std::move(hanging)) {}
  void process(const RigFrameView& f, PoseEstimate& out) override {
    if (f.sequence == 10) {
      hanging_(true);
      std::this_thread::sleep_for(std::chrono::seconds(3));
      hanging_(false);
    }
    out = PoseEstimate{};
    out.t = f.t;
    out.sequence = f.sequence;
    out.state = TrackingState::Tracking;
    out.valid = true;
  }

 private:
  std::function<void(bool)> hanging_;
};
}  // namespace

// systemd restarts a daemon whose watchdog pings stop (WatchdogSec=): the supervisor pings only while frames are
// processed, so a pipeline that hangs gets none (and a log line) for as long as it hangs, and pings again after.
TEST(McslamdProcess, AHungPipelineGetsNoWatchdogPings) {
  test::TempDir dir("mcslamd-hang");
  NotifyListener notify(dir.file("notify.sock"));
  ASSERT_TRUE(notify.ok());
  test::writeSmallDataset(dir.file("data"), 2, 30);
  const platform::DaemonConfig config = platform::parseDaemonConfig(
      "source:\n  type: dataset\n  dataset:\n    path: data\n    at_end: exit\n"  // 20 Hz
      "publish:\n  shm:\n    enabled: false\noutput:\n  directory: .\n",
      dir.file("mcslamd.yaml"));
  ::setenv("NOTIFY_SOCKET", dir.file("notify.sock").c_str(), 1);
  ::setenv("WATCHDOG_USEC", "100000", 1);  // a ping every 50 ms while there is progress
  ::unsetenv("WATCHDOG_PID");
  int pings_at_hang = -1, pings_after_hang = -1;
  auto processor = std::make_unique<HangingProcessor>(
      [&](bool hanging) { (hanging ? pings_at_hang : pings_after_hang) = notify.count("WATCHDOG=1"); });
  const LogCapture log;
  const int rc = platform::runDaemon(config, std::move(processor));
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");
  EXPECT_EQ(rc, 0);
  EXPECT_GE(pings_at_hang, 1) << "pings while frames were processed";
  EXPECT_LE(pings_after_hang - pings_at_hang, 1) << "pings while the pipeline hung for 3 s";  // one in flight
  EXPECT_GT(notify.count("WATCHDOG=1"), pings_after_hang) << "pings once frames flowed again";
  EXPECT_NE(log.text().find("no frame processed for 2 s"), std::string::npos) << log.text();
  EXPECT_NE(log.text().find("frames flow again"), std::string::npos) << log.text();
}

TEST(McslamdProcess, OtherSignalsAreAnsweredAndSigquitStopsCleanly) {
  test::TempDir dir("mcslamd-signals");
  NotifyListener notify(dir.file("notify.sock"));
  ASSERT_TRUE(notify.ok());
  const std::string config = idleDaemonConfig(dir, "1000");  // no status line from the timer
  const pid_t pid = spawnDaemon(config, dir.file("notify.sock"), "0", dir.file("log.txt"));
  const ReapOnExit reap_pid(pid);
  ASSERT_TRUE(waitFor([&] { return notify.count("READY=1") == 1; })) << readAll(dir.file("log.txt"));
  ::kill(pid, SIGHUP);
  ::kill(pid, SIGUSR2);
  ASSERT_TRUE(waitFor([&] { return readAll(dir.file("log.txt")).find("SIGUSR2 ignored") != std::string::npos; }))
      << readAll(dir.file("log.txt"));
  EXPECT_NE(readAll(dir.file("log.txt")).find("SIGHUP ignored"), std::string::npos);
  const int status_lines = notify.count("STATUS=");  // none from the timer: its interval is 1000 s
  ::kill(pid, SIGUSR1);
  ASSERT_TRUE(waitFor([&] { return notify.count("STATUS=") > status_lines; })) << readAll(dir.file("log.txt"));
  int status = 0;
  EXPECT_EQ(::waitpid(pid, &status, WNOHANG), 0) << "a signal ended the daemon";
  ::kill(pid, SIGQUIT);
  EXPECT_EQ(waitExit(pid, 20), 0) << readAll(dir.file("log.txt"));
  const std::string log = readAll(dir.file("log.txt"));
  EXPECT_NE(log.find("SIGQUIT: stopping"), std::string::npos) << log;
  EXPECT_NE(log.find("stopped:"), std::string::npos) << log;
  EXPECT_EQ(notify.count("STOPPING=1"), 1);
}

// The CPUs each of the process's threads may run on (/proc/PID/task/*/status, Cpus_allowed_list), one per thread.
std::vector<std::string> threadCpuLists(pid_t pid) {
  std::vector<std::string> lists;
  for (const auto& task : std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/task")) {
    const std::string status = readAll(task.path().string() + "/status");
    const std::size_t at = status.find("Cpus_allowed_list:");
    if (at == std::string::npos) continue;
    const std::size_t begin = status.find_first_not_of(" \t", at + 18);
    lists.push_back(status.substr(begin, status.find('\n', begin) - begin));
  }
  return lists;
}

// realtime.cpus keeps every thread of the daemon (the pipeline's workers and background tasks included) on the
// CPUs it names; a set the machine cannot honour is a warning, and the daemon runs on any CPU.
TEST(McslamdProcess, RealtimeCpusKeepsEveryThreadOnThem) {
  test::TempDir dir("mcslamd-cpus");
  NotifyListener notify(dir.file("notify.sock"));
  ASSERT_TRUE(notify.ok());
  const std::string idle = test::readFile(idleDaemonConfig(dir, "1000"));
  for (const auto& [cpus, expected] : {std::pair<std::string, std::string>{"[0]", "0"}, {"[1023]", ""}}) {
    const std::string config = test::writeFile(dir.file("cpus.yaml"), idle + "realtime:\n  cpus: " + cpus + "\n");
    const int ready_before = notify.count("READY=1");
    const pid_t pid = spawnDaemon(config, dir.file("notify.sock"), "0", dir.file("log.txt"));
    const ReapOnExit reap_pid(pid);
    ASSERT_TRUE(waitFor([&] { return notify.count("READY=1") > ready_before; })) << readAll(dir.file("log.txt"));
    const std::vector<std::string> lists = threadCpuLists(pid);
    EXPECT_GE(lists.size(), 5u);  // main, trigger, assembly, processing stages, workers
    const std::string log = readAll(dir.file("log.txt"));
    if (expected.empty()) {  // CPU 1023 is on no machine this runs on
      EXPECT_NE(log.find("realtime.cpus [1023]: Invalid argument; the threads run on any CPU"), std::string::npos)
          << log;
    } else {
      EXPECT_NE(log.find("realtime: every thread on CPUs 0"), std::string::npos) << log;
      // Under qemu-user one thread is the emulator's own (its RCU thread), which the daemon does not pin.
      const long pinned = std::count(lists.begin(), lists.end(), expected);
      EXPECT_GE(pinned, static_cast<long>(lists.size()) - (test::underEmulator() ? 1 : 0))
          << "threads on other CPUs than " << expected;
    }
    ::kill(pid, SIGTERM);
    EXPECT_EQ(waitExit(pid, 20), 0) << log;
  }
}

TEST(McslamdProcess, ImageCodecIsMappedOnlyWhenTheReplayMeetsAPng) {
  test::TempDir dir("mcslamd-codec");
  test::writeSmallPgmDataset(dir.file("pgm"), 2, 5);  // and its PNG original in pgm_png
  for (const std::string data : {"pgm", "pgm_png"}) {
    NotifyListener notify(dir.file(data + ".sock"));
    ASSERT_TRUE(notify.ok());
    const std::string config = test::writeFile(
        dir.file(data + ".yaml"),
        "status_interval_s: 0.1\nsource:\n  type: dataset\n  dataset:\n    path: " + data +
            "\n    rate: fastest\n    at_end: loop\npublish:\n  shm:\n    enabled: false\noutput:\n  directory: .\n");
    const std::string log = dir.file(data + ".log");
    const pid_t pid = spawnDaemon(config, dir.file(data + ".sock"), "400000", log);
    const ReapOnExit reap_pid(pid);
    // WATCHDOG=1 is sent only once frames are processed: their images were read by then.
    ASSERT_TRUE(waitFor([&] { return notify.count("WATCHDOG=1") >= 1; })) << readAll(log);
    const std::string maps = readAll("/proc/" + std::to_string(pid) + "/maps");
    const bool png = data == "pgm_png";
    EXPECT_EQ(maps.find("libopencv_imgcodecs") != std::string::npos, png) << data;
    EXPECT_EQ(maps.find("mcslam_image_codec.so") != std::string::npos, png) << data;
    ::kill(pid, SIGTERM);
    EXPECT_EQ(waitExit(pid, 20), 0) << readAll(log);
  }
}

TEST(McslamdProcess, BadConfigEndsStartupWithOneMessageNamingTheKey) {
  test::TempDir dir("mcslamd-bad");
  test::writeSmallDataset(dir.file("data"), 2, 2);
  const std::string config =
      test::writeFile(dir.file("bad.yaml"),
                      "source:\n  type: dataset\n  dataset:\n    path: data\ncapacities:\n  pose_ring_slots: 0\n");
  std::string out;
  const int rc = test::runCommand(test::binPath("mcslamd") + " --config " + config, &out);
  EXPECT_EQ(rc, 2) << out;
  EXPECT_NE(out.find("capacities.pose_ring_slots"), std::string::npos) << out;
  EXPECT_NE(out.find(config), std::string::npos) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << "one message:\n" << out;
  const int check_rc = test::runCommand(test::binPath("mcslamd") + " --check-config " + config, &out);
  EXPECT_EQ(check_rc, 2) << out;
}

TEST(McslamdProcess, CheckConfigPrintsTheEffectiveConfiguration) {
  test::TempDir dir("mcslamd-check");
  test::writeSmallDataset(dir.file("data"), 2, 2);
  const std::string config =
      test::writeFile(dir.file("ok.yaml"), "source:\n  type: dataset\n  dataset:\n    path: data\n");
  std::string out;
  ASSERT_EQ(test::runCommand(test::binPath("mcslamd") + " --check-config " + config, &out), 0) << out;
  for (const char* key : {"rig_ring_slots: 2", "pose_ring_slots: 64", "name: /mcslam_pose", "mode: free_running",
                          "slam:", "rig: 2 camera"})
    EXPECT_NE(out.find(key), std::string::npos) << key << " missing in:\n" << out;
}

TEST(McslamdProcess, ShippedSimConfigChecksOutWithoutADataset) {
  const std::string config = test::dataPath("../../config/mcslamd-sim.yaml");
  std::string out;
  ASSERT_EQ(test::runCommand(test::binPath("mcslamd") + " --check-config " + config, &out), 0) << out;
  for (const char* key : {"type: sim", "world: indoor", "cameras: [0, 1, 2, 3, 4]", "rig: 5 camera"})
    EXPECT_NE(out.find(key), std::string::npos) << key << " missing in:\n" << out;
}

namespace {

// The frames [first, end) of an ASL dataset as a dataset of their own (same stamps, images linked): a robot that
// restarts further along its route.
std::string datasetTail(const std::string& data, const std::string& out, int first) {
  namespace fs = std::filesystem;
  fs::create_directories(out);
  fs::copy_file(fs::path(data) / "camchain.yaml", fs::path(out) / "camchain.yaml");
  for (int c = 0;; ++c) {
    const fs::path cam = fs::path(data) / ("cam" + std::to_string(c));
    if (!fs::exists(cam)) break;
    fs::create_directories(fs::path(out) / cam.filename());
    fs::create_directory_symlink(cam / "data", fs::path(out) / cam.filename() / "data");
    std::ifstream in(cam / "data.csv");
    std::ofstream csv(fs::path(out) / cam.filename() / "data.csv");
    std::string line;
    for (int row = -1; std::getline(in, line); ++row)
      if (row < 0 || line[0] == '#' || row >= first) csv << line << "\n";
  }
  return out;
}

// The saves the last status line counts.
uint64_t lastMapSaves(const std::string& log) {
  const std::size_t at = log.rfind("map saves ");
  return at == std::string::npos ? 0 : std::stoull(log.substr(at + 10));
}

std::string mapConfig(const std::string& data, const std::string& out, const std::string& map, const char* at_end,
                      const std::string& extra = "") {
  return "log_level: info\nstatus_interval_s: 0.2\nsource:\n  type: dataset\n  dataset:\n    path: " + data +
         "\n    rate: fastest\n    at_end: " + at_end + "\npublish:\n  shm:\n    enabled: false\n" +
         "output:\n  directory: " + out + "\nmap:\n  load: " + map + "\n  save: " + map + "\n  save_interval_s: 0.3\n" +
         extra;
}

}  // namespace

// systemd's restart after a crash: the daemon saves its map as it goes; SIGKILL ends it; started again (further
// along the route, with the same configuration) it loads the map, recognizes where it is and publishes poses in
// the same world frame as before the crash. Without the map the new run's frame would start at the robot's
// pose there, 2.5 m away.
TEST(McslamdProcess, AfterACrashTheRestartedDaemonKeepsTheWorldFrame) {
  const std::string data = test::cachedSimDataset();
  test::TempDir dir("mcslamd-restart");
  const std::string map = dir.file("robot.mcmap");
  std::filesystem::create_directories(dir.file("out1"));
  std::filesystem::create_directories(dir.file("out2"));
  const std::string first = test::writeFile(dir.file("first.yaml"), mapConfig(data, dir.file("out1"), map, "loop"));
  const pid_t pid = spawnDaemon(first, dir.file("none.sock"), "0", dir.file("log1.txt"));
  const ReapOnExit reap_pid(pid);
  ASSERT_GT(pid, 0);
  // A save made after the whole route was mapped once (the map file is replaced whole, never partly written).
  ASSERT_TRUE(waitFor([&] { return readTumRows(dir.file("out1/trajectory.tum")).size() >= 60; }, 120))
      << readAll(dir.file("log1.txt"));
  const uint64_t saves = lastMapSaves(readAll(dir.file("log1.txt")));
  ASSERT_TRUE(waitFor([&] { return lastMapSaves(readAll(dir.file("log1.txt"))) >= saves + 2; }, 60))
      << readAll(dir.file("log1.txt"));
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(std::filesystem::exists(map));
  EXPECT_FALSE(std::filesystem::exists(map + ".tmp"));

  const std::string tail = datasetTail(data, dir.file("tail"), 25);
  const std::string second = test::writeFile(dir.file("second.yaml"), mapConfig(tail, dir.file("out2"), map, "exit"));
  const pid_t again = spawnDaemon(second, dir.file("none.sock"), "0", dir.file("log2.txt"));
  const ReapOnExit reap_again(again);
  ASSERT_EQ(waitExit(again, 120), 0) << readAll(dir.file("log2.txt"));
  const std::string log2 = readAll(dir.file("log2.txt"));
  EXPECT_NE(log2.find("recognized in the map"), std::string::npos) << log2;

  // Same stamps in both runs: the restarted run's poses against the first run's (its first pass over the route).
  const Trajectory before = readTumTrajectory(dir.file("out1/trajectory.tum"));
  const Trajectory after = readTumTrajectory(dir.file("out2/trajectory.tum"));
  ASSERT_GE(after.size(), 20u) << log2;
  // Every pose within decimetres of the first run's (two estimates of the same place), on average centimetres.
  int compared = 0;
  double sum = 0;
  for (const auto& pose : after) {
    for (const auto& reference : before) {
      if (reference.t != pose.t) continue;
      const double d = (reference.T_w_b.t - pose.T_w_b.t).norm();
      EXPECT_LT(d, 0.3) << "t = " << toSeconds(pose.t);
      sum += d;
      ++compared;
      break;
    }
  }
  ASSERT_GE(compared, 20);
  EXPECT_LT(sum / compared, 0.05);
}

// A map file that cannot be read ends start-up with one message naming it, unless the configuration says to start
// without it; then the file is set aside (not overwritten by the next save) and the daemon maps anew.
TEST(McslamdProcess, AnUnreadableMapStopsStartUpOrIsSetAsideWhenConfigured) {
  test::TempDir dir("mcslamd-badmap");
  const std::string data = test::writeSmallDataset(dir.file("data"), 2, 5);
  const std::string map = test::writeFile(dir.file("robot.mcmap"), "MCSLMAP\1 not a map");
  const std::string strict = test::writeFile(dir.file("strict.yaml"), mapConfig(data, dir.file("."), map, "exit"));
  std::string out;
  EXPECT_EQ(test::runCommand(test::binPath("mcslamd") + " --config " + strict, &out), 2);
  EXPECT_NE(out.find(map + ": not an mcslam map file"), std::string::npos) << out;
  const std::string lenient = test::writeFile(
      dir.file("lenient.yaml"), mapConfig(data, dir.file("."), map, "exit", "  on_unreadable: start_empty\n"));
  EXPECT_EQ(test::runCommand(test::binPath("mcslamd") + " --config " + lenient, &out), 0) << out;
  EXPECT_NE(out.find("starting without a map"), std::string::npos) << out;
  EXPECT_EQ(test::readFile(map + ".unreadable"), "MCSLMAP\1 not a map");
}
