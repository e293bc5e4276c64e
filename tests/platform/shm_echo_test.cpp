// mcslam-shm-echo when the segment misbehaves: a dead writer ends the wait with a message (never a wait without
// end), an inconsistent header ends it with one message (not a line per retry), a truncated segment does not kill
// it with SIGBUS, and a segment replaced under it (a restarted writer) is followed.
#include <gtest/gtest.h>

#include <memory>
#include <sstream>
#include <vector>

#include "child_process.hpp"
#include "shm/pose_shm_writer.hpp"
#include "shm_test_segments.hpp"
#include "test_support.hpp"

using namespace mcslam;

namespace {
// The `seq` of every printed pose.
std::vector<uint64_t> sequencesIn(const std::string& out) {
  std::vector<uint64_t> seqs;
  std::istringstream in(out);
  std::string word;
  while (in >> word)
    if (word == "seq" && in >> word) seqs.push_back(std::stoull(word));
  return seqs;
}

// mcslam-shm-echo on `writer`'s segment (with `options`) once `writer` published poses 1-3 and the echo printed
// them; null when it did not.
std::unique_ptr<test::ChildProcess> echoAfterThreePoses(platform::PoseShmWriter& writer, const test::TempDir& dir,
                                                        const std::vector<std::string>& options) {
  for (uint64_t s = 1; s <= 3; ++s) writer.publish(test::recordFor(s));
  std::vector<std::string> argv{test::binPath("mcslam-shm-echo"), "--name", writer.name()};
  argv.insert(argv.end(), options.begin(), options.end());
  auto echo = std::make_unique<test::ChildProcess>(argv, dir.file("out"), dir.file("err"));
  if (!test::eventually([&] { return test::lineCount(test::readFile(dir.file("out"))) == 3; })) return nullptr;
  return echo;
}

// `timeout` and `ulimit -f` bound the run for the old behaviour (waiting or printing for ever); not a measurement.
std::string echoCommand(const std::string& name, const std::string& args) {
  return "(ulimit -f 10000; timeout 60 " + test::binPath("mcslam-shm-echo") + " --name " + name + " " + args + ")";
}
}  // namespace

TEST(ShmEcho, ADeadWriterEndsTheWaitWithAMessage) {
  const std::string name = test::uniqueShmName("echo-dead");
  ASSERT_TRUE(test::makeSegment(name, test::deadPid(), 0));
  std::string out;
  EXPECT_EQ(test::runCommand(echoCommand(name, "--wait 0.2"), &out), 1) << out;
  EXPECT_NE(out.find("writer gone"), std::string::npos) << out;
  ::shm_unlink(name.c_str());
}

TEST(ShmEcho, AnInconsistentSegmentEndsWithOneMessage) {
  const std::string name = test::uniqueShmName("echo-garbage");
  // `published` far ahead, every slot garbage with an even (complete) sequence word; the writer (us) alive.
  ASSERT_TRUE(test::makeSegment(name, ::getpid(), 1000000, 8, 0x54));
  test::TempDir dir("shm-echo");
  const std::string out = dir.file("out"), err = dir.file("err");
  EXPECT_EQ(test::runCommand(echoCommand(name, "> " + out + " 2> " + err)), 1);
  const std::string errors = test::readFile(err);
  EXPECT_NE(errors.find("inconsistent segment"), std::string::npos) << errors;
  EXPECT_LE(test::lineCount(errors), 2) << errors.substr(0, 2000);
  EXPECT_LE(test::lineCount(test::readFile(out)), 8);
  ::shm_unlink(name.c_str());
}

// Every slot holds a whole record, but not the one `published` says: the old echo printed "missed poses" for
// ever, each time going back to the same place.
TEST(ShmEcho, RecordsNotMatchingTheirSlotsAreSkippedWithoutALineEach) {
  const std::string name = test::uniqueShmName("echo-mismatch");
  ASSERT_TRUE(test::makeSegment(name, ::getpid(), 1000, 8));
  uint8_t bytes[pose::kPacketSize];
  pose::encodePacket(test::recordFor(1), bytes);
  ASSERT_TRUE(test::editSegment(name, [&](pose::ShmHeader&, pose::ShmSlot* slots, uint32_t capacity) {
    for (uint32_t i = 0; i <= capacity; ++i) pose::seqlockWrite(slots[i], bytes);  // latest slot and ring
  }));
  ASSERT_TRUE(test::editSegment(name, [](pose::ShmHeader& h, pose::ShmSlot*, uint32_t) {
    h.state.store(pose::kWriterStopped);  // so that it ends once past `published`
  }));
  test::TempDir dir("shm-echo");
  const std::string out = dir.file("out"), err = dir.file("err");
  EXPECT_EQ(test::runCommand(echoCommand(name, "> " + out + " 2> " + err)), 0);
  const std::string errors = test::readFile(err);
  EXPECT_LE(test::lineCount(errors), 1) << errors.substr(0, 2000);
  EXPECT_EQ(test::lineCount(test::readFile(out)), 0);
  ::shm_unlink(name.c_str());
}

TEST(ShmEcho, ATruncatedSegmentDoesNotKillIt) {
  const std::string name = test::uniqueShmName("echo-trunc");
  platform::PoseShmWriter writer(name, 8, 0644);
  test::TempDir dir("shm-echo");
  const auto echo = echoAfterThreePoses(writer, dir, {"--wait", "0.2"});
  ASSERT_TRUE(echo);
  ASSERT_TRUE(test::truncateSegment(name));
  ASSERT_TRUE(echo->endsWithin(60));
  const std::string err = test::readFile(dir.file("err"));
  EXPECT_EQ(echo->wait(), 1) << err;  // not 128 + SIGBUS
  EXPECT_NE(err.find("truncated"), std::string::npos) << err;
}

TEST(ShmEcho, FollowsASegmentReplacedUnderIt) {
  const std::string name = test::uniqueShmName("echo-replaced");
  platform::PoseShmWriter first(name, 8, 0644);
  test::TempDir dir("shm-echo");
  const auto echo = echoAfterThreePoses(first, dir, {"--count", "5"});
  ASSERT_TRUE(echo);
  platform::PoseShmWriter second(name, 8, 0644);  // what a restarted daemon does
  for (uint64_t s = 1; s <= 2; ++s) second.publish(test::recordFor(s));
  ASSERT_TRUE(echo->endsWithin(60)) << test::readFile(dir.file("err"));
  const std::string err = test::readFile(dir.file("err"));
  EXPECT_EQ(echo->wait(), 0) << err;
  EXPECT_EQ(sequencesIn(test::readFile(dir.file("out"))), (std::vector<uint64_t>{1, 2, 3, 1, 2})) << err;
  EXPECT_NE(err.find("reattached"), std::string::npos) << err;
}
