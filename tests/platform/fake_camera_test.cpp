// Aravis for real: mcslamd acquires from Aravis's fake GigE Vision camera (arv-fake-gv-camera-0.8 on
// 127.0.0.1, Debian package aravis-tools) in software-trigger mode, and frames flow through the whole
// daemon to shared memory; a camera that disappears is reopened when it comes back. Also: an unreachable
// camera, a trigger line the camera lacks and a missing GPIO chip end start-up with a message naming the key. Only
// loopback addresses are ever contacted.
#include <arv.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "daemon/daemon.hpp"
#include "daemon_fixture.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/pipeline/pipeline_factory.hpp"
#include "mcslam/pose_shm.hpp"
#include "test_support.hpp"

using namespace mcslam;
using namespace mcslam::platform;
using Clock = std::chrono::steady_clock;

namespace {
const char* kFakeCamera = "/usr/bin/arv-fake-gv-camera-0.8";

class FakeCamera {
 public:
  FakeCamera() {
    pid_ = test::forkDyingWithParent();
    if (pid_ == 0) {
      const int null = ::open("/dev/null", O_WRONLY);
      ::dup2(null, 1);
      ::dup2(null, 2);
      ::execl(kFakeCamera, kFakeCamera, "-i", "127.0.0.1", static_cast<char*>(nullptr));
      ::_exit(127);
    }
  }
  ~FakeCamera() {
    // arv-fake-gv-camera does not always end on SIGTERM, and a test must not wait for ever: a few seconds, then
    // SIGKILL.
    ::kill(pid_, SIGTERM);
    int status;
    for (int i = 0; i < 100; ++i) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, &status, 0);
  }
  // Liveness: until the camera answers on its control channel.
  bool waitReady() {
    const auto deadline = Clock::now() + std::chrono::seconds(20);
    while (Clock::now() < deadline) {
      GError* err = nullptr;
      ArvCamera* cam = arv_camera_new("127.0.0.1", &err);
      g_clear_error(&err);
      if (cam) {
        g_object_unref(cam);
        return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }

 private:
  pid_t pid_ = -1;
};

std::string readAll(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string aravisConfig(const std::string& calib, const std::string& camera_id, const std::string& extra) {
  return "calibration: " + calib +
         "\nsource:\n  type: aravis\n  aravis:\n    frame_timeout_ms: 3000\n    cameras:\n"
         "      - {id: \"" +
         camera_id + "\", exposure_us: 2000, gain_db: 1, pixel_format: Mono8}\n" + extra;
}
}  // namespace

TEST(FakeGigECamera, FramesFlowThroughTheWholeDaemonWithSoftwareTrigger) {
  if (::access(kFakeCamera, X_OK) != 0)
    GTEST_SKIP() << kFakeCamera << " not found: install the Debian package aravis-tools to run this test";
  test::TempDir dir("fakecam");
  const std::string calib = dir.file("camchain.yaml");
  writeKalibrRig(test::smallRig(1, 320, 240), calib);  // the fake camera's region is set to this
  auto camera = std::make_unique<FakeCamera>();
  ASSERT_TRUE(camera->waitReady()) << "the fake camera did not come up on 127.0.0.1";

  // 1. The mcslamd process: software trigger at 20 Hz, poses appear in shared memory; SIGTERM stops it.
  const std::string shm = "/mcslam-test-fakecam-" + std::to_string(getpid());
  const std::string config = test::writeFile(
      dir.file("mcslamd.yaml"), aravisConfig(calib, "127.0.0.1",
                                             "trigger:\n  mode: software\n  rate_hz: 20\nstatus_interval_s: 0.5\n"
                                             "publish:\n  shm:\n    name: " +
                                                 shm + "\noutput:\n  directory: " + dir.path().string() + "\n"));
  const pid_t pid = test::forkDyingWithParent();
  if (pid == 0) {
    const int fd = ::open(dir.file("log.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    const std::string bin = test::binPath("mcslamd");
    ::execl(bin.c_str(), bin.c_str(), "--config", config.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  pose::PoseShmReader reader;
  const auto deadline = Clock::now() + std::chrono::seconds(60);  // liveness only
  while (Clock::now() < deadline && !(reader.isOpen() && reader.published() >= 20)) {
    if (!reader.isOpen()) reader.open(shm);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(reader.isOpen()) << readAll(dir.file("log.txt"));
  ASSERT_GE(reader.published(), 20u) << readAll(dir.file("log.txt"));
  pose::PoseRecord first, last;
  const uint64_t newest = reader.published();
  ASSERT_EQ(reader.readSequence(newest - 19, first), pose::ReadStatus::Ok);
  ASSERT_EQ(reader.readSequence(newest, last), pose::ReadStatus::Ok);
  EXPECT_GT(last.frame_sequence, first.frame_sequence);  // trigger counts advance
  EXPECT_GT(last.capture_time_ns, first.capture_time_ns);
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const std::string log = readAll(dir.file("log.txt"));
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << log;
  EXPECT_NE(log.find("stopped:"), std::string::npos) << log;

  // 2. In-process, to read the counters: images arrive, are assembled and processed, and the daemon's
  //    threads (acquisition included) allocate nothing per frame after warm-up.
  {
    DaemonConfig c = parseDaemonConfig(aravisConfig(calib, "127.0.0.1",
                                                    "trigger:\n  mode: software\n  rate_hz: 50\nwarmup_frames: 20\n"
                                                    "publish:\n  shm:\n    enabled: false\noutput:\n  directory: " +
                                                        dir.path().string() + "\n"),
                                       dir.file("inproc.yaml"));
    Daemon d(c, createPipeline(c.slam, c.file, c.rig));
    d.start();
    const auto until = Clock::now() + std::chrono::seconds(60);
    while (Clock::now() < until && d.stats().frames_after_warmup < 100)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    d.stop();
    const DaemonStats s = d.stats();
    EXPECT_GE(s.frames_after_warmup, 100u);
    EXPECT_GT(s.camera_frames, 0u);
    EXPECT_EQ(s.bad_frames, 0u);
    EXPECT_EQ(s.allocations_after_warmup, 0u) << "over " << s.frames_after_warmup << " frames";
    EXPECT_EQ(s.partial_frames, 0u);
    std::printf("fake camera: %llu triggers, %llu images, %llu processed, latency p50 %.2f ms p99 %.2f ms\n",
                static_cast<unsigned long long>(s.triggers), static_cast<unsigned long long>(s.camera_frames),
                static_cast<unsigned long long>(s.processed), s.latency_p50_ns * 1e-6, s.latency_p99_ns * 1e-6);
  }

  // 3. A camera that disappears is reported lost and reopened; frames flow again once it is back,
  //    while the daemon keeps running.
  {
    DaemonConfig c = parseDaemonConfig(aravisConfig(calib, "127.0.0.1",
                                                    "trigger:\n  mode: software\n  rate_hz: 20\n"
                                                    "publish:\n  shm:\n    enabled: false\noutput:\n  directory: " +
                                                        dir.path().string() + "\n"),
                                       dir.file("lost.yaml"));
    c.aravis.frame_timeout_ms = 500;
    Daemon d(c, createPipeline(c.slam, c.file, c.rig));
    d.start();
    auto waitUntil = [&](auto pred) {
      const auto until = Clock::now() + std::chrono::seconds(60);  // liveness only
      while (Clock::now() < until && !pred()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
      return pred();
    };
    ASSERT_TRUE(waitUntil([&] { return d.stats().processed >= 10; }));
    camera.reset();  // the camera goes away
    ASSERT_TRUE(waitUntil([&] { return d.stats().lost_events >= 1; }));
    const uint64_t before = d.stats().processed;
    camera = std::make_unique<FakeCamera>();  // and comes back
    EXPECT_TRUE(waitUntil([&] { return d.stats().processed >= before + 10; })) << "frames did not flow again";
    d.stop();
    EXPECT_GE(d.stats().lost_events, 1u);
  }

  // 4. Hardware trigger: an input line the camera does not have is refused naming the key; with a line
  //    it has, the missing GPIO chip is what fails, naming trigger.gpio_chip.
  const std::string gpio_trigger =
      "trigger:\n  mode: gpio\n  rate_hz: 20\n  gpio_chip: gpiochip-mcslam-missing\n  gpio_line: 4\n"
      "output:\n  directory: " +
      dir.path().string() + "\n";
  std::string out;
  const std::string bad_line = test::writeFile(dir.file("line.yaml"), aravisConfig(calib, "127.0.0.1", gpio_trigger));
  EXPECT_EQ(test::runCommand(test::binPath("mcslamd") + " --config " + bad_line, &out), 2) << out;
  EXPECT_NE(out.find("source.aravis.cameras[0].trigger_line"), std::string::npos) << out;
  std::string with_line = aravisConfig(calib, "127.0.0.1", gpio_trigger);
  with_line.replace(with_line.find("pixel_format: Mono8}"), 20, "pixel_format: Mono8, trigger_line: Line0}");
  const std::string gpio = test::writeFile(dir.file("gpio.yaml"), with_line);
  EXPECT_EQ(test::runCommand(test::binPath("mcslamd") + " --config " + gpio, &out), 2) << out;
  EXPECT_NE(out.find("trigger.gpio_chip"), std::string::npos) << out;
  EXPECT_NE(out.find("gpiochip-mcslam-missing"), std::string::npos) << out;
}

TEST(FakeGigECamera, UnreachableCameraEndsStartupNamingTheKey) {
  test::TempDir dir("nocam");
  const std::string calib = dir.file("camchain.yaml");
  writeKalibrRig(test::smallRig(1, 320, 240), calib);
  // 127.0.0.3: a loopback address where no camera listens (the fake camera only binds 127.0.0.1).
  const std::string config = test::writeFile(dir.file("nocam.yaml"), aravisConfig(calib, "127.0.0.3", ""));
  std::string out;
  EXPECT_EQ(test::runCommand(test::binPath("mcslamd") + " --config " + config, &out), 2) << out;
  EXPECT_NE(out.find("source.aravis.cameras[0].id"), std::string::npos) << out;
  EXPECT_NE(out.find("127.0.0.3"), std::string::npos) << out;
}
