// The shared-memory pose segment: layout, read-only mapping, ring semantics, and a concurrent
// writer/reader stress test of the seqlock (every record a reader accepts is one the writer wrote whole).
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <thread>

#include "mcslam/pose_shm.hpp"
#include "shm/pose_shm_writer.hpp"
#include "shm_test_segments.hpp"

using namespace mcslam;

namespace {
bool consistent(const pose::PoseRecord& r) {
  const pose::PoseRecord w = test::recordFor(r.sequence);
  uint8_t a[pose::kPacketSize], b[pose::kPacketSize];
  pose::encodePacket(r, a);
  pose::encodePacket(w, b);
  return std::memcmp(a, b, sizeof(a)) == 0;
}
}  // namespace

TEST(PoseShm, ReaderSeesHeaderLatestAndRing) {
  const std::string name = test::uniqueShmName("basic");
  platform::PoseShmWriter writer(name, 8, 0640);
  pose::PoseShmReader reader;
  std::string error;
  ASSERT_TRUE(reader.open(name, &error)) << error;
  EXPECT_EQ(reader.ringCapacity(), 8u);
  EXPECT_TRUE(reader.writerRunning());
  EXPECT_EQ(reader.writerPid(), getpid());
  pose::PoseRecord r;
  EXPECT_EQ(reader.readLatest(r), pose::ReadStatus::NotYet);
  for (uint64_t s = 1; s <= 20; ++s) writer.publish(test::recordFor(s));
  EXPECT_EQ(reader.published(), 20u);
  ASSERT_EQ(reader.readLatest(r), pose::ReadStatus::Ok);
  EXPECT_EQ(r.sequence, 20u);
  EXPECT_TRUE(consistent(r));
  ASSERT_EQ(reader.readSequence(13, r), pose::ReadStatus::Ok);  // the last 8 are in the ring
  EXPECT_EQ(r.sequence, 13u);
  EXPECT_TRUE(consistent(r));
  EXPECT_EQ(reader.readSequence(12, r), pose::ReadStatus::Overwritten);
  EXPECT_EQ(reader.readSequence(21, r), pose::ReadStatus::NotYet);
  writer.markStopped();
  EXPECT_FALSE(reader.writerRunning());
}

TEST(PoseShm, PermissionsComeFromTheConfigAndReadersMapReadOnly) {
  const std::string name = test::uniqueShmName("perm");
  platform::PoseShmWriter writer(name, 4, 0640);
  struct stat st {};
  ASSERT_EQ(::stat(("/dev/shm" + name).c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);
  pose::PoseShmReader reader;
  ASSERT_TRUE(reader.open(name));
  // A write through the reader's mapping must be refused by the kernel: mprotect cannot add PROT_WRITE
  // to a mapping of a descriptor opened O_RDONLY.
  void* page = const_cast<pose::ShmHeader*>(&reader.header());
  EXPECT_NE(::mprotect(page, 4096, PROT_READ | PROT_WRITE), 0);
}

TEST(PoseShm, OpeningSomethingElseFailsWithAReason) {
  pose::PoseShmReader reader;
  std::string error;
  EXPECT_FALSE(reader.open("/mcslam-test-does-not-exist", &error));
  EXPECT_NE(error.find("mcslam-test-does-not-exist"), std::string::npos) << error;
}

TEST(PoseShm, ConcurrentWriterAndReadersNeverSeeATornRecord) {
  const std::string name = test::uniqueShmName("stress");
  platform::PoseShmWriter writer(name, 16, 0600);
  constexpr uint64_t kRecords = 300000;
  std::atomic<bool> done{false};
  auto readerLoop = [&](uint64_t& reads, uint64_t& torn, uint64_t& backwards) {
    pose::PoseShmReader reader;
    ASSERT_TRUE(reader.open(name));
    uint64_t last = 0;
    while (!done.load(std::memory_order_acquire)) {
      pose::PoseRecord r;
      if (reader.readLatest(r) == pose::ReadStatus::Ok) {
        ++reads;
        if (!consistent(r)) ++torn;
        if (r.sequence < last) ++backwards;
        last = r.sequence;
      }
      const uint64_t newest = reader.published();
      if (newest > 4 && reader.readSequence(newest - 3, r) == pose::ReadStatus::Ok) {
        ++reads;
        if (!consistent(r) || r.sequence != newest - 3) ++torn;
      }
    }
  };
  uint64_t reads[2] = {0, 0}, torn[2] = {0, 0}, backwards[2] = {0, 0};
  std::thread r0(readerLoop, std::ref(reads[0]), std::ref(torn[0]), std::ref(backwards[0]));
  std::thread r1(readerLoop, std::ref(reads[1]), std::ref(torn[1]), std::ref(backwards[1]));
  for (uint64_t s = 1; s <= kRecords; ++s) writer.publish(test::recordFor(s));
  done.store(true, std::memory_order_release);
  r0.join();
  r1.join();
  EXPECT_GT(reads[0] + reads[1], 0u);
  EXPECT_EQ(torn[0] + torn[1], 0u);
  EXPECT_EQ(backwards[0] + backwards[1], 0u);
}
