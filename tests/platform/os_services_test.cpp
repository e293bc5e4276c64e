// sd_notify datagrams, UDP pose datagrams, the TUM trajectory writer and pixel conversion.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "aravis/pixel_convert.hpp"
#include "daemon/trajectory_writer.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/core/error.hpp"
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
  const int rx = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(rx, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
  socklen_t len = sizeof(a);
  ::getsockname(rx, reinterpret_cast<sockaddr*>(&a), &len);
  timeval tv{5, 0};
  ::setsockopt(rx, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  const std::string dest = "127.0.0.1:" + std::to_string(ntohs(a.sin_port));
  UdpPoseSender sender({resolveUdpDestination(dest, "publish.udp.destinations")});
  pose::PoseRecord r;
  r.sequence = 11;
  r.position[1] = 2.5;
  sender.send(r);
  uint8_t buf[256];
  const ssize_t n = ::recv(rx, buf, sizeof(buf), 0);
  ASSERT_EQ(n, static_cast<ssize_t>(pose::kPacketSize));
  pose::PoseRecord d;
  ASSERT_EQ(pose::decodePacket(buf, static_cast<std::size_t>(n), d), pose::DecodeStatus::Ok);
  EXPECT_EQ(d.sequence, 11u);
  EXPECT_EQ(d.position[1], 2.5);
  EXPECT_EQ(sender.sent(), 1u);
  ::close(rx);
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
