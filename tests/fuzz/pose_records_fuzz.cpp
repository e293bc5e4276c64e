// The pose consumer's parsers (include/mcslam/pose_*.hpp): a UDP datagram through decodePacket, and the same bytes
// as a shared-memory segment through PoseShmReader (open's validation, then reading the latest pose and the ring).
// Their documented outcomes are status values; nothing may throw or read outside the bytes.
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <string>

#include "mcslam/pose_shm.hpp"

namespace {

const std::string& segmentName() {
  static const std::string name = "/mcslam-fuzz-" + std::to_string(::getpid());
  return name;
}

void readSegment(const uint8_t* data, std::size_t size) {
  const int fd = ::shm_open(segmentName().c_str(), O_RDWR | O_CREAT | O_TRUNC, 0600);
  if (fd < 0) return;
  const bool written = ::write(fd, data, size) == static_cast<ssize_t>(size);
  ::close(fd);
  if (written) {
    mcslam::pose::PoseShmReader reader;
    if (reader.open(segmentName())) {
      mcslam::pose::PoseRecord record;
      (void)reader.readLatest(record);
      const uint64_t newest = reader.published();
      for (uint64_t back = 0; back < 6; ++back) (void)reader.readSequence(newest + 1 - back, record);  // wraps: fine
    }
  }
  ::shm_unlink(segmentName().c_str());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  mcslam::pose::PoseRecord record;
  (void)mcslam::pose::decodePacket(data, size, record);
  readSegment(data, size);
  return 0;
}
