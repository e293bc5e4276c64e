// sd_notify datagrams, UDP pose datagrams, the TUM trajectory writer, pixel conversion and the background threads'
// scheduling class.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "aravis/pixel_convert.hpp"
#include "daemon/trajectory_writer.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/core/background_task.hpp"
#include "mcslam/core/error.hpp"
#include "realtime/scheduling.hpp"
#include "systemd/notifier.hpp"
#include "test_support.hpp"
#include "udp/udp_pose_sender.hpp"

using namespace mcslam;
using namespace mcslam::platform;

namespace {
int boundUnixSocket(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM, 0);
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  std::snprintf(a.sun_path, sizeof(a.sun_path), "%s", path.c_str());
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0) return -1;
  timeval tv{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  return fd;
}

std::string receiveText(int fd) {
  char buf[1024];
  const ssize_t n = ::recv(fd, buf, sizeof(buf), 0);
  return n > 0 ? std::string(buf, n) : std::string();
}
}  // namespace

TEST(SystemdNotifier, SendsReadyWatchdogAndStatusToNotifySocket) {
  test::TempDir dir("notify");
  const std::string path = dir.file("notify.sock");
  const int fd = boundUnixSocket(path);
  ASSERT_GE(fd, 0);
  ::setenv("NOTIFY_SOCKET", path.c_str(), 1);
  ::setenv("WATCHDOG_USEC", "3000000", 1);
  ::unsetenv("WATCHDOG_PID");
  SystemdNotifier n;
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");
  ASSERT_TRUE(n.enabled());
  EXPECT_EQ(n.watchdogIntervalUs(), 3000000);
  EXPECT_TRUE(n.ready());
  EXPECT_EQ(receiveText(fd), "READY=1");
  EXPECT_TRUE(n.watchdog());
  EXPECT_EQ(receiveText(fd), "WATCHDOG=1");
  EXPECT_TRUE(n.status("20.0 Hz\ntracking"));
  EXPECT_EQ(receiveText(fd), "STATUS=20.0 Hz tracking");
  ::close(fd);
}

TEST(SystemdNotifier, WithoutNotifySocketEverythingIsANoOp) {
  ::unsetenv("NOTIFY_SOCKET");
  SystemdNotifier n;
  EXPECT_FALSE(n.enabled());
  EXPECT_FALSE(n.ready());
}

TEST(UdpPoseSender, EveryDestinationGetsOneDecodableDatagramPerPose) {
  const test::UdpReceiver rx(INADDR_LOOPBACK, 5000);
  ASSERT_GE(rx.fd(), 0);
  const std::string dest = "127.0.0.1:" + std::to_string(rx.port());
  UdpPoseSender sender({resolveUdpDestination(dest, "publish.udp.destinations")});
  pose::PoseRecord r;
  r.sequence = 11;
  r.position[1] = 2.5;
  sender.send(r);
  uint8_t buf[256];
  const ssize_t n = ::recv(rx.fd(), buf, sizeof(buf), 0);
  ASSERT_EQ(n, static_cast<ssize_t>(pose::kPacketSize));
  pose::PoseRecord d;
  ASSERT_EQ(pose::decodePacket(buf, static_cast<std::size_t>(n), d), pose::DecodeStatus::Ok);
  EXPECT_EQ(d.sequence, 11u);
  EXPECT_EQ(d.position[1], 2.5);
  EXPECT_EQ(sender.sent(), 1u);
}

// A broadcast destination needs SO_BROADCAST (without it every send fails with EACCES): loopback's broadcast
// address reaches a socket bound to any address.
TEST(UdpPoseSender, ABroadcastDestinationIsSentTo) {
  const test::UdpReceiver rx(INADDR_ANY, 5000);
  ASSERT_GE(rx.fd(), 0);
  const std::string dest = "127.255.255.255:" + std::to_string(rx.port());
  UdpPoseSender sender({resolveUdpDestination(dest, "publish.udp.destinations")});
  pose::PoseRecord r;
  r.sequence = 7;
  sender.send(r);
  EXPECT_EQ(sender.failed(), 0u) << std::strerror(sender.lastErrno());
  EXPECT_EQ(sender.sent(), 1u);
  uint8_t buf[256];
  EXPECT_EQ(::recv(rx.fd(), buf, sizeof(buf), 0), static_cast<ssize_t>(pose::kPacketSize));
}

TEST(UdpPoseSender, BadDestinationsNameTheKeyAndTheText) {
  for (const char* bad : {"localhost", "127.0.0.1:0", "127.0.0.1:99999", "no-such-host.invalid:9000", "[::1]9000"}) {
    try {
      resolveUdpDestination(bad, "publish.udp.destinations");
      FAIL() << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("publish.udp.destinations"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(TrajectoryWriter, WritesExactTumLinesAndKeepsThePreviousFile) {
  test::TempDir dir("traj");
  const std::string path = dir.file("trajectory.tum");
  test::writeFile(path, "old run\n");
  pose::PoseRecord r;
  r.capture_time_ns = 1403636579763555584ll;
  r.position[0] = 0.1;
  r.position[1] = -1e-7;
  r.position[2] = 3;
  r.orientation[0] = 0;
  r.orientation[1] = 0;
  r.orientation[2] = std::sqrt(0.5);
  r.orientation[3] = std::sqrt(0.5);
  {
    TrajectoryWriter w(path);
    alloc::ThreadScope scope;
    EXPECT_TRUE(w.append(r));
    EXPECT_EQ(scope.count(), 0u);
    EXPECT_EQ(w.written(), 1u);
  }
  std::ifstream in(path);
  std::string header, line;
  std::getline(in, header);
  std::getline(in, line);
  EXPECT_EQ(header[0], '#');
  std::istringstream fields(line);
  std::string t;
  double v[7];
  fields >> t;
  for (double& x : v) fields >> x;
  EXPECT_EQ(t, "1403636579.763555584");
  EXPECT_EQ(v[0], 0.1);  // shortest round-trip text reads back to the same double
  EXPECT_EQ(v[1], -1e-7);
  EXPECT_EQ(v[5], std::sqrt(0.5));
  std::ifstream previous(path + ".previous");
  std::getline(previous, line);
  EXPECT_EQ(line, "old run");
}

TEST(TrajectoryWriter, UnwritablePathNamesTheKey) {
  try {
    TrajectoryWriter w("/proc/mcslam-no/trajectory.tum");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("output.trajectory"), std::string::npos) << e.what();
  }
}

namespace {
pose::PoseRecord recordAt(int i) {
  pose::PoseRecord r;
  r.capture_time_ns = 1000000000ll * (i + 1);
  r.position[0] = 0.25 * i;
  r.orientation[3] = 1;
  return r;
}

// Every line of the file, and whether the last one ends with its newline.
std::vector<std::string> fileLines(const std::string& path, bool* ends_with_newline) {
  const std::string text = test::readFile(path);
  *ends_with_newline = text.empty() || text.back() == '\n';
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The process's file size limit for one scope: a write across it is cut short (the way a full disk cuts it) and
// fails with EFBIG after it; SIGXFSZ, which would end the process, is ignored meanwhile.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    previous_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = saved_;
    limit.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, previous_handler_);
  }

 private:
  rlimit saved_{};
  void (*previous_handler_)(int) = nullptr;
};
}  // namespace

// A full disk cuts a pose's line short: the writer counts the pose, keeps the reason and cuts the file back to
// its last whole line, so that once space returns the next pose starts a line of its own.
TEST(TrajectoryWriter, AFullDiskLeavesNoTornLineAndWritingGoesOnWhenSpaceReturns) {
  test::TempDir dir("traj-full");
  const std::string path = dir.file("trajectory.tum");
  TrajectoryWriter w(path);
  ASSERT_TRUE(w.append(recordAt(0)));
  const auto whole = static_cast<rlim_t>(test::readFile(path).size());
  {
    const FileSizeLimit limit(whole + 10);  // room for 10 bytes of the next line
    EXPECT_FALSE(w.append(recordAt(1)));
    EXPECT_FALSE(w.append(recordAt(2)));
  }
  EXPECT_EQ(w.errors(), 2u);
  EXPECT_EQ(w.lastErrno(), EFBIG);
  EXPECT_EQ(test::readFile(path).size(), whole) << "the torn line is cut off";
  ASSERT_TRUE(w.append(recordAt(3)));
  EXPECT_TRUE(w.sync());
  bool newline = false;
  const std::vector<std::string> lines = fileLines(path, &newline);
  EXPECT_TRUE(newline);
  ASSERT_EQ(lines.size(), 3u);  // the header, pose 0, pose 3
  EXPECT_EQ(lines[1].rfind("1.000000000 ", 0), 0u) << lines[1];
  EXPECT_EQ(lines[2].rfind("4.000000000 0.75 ", 0), 0u) << lines[2];
  EXPECT_EQ(w.written(), 2u);
}

TEST(TrajectoryWriter, OnADeviceThatIsAlwaysFullEveryPoseCountsAsAnError) {
  if (::access("/dev/full", W_OK) != 0) GTEST_SKIP() << "/dev/full is not writable here";
  TrajectoryWriter w("/dev/full");
  EXPECT_FALSE(w.append(recordAt(0)));
  EXPECT_EQ(w.lastErrno(), ENOSPC);
  EXPECT_EQ(w.errors(), 2u);  // the header and the pose
  EXPECT_EQ(w.written(), 0u);
}

// A trajectory file removed while it is written (its folder cleaned up) is made again at the same path; with its
// folder gone too, each pose counts as an error until the folder is back.
TEST(TrajectoryWriter, ARemovedFileIsMadeAgainAndAMissingFolderCountsEachPose) {
  test::TempDir dir("traj-removed");
  const std::string folder = dir.file("out");
  std::filesystem::create_directories(folder);
  const std::string path = folder + "/trajectory.tum";
  TrajectoryWriter w(path);
  ASSERT_TRUE(w.append(recordAt(0)));
  std::filesystem::remove_all(folder);
  EXPECT_FALSE(w.append(recordAt(1)));
  EXPECT_FALSE(w.append(recordAt(2)));
  EXPECT_EQ(w.errors(), 2u);
  EXPECT_EQ(w.lastErrno(), ENOENT);
  std::filesystem::create_directories(folder);
  ASSERT_TRUE(w.append(recordAt(3)));
  EXPECT_EQ(w.reopened(), 1u);
  bool newline = false;
  const std::vector<std::string> lines = fileLines(path, &newline);
  ASSERT_EQ(lines.size(), 2u);  // a header and pose 3
  EXPECT_EQ(lines[0][0], '#');
  EXPECT_EQ(lines[1].rfind("4.000000000 ", 0), 0u) << lines[1];
}

TEST(PixelConvert, BayerPatternsGiveTheGreyOfTheirColour) {
  // A uniform colour (R, G, B) = (200, 100, 50) in each GenICam Bayer layout must come out as its
  // luminance 0.299 R + 0.587 G + 0.114 B = 124.2; swapping R and B would give 96.5.
  const int w = 16, h = 8;
  const struct {
    PixelLayout layout;
    const char* cell;  // top-left 2x2 cell, row-major
  } cases[] = {{PixelLayout::BayerRG8, "RGGB"},
               {PixelLayout::BayerGR8, "GRBG"},
               {PixelLayout::BayerGB8, "GBRG"},
               {PixelLayout::BayerBG8, "BGGR"}};
  for (const auto& c : cases) {
    std::vector<uint8_t> raw(w * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const char ch = c.cell[(y % 2) * 2 + (x % 2)];
        raw[y * w + x] = ch == 'R' ? 200 : ch == 'G' ? 100 : 50;
      }
    Image out(w, h);
    ASSERT_TRUE(convertToGrey(c.layout, raw.data(), raw.size(), w, h, out));  // warm-up (OpenCV's first call)
    alloc::ThreadScope scope;
    ASSERT_TRUE(convertToGrey(c.layout, raw.data(), raw.size(), w, h, out));
    EXPECT_EQ(scope.count(), 0u) << pixelLayoutName(c.layout);
    EXPECT_NEAR(out.data()[(h / 2) * w + w / 2], 124, 2) << pixelLayoutName(c.layout);
  }
}

TEST(PixelConvert, Mono8CopiesAndSizeMismatchIsRefused) {
  std::vector<uint8_t> raw(12);
  for (int i = 0; i < 12; ++i) raw[i] = static_cast<uint8_t>(i);
  Image out(4, 3);
  ASSERT_TRUE(convertToGrey(PixelLayout::Mono8, raw.data(), raw.size(), 4, 3, out));
  EXPECT_EQ(out.data()[11], 11);
  EXPECT_FALSE(convertToGrey(PixelLayout::Mono8, raw.data(), raw.size(), 5, 3, out));
  EXPECT_FALSE(convertToGrey(PixelLayout::Mono8, raw.data(), 10, 4, 3, out));
  EXPECT_THROW(pixelLayoutFromName("RGB8"), InputError);
}

namespace {
class RecordPolicy final : public BackgroundJob {
 public:
  void run() override { policy = sched_getscheduler(0); }
  int policy = -1;
};
}  // namespace

TEST(BackgroundScheduling, TheDaemonsSetupPutsTheCoresBackgroundThreadsInTheBatchClassOnly) {
  const int own_policy = sched_getscheduler(0);
  setBackgroundThreadSetup(&setUpBackgroundThread);
  RecordPolicy job;
  bool collected = false;
  {
    BackgroundTask task;
    task.start(job);
    collected = task.collect();
  }
  setBackgroundThreadSetup(nullptr);  // before any assertion can end the test
  ASSERT_TRUE(collected);
  EXPECT_EQ(job.policy, SCHED_BATCH);
  EXPECT_EQ(sched_getscheduler(0), own_policy);  // the thread that handed the job over keeps its class
}
