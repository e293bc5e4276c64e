// mcslamd's shared memory across daemons, as processes: a reader holding the segment of a daemon that was
// SIGKILLed sees the writer gone, then the restarted daemon's segment replace it, reattaches and reads the new
// poses (the same reader object); a daemon whose segment is truncated goes on in a new one; a second daemon with the
// same name refuses to start (exit 3, naming the first one's pid) and leaves the first one's segment alone; a name
// another user owns ends start-up with exit 3 (systemd restarts it; 2 it would not), naming the owner; a mode that lets
// others write fails --check-config.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>

#include "child_process.hpp"
#include "daemon_fixture.hpp"
#include "emulation.hpp"
#include "mcslam/pose_shm.hpp"
#include "shm_test_segments.hpp"
#include "test_support.hpp"

using namespace mcslam;
using pose::SegmentStatus;

namespace {
// A replay of a small dataset, looped as fast as it goes, publishing in the segment `shm`.
std::string daemonConfig(const test::TempDir& dir, const std::string& shm, const std::string& mode = "0644",
                         const std::string& udp_destination = "") {
  const std::string data = test::writeSmallDataset(dir.file("data"), 2, 20);
  std::filesystem::create_directories(dir.file("out"));
  return test::writeFile(
      dir.file("mcslamd.yaml"),
      "log_level: info\nsource:\n  type: dataset\n  dataset:\n    path: " + data +
          "\n    rate: fastest\n    at_end: loop\n" + "publish:\n  shm:\n    name: " + shm + "\n    mode: \"" + mode +
          "\"\n    ring_length: 64\n" +
          (udp_destination.empty() ? "" : "  udp:\n    destinations: [\"" + udp_destination + "\"]\n") +
          "output:\n  directory: " + dir.file("out") + "\n");
}

std::unique_ptr<test::ChildProcess> startDaemon(const std::string& config, const test::TempDir& dir,
                                                const std::string& tag, int uid = -1) {
  return std::make_unique<test::ChildProcess>(std::vector<std::string>{test::binPath("mcslamd"), "--config", config},
                                              dir.file(tag + ".out"), dir.file(tag + ".err"), uid);
}

std::string logsOf(const test::TempDir& dir, const std::string& tag) {
  return test::readFile(dir.file(tag + ".out")) + test::readFile(dir.file(tag + ".err"));
}
}  // namespace

TEST(ShmRestart, AReaderFollowsTheDaemonThroughACrashAndARestart) {
  test::TempDir dir("shm-restart");
  const std::string shm = test::uniqueShmName("restart");
  const std::string config = daemonConfig(dir, shm);
  auto first = startDaemon(config, dir, "first");
  pose::PoseShmReader reader;
  ASSERT_TRUE(test::eventually([&] { return reader.open(shm) && reader.published() >= 5; })) << logsOf(dir, "first");
  EXPECT_EQ(reader.writerPid(), first->pid());
  EXPECT_EQ(reader.check(), SegmentStatus::Live);
  pose::PoseRecord r;
  ASSERT_EQ(reader.readLatest(r), pose::ReadStatus::Ok);

  ASSERT_TRUE(first->signal(SIGKILL));
  EXPECT_EQ(first->wait(), 128 + SIGKILL);
  EXPECT_TRUE(reader.writerRunning());  // the header still says so: `state` alone cannot tell a crash
  EXPECT_EQ(reader.check(), SegmentStatus::WriterGone);

  auto second = startDaemon(config, dir, "second");
  ASSERT_TRUE(test::eventually([&] { return reader.check() == SegmentStatus::Replaced; })) << logsOf(dir, "second");
  // The new segment may still be being made: reattach until it is whole.
  ASSERT_TRUE(test::eventually([&] { return reader.reattach() && reader.check() == SegmentStatus::Live; }))
      << logsOf(dir, "second");
  EXPECT_EQ(reader.writerPid(), second->pid());
  ASSERT_TRUE(test::eventually([&] { return reader.published() >= 5; })) << logsOf(dir, "second");
  const uint64_t newest = reader.published();
  ASSERT_EQ(reader.readSequence(newest, r), pose::ReadStatus::Ok);
  EXPECT_EQ(r.sequence, newest);
  ASSERT_EQ(reader.readLatest(r), pose::ReadStatus::Ok);
  EXPECT_GE(r.sequence, newest);

  ASSERT_TRUE(second->signal(SIGTERM));
  EXPECT_EQ(second->wait(), 0) << logsOf(dir, "second");
  EXPECT_EQ(reader.check(), SegmentStatus::Stopped);
  EXPECT_FALSE(pose::PoseShmReader().open(shm));  // its clean stop removed its own name
}

// A truncation of the segment must not end the daemon with SIGBUS at its next pose.
TEST(ShmRestart, ADaemonWhoseSegmentIsTruncatedGoesOnInANewOne) {
  test::TempDir dir("shm-truncated");
  const std::string shm = test::uniqueShmName("truncated");
  auto daemon = startDaemon(daemonConfig(dir, shm), dir, "daemon");
  pose::PoseShmReader::guardAgainstTruncation();
  pose::PoseShmReader reader;
  ASSERT_TRUE(test::eventually([&] { return reader.open(shm) && reader.published() >= 1; })) << logsOf(dir, "daemon");
  ASSERT_TRUE(test::truncateSegment(shm));
  EXPECT_EQ(reader.check(), SegmentStatus::Truncated);
  ASSERT_TRUE(test::eventually([&] { return reader.reattach() && reader.check() == SegmentStatus::Live; }))
      << logsOf(dir, "daemon");
  EXPECT_EQ(reader.writerPid(), daemon->pid());
  const uint64_t first = reader.published();
  ASSERT_TRUE(test::eventually([&] { return reader.published() > first; })) << logsOf(dir, "daemon");
  EXPECT_NE(logsOf(dir, "daemon").find("was truncated by another process"), std::string::npos) << logsOf(dir, "daemon");
  ASSERT_TRUE(daemon->signal(SIGTERM));
  EXPECT_EQ(daemon->wait(), 0) << logsOf(dir, "daemon");
  EXPECT_NE(logsOf(dir, "daemon").find("segments made anew after a truncation by another process: 1"),
            std::string::npos)
      << logsOf(dir, "daemon");
}

// A second daemon must not unlink the first one's live segment, nor the first one's stop the second one's.
TEST(ShmRestart, ASecondDaemonRefusesTheNameOfARunningOne) {
  test::TempDir dir("shm-second");
  const std::string shm = test::uniqueShmName("second");
  const std::string config = daemonConfig(dir, shm);
  auto first = startDaemon(config, dir, "first");
  pose::PoseShmReader reader;
  ASSERT_TRUE(test::eventually([&] { return reader.open(shm) && reader.published() >= 1; })) << logsOf(dir, "first");

  auto second = startDaemon(config, dir, "second");
  ASSERT_TRUE(second->endsWithin(60)) << "the second daemon runs beside the first";
  const std::string log = logsOf(dir, "second");
  EXPECT_EQ(second->wait(), 3) << log;
  EXPECT_NE(log.find(shm), std::string::npos) << log;
  EXPECT_NE(log.find("pid " + std::to_string(first->pid())), std::string::npos) << log;
  EXPECT_EQ(reader.check(), SegmentStatus::Live);

  ASSERT_TRUE(first->signal(SIGTERM));
  EXPECT_EQ(first->wait(), 0) << logsOf(dir, "first");
  EXPECT_EQ(reader.check(), SegmentStatus::Stopped);
}

// Not exit 2 ("bad configuration"), which the unit's RestartPreventExitStatus=2 never restarts.
TEST(ShmRestart, ANameAnotherUserOwnsEndsStartUpWithARestartableStatus) {
  if (::getuid() != 0) GTEST_SKIP() << "needs root to act as two users";
  if (test::underEmulator()) GTEST_SKIP() << "user nobody cannot read the emulator's arm64 root (in root's home)";
  test::TempDir dir("shm-owner");
  const std::string shm = test::uniqueShmName("owner");
  const std::string config = daemonConfig(dir, shm);
  std::filesystem::permissions(dir.path(), std::filesystem::perms::all);  // the daemon runs as nobody
  std::filesystem::permissions(dir.file("out"), std::filesystem::perms::all);
  ::shm_unlink(shm.c_str());
  const int fd = ::shm_open(shm.c_str(), O_CREAT | O_EXCL | O_RDWR, 0600);  // root's
  ASSERT_GE(fd, 0);
  ::close(fd);
  auto daemon = startDaemon(config, dir, "nobody", 65534);
  ASSERT_TRUE(daemon->endsWithin(60)) << logsOf(dir, "nobody");
  const std::string log = logsOf(dir, "nobody");
  EXPECT_EQ(daemon->wait(), 3) << log;
  EXPECT_NE(log.find(shm), std::string::npos) << log;
  EXPECT_NE(log.find("uid 0"), std::string::npos) << log;
  ::shm_unlink(shm.c_str());
}

TEST(ShmRestart, AModeLettingOthersWriteFailsTheConfigCheck) {
  test::TempDir dir("shm-mode");
  const std::string config = daemonConfig(dir, test::uniqueShmName("mode"), "0666");
  std::string out;
  EXPECT_EQ(test::runCommand(test::binPath("mcslamd") + " --check-config " + config, &out), 2);
  EXPECT_NE(out.find("publish.shm.mode"), std::string::npos) << out;
  EXPECT_NE(out.find("0666"), std::string::npos) << out;
  EXPECT_NE(out.find(config), std::string::npos) << out;
}

// The UDP consumer written from docs/pose-protocol.md alone (tools/pose_client.py) goes on through a daemon's crash
// and restart and says so: the new run's sequence starts at 1 again (the document's rule 4).
TEST(ShmRestart, TheDocumentsUdpConsumerRecognizesARestartedDaemon) {
  if (test::runCommand("python3 --version") != 0) GTEST_SKIP() << "python3 is not installed";
  test::TempDir dir("udp-restart");
  const std::string script = std::string(MCSLAM_TEST_DATA_DIR) + "/../../tools/pose_client.py";
  test::ChildProcess client(
      {"/usr/bin/env", "python3", script, "--bind", "127.0.0.1", "--port", "0", "--timeout", "60"},
      dir.file("client.out"), dir.file("client.err"));
  std::string port;
  ASSERT_TRUE(test::eventually([&] {
    const std::string hello = test::readFile(dir.file("client.err"));  // "listening on 127.0.0.1:PORT"
    const auto colon = hello.rfind(':'), end = hello.find('\n');
    if (colon == std::string::npos || end == std::string::npos || end < colon) return false;
    port = hello.substr(colon + 1, end - colon - 1);
    return true;
  }));
  const std::string config = daemonConfig(dir, test::uniqueShmName("udp-restart"), "0644", "127.0.0.1:" + port);
  const auto lines = [&] { return test::lineCount(test::readFile(dir.file("client.out"))); };
  auto first = startDaemon(config, dir, "first");
  ASSERT_TRUE(test::eventually([&] { return lines() >= 100; })) << logsOf(dir, "first");
  ASSERT_TRUE(first->signal(SIGKILL));
  first->wait();
  const int before = lines();
  auto second = startDaemon(config, dir, "second");
  ASSERT_TRUE(test::eventually([&] {
    return test::readFile(dir.file("client.err")).find("pose_client: the daemon restarted (sequence ") !=
           std::string::npos;
  })) << logsOf(dir, "second")
      << test::readFile(dir.file("client.err"));
  ASSERT_TRUE(test::eventually([&] { return lines() > before + 5; }));  // and goes on printing the new run's poses
  unsigned long long sequence = 0, highest = 0;
  const std::string err = test::readFile(dir.file("client.err"));
  ASSERT_EQ(
      std::sscanf(err.c_str() + err.find("restarted"), "restarted (sequence %llu after %llu)", &sequence, &highest), 2)
      << err;
  EXPECT_LT(sequence + 64, highest) << err;
  ASSERT_TRUE(second->signal(SIGTERM));
  EXPECT_EQ(second->wait(), 0) << logsOf(dir, "second");
}
