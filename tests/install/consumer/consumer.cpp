// A pose consumer built against an installed mcslam. Without arguments: encodes a pose record, decodes it again and
// checks the round trip, then tries to open a shared-memory segment that does not exist and expects the reader's
// error (exit 0 when both behave). With a segment name: reads COUNT poses (default 10) from a running mcslamd's
// segment, waiting up to 120 s for them, and prints the last (exit 0 when they came).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "mcslam/pose_protocol.hpp"
#include "mcslam/pose_shm.hpp"

namespace {

int selfCheck() {
  mcslam::pose::PoseRecord in;
  in.sequence = 7;
  in.frame_sequence = 42;
  in.position[0] = 1.5;
  in.flags = mcslam::pose::kFlagValid;
  uint8_t bytes[mcslam::pose::kPacketSize];
  mcslam::pose::encodePacket(in, bytes);
  mcslam::pose::PoseRecord out;
  if (mcslam::pose::decodePacket(bytes, sizeof bytes, out) != mcslam::pose::DecodeStatus::Ok || out.sequence != 7 ||
      out.frame_sequence != 42 || out.position[0] != 1.5 || !out.valid()) {
    std::puts("consumer: round trip failed");
    return 1;
  }
  mcslam::pose::PoseShmReader reader;
  std::string error;
  if (reader.open("/mcslam_consumer_test_no_such_segment", &error) || error.empty()) {
    std::puts("consumer: opening a missing segment did not fail");
    return 1;
  }
  std::printf("consumer: ok (%s)\n", error.c_str());
  return 0;
}

int readLive(const std::string& segment, uint64_t count) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  mcslam::pose::PoseShmReader reader;
  std::string error;
  while (!reader.open(segment, &error) || reader.published() < count) {
    if (std::chrono::steady_clock::now() > deadline) {
      std::printf("consumer: %s: fewer than %llu poses in 120 s (%s)\n", segment.c_str(),
                  static_cast<unsigned long long>(count), error.c_str());
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  mcslam::pose::PoseRecord r;
  if (reader.readLatest(r) != mcslam::pose::ReadStatus::Ok) {
    std::puts("consumer: the latest pose could not be read");
    return 1;
  }
  std::printf("consumer: ok, %llu poses, latest frame %llu at (%.3f, %.3f, %.3f), %s\n",
              static_cast<unsigned long long>(reader.published()), static_cast<unsigned long long>(r.frame_sequence),
              r.position[0], r.position[1], r.position[2], mcslam::pose::trackingName(r.tracking));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return selfCheck();
  return readLive(argv[1], argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 10);
}
