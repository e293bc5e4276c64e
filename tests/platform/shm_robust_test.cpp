// The pose segment against careless and hostile neighbours: a mode that would let others write is refused; a
// truncated segment ends neither the writer nor a guarded reader with SIGBUS; a name a running writer holds is
// refused (naming its pid), one another user owns is reported with its uid, one a dead writer left is taken
// over; a stop unlinks only its own segment; and a reader's check() tells live, stopped, writer gone, replaced,
// name gone and truncated apart without allocating, and reattach() follows the name.
#include <gtest/gtest.h>

#include <functional>
#include <memory>

#include "alloc_testing.hpp"
#include "mcslam/core/error.hpp"
#include "shm/pose_shm_writer.hpp"
#include "shm_test_segments.hpp"

using namespace mcslam;
using pose::SegmentStatus;

namespace {
// The segment of `name`, whose writer is gone, is taken over by a writer made now: a reader of the old segment sees
// its writer gone, then the segment replaced; a new reader sees this process's live segment.
void expectTakenOverByANewWriter(const std::string& name) {
  pose::PoseShmReader old_reader;
  ASSERT_TRUE(old_reader.open(name));
  EXPECT_EQ(old_reader.check(), SegmentStatus::WriterGone);
  platform::PoseShmWriter writer(name, 4, 0644);
  EXPECT_EQ(old_reader.check(), SegmentStatus::Replaced);
  pose::PoseShmReader reader;
  ASSERT_TRUE(reader.open(name));
  EXPECT_EQ(reader.writerPid(), ::getpid());
  EXPECT_EQ(reader.header().writer_start_ticks, pose::processStartTicks(::getpid()));
  EXPECT_EQ(reader.check(), SegmentStatus::Live);
}

template <typename Error>
std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}
}  // namespace

TEST(PoseShmRobust, AModeLettingOthersWriteIsRefused) {
  const std::string name = test::uniqueShmName("mode");
  for (unsigned mode : {0666u, 0620u, 0602u, 0400u}) {
    char text[8];
    std::snprintf(text, sizeof(text), "%04o", mode);
    const std::string m = messageOf<InputError>([&] { platform::PoseShmWriter w(name, 4, mode); });
    EXPECT_NE(m.find("publish.shm.mode"), std::string::npos) << m;
    EXPECT_NE(m.find(text), std::string::npos) << m;
  }
  EXPECT_NO_THROW(platform::PoseShmWriter(name, 4, 0644));
}

// Without the guard, the first publish after the truncation would end the process with SIGBUS.
TEST(PoseShmRobustDeathTest, TheWriterSurvivesATruncationAndSaysSo) {
  const std::string name = test::uniqueShmName("trunc-writer");
  EXPECT_EXIT(
      {
        platform::PoseShmWriter writer(name, 8, 0644);
        for (uint64_t s = 1; s <= 3; ++s) writer.publish(test::recordFor(s));
        const bool lost_before = writer.lost();
        if (!test::truncateSegment(name)) std::_Exit(10);
        for (uint64_t s = 4; s <= 20; ++s) writer.publish(test::recordFor(s));
        if (lost_before || !writer.lost()) std::_Exit(11);
        writer.markStopped();  // the truncated file is still ours: its name goes
        pose::PoseShmReader reader;
        std::_Exit(reader.open(name) ? 12 : 0);
      },
      ::testing::ExitedWithCode(0), "");
  ::shm_unlink(name.c_str());  // in case the child failed before its stop
}

TEST(PoseShmRobustDeathTest, AGuardedReaderSurvivesATruncationAndSeesIt) {
  const std::string name = test::uniqueShmName("trunc-reader");
  EXPECT_EXIT(
      {
        platform::PoseShmWriter writer(name, 8, 0644);
        pose::PoseShmReader::guardAgainstTruncation();
        pose::PoseShmReader reader;
        if (!reader.open(name)) std::_Exit(10);
        for (uint64_t s = 1; s <= 5; ++s) writer.publish(test::recordFor(s));
        pose::PoseRecord r;
        if (reader.readLatest(r) != pose::ReadStatus::Ok || reader.check() != SegmentStatus::Live) std::_Exit(11);
        if (!test::truncateSegment(name)) std::_Exit(12);
        if (reader.readLatest(r) != pose::ReadStatus::NotYet) std::_Exit(13);  // zeros now
        std::_Exit(reader.check() == SegmentStatus::Truncated ? 0 : 14);
      },
      ::testing::ExitedWithCode(0), "");
  ::shm_unlink(name.c_str());  // the child ended without its writer's stop
}

TEST(PoseShmRobust, ANameARunningWriterHoldsIsRefusedWithItsPid) {
  const std::string name = test::uniqueShmName("live");
  const pid_t other = ::getppid();  // alive, and not us
  ASSERT_TRUE(test::makeSegment(name, other, 0));
  const std::string m = messageOf<platform::ResourceBusyError>([&] { platform::PoseShmWriter w(name, 4, 0644); });
  EXPECT_NE(m.find(name), std::string::npos) << m;
  EXPECT_NE(m.find("pid " + std::to_string(other)), std::string::npos) << m;
  pose::PoseShmReader reader;  // the running writer's segment is left alone
  ASSERT_TRUE(reader.open(name));
  EXPECT_EQ(reader.writerPid(), other);
  ::shm_unlink(name.c_str());
}

TEST(PoseShmRobust, ASegmentADeadWriterLeftIsTakenOver) {
  const std::string name = test::uniqueShmName("dead");
  ASSERT_TRUE(test::makeSegment(name, test::deadPid(), 7));
  expectTakenOverByANewWriter(name);
}

// A crashed writer's pid given to a later process: the start time the writer recorded tells them apart, so the
// name is taken over instead of being refused for as long as that process lives.
TEST(PoseShmRobust, APidReusedAfterACrashDoesNotHoldTheName) {
  const std::string name = test::uniqueShmName("reused");
  const pid_t other = ::getppid();  // alive, and not us
  const uint64_t its_start = pose::processStartTicks(other);
  ASSERT_GT(its_start, 0u) << "/proc/" << other << "/stat unreadable";
  EXPECT_TRUE(pose::writerProcessRuns(other, its_start));
  EXPECT_FALSE(pose::writerProcessRuns(other, its_start + 1));
  ASSERT_TRUE(test::makeSegment(name, other, 3));
  ASSERT_TRUE(test::editSegment(name, [&](pose::ShmHeader& h, pose::ShmSlot*, uint32_t) {
    h.writer_start_ticks = its_start + 1;  // the writer that made it started at another time
  }));
  expectTakenOverByANewWriter(name);
}

// A's stop must not unlink whatever has the name now, here B's live segment.
TEST(PoseShmRobust, AStopUnlinksOnlyItsOwnSegment) {
  const std::string name = test::uniqueShmName("own");
  platform::PoseShmWriter a(name, 4, 0644);
  ::shm_unlink(name.c_str());  // someone removed A's name, and B took it
  platform::PoseShmWriter b(name, 4, 0644);
  a.markStopped();
  pose::PoseShmReader reader;
  ASSERT_TRUE(reader.open(name));
  EXPECT_TRUE(reader.writerRunning());
  b.markStopped();
  EXPECT_FALSE(reader.open(name));
}

// Another user's file under the name: a non-root daemon may not remove it (sticky /dev/shm). The message names
// the owner, and the error is not a configuration error (mcslamd exits 3, which systemd restarts).
TEST(PoseShmRobustDeathTest, ANameAnotherUserOwnsIsReportedWithTheOwner) {
  if (::getuid() != 0) GTEST_SKIP() << "needs root to act as two users";
  const std::string name = test::uniqueShmName("other-user");
  ::shm_unlink(name.c_str());
  const int fd = ::shm_open(name.c_str(), O_CREAT | O_EXCL | O_RDWR, 0600);  // root's, not a pose segment
  ASSERT_GE(fd, 0);
  ::close(fd);
  EXPECT_EXIT(
      {
        if (::setgid(65534) != 0 || ::setuid(65534) != 0) std::_Exit(10);
        try {
          platform::PoseShmWriter writer(name, 4, 0644);
        } catch (const platform::ResourceBusyError& e) {
          const std::string m = e.what();
          std::fprintf(stderr, "%s\n", m.c_str());
          std::_Exit(m.find(name) != std::string::npos && m.find("uid 0") != std::string::npos ? 0 : 11);
        } catch (const std::exception& e) {
          std::fprintf(stderr, "%s\n", e.what());
          std::_Exit(12);
        }
        std::_Exit(13);
      },
      ::testing::ExitedWithCode(0), "");
  ::shm_unlink(name.c_str());
}

TEST(PoseShmRobust, CheckTellsTheCasesApartWithoutAllocating) {
  const std::string name = test::uniqueShmName("check");
  auto a = std::make_unique<platform::PoseShmWriter>(name, 4, 0644);
  pose::PoseShmReader reader;
  ASSERT_TRUE(reader.open(name));
  SegmentStatus live = SegmentStatus::NotOpen;
  {
    alloc::ThreadScope scope;
    live = reader.check();
    if (test::countsAllocations()) {
      EXPECT_EQ(scope.count(), 0u);
    }
  }
  EXPECT_EQ(live, SegmentStatus::Live);

  // A new writer under the name (what a restarted daemon does): the old mapping is Replaced, reattach() finds
  // the new one.
  a->publish(test::recordFor(1));
  auto b = std::make_unique<platform::PoseShmWriter>(name, 16, 0644);
  EXPECT_EQ(reader.check(), SegmentStatus::Replaced);
  EXPECT_EQ(reader.published(), 1u);
  ASSERT_TRUE(reader.reattach());
  EXPECT_EQ(reader.check(), SegmentStatus::Live);
  EXPECT_EQ(reader.ringCapacity(), 16u);
  EXPECT_EQ(reader.published(), 0u);

  ::shm_unlink(name.c_str());
  EXPECT_EQ(reader.check(), SegmentStatus::NameGone);
  b->markStopped();
  EXPECT_EQ(reader.check(), SegmentStatus::Stopped);
  reader.close();
  EXPECT_EQ(reader.check(), SegmentStatus::NotOpen);
}

// Offsets come from the header as it was at open: a header rewritten later cannot send a read outside the
// mapping, and a ring slot `published` covers but no one wrote reads as gone, not as busy forever.
TEST(PoseShmRobust, ARingSlotNeverWrittenReadsAsGone) {
  const std::string name = test::uniqueShmName("unwritten");
  ASSERT_TRUE(test::makeSegment(name, ::getppid(), 1000, 8));
  pose::PoseShmReader reader;
  ASSERT_TRUE(reader.open(name));
  pose::PoseRecord r;
  EXPECT_EQ(reader.readSequence(995, r), pose::ReadStatus::Overwritten);
  ::shm_unlink(name.c_str());
}
