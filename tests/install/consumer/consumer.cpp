// Encodes a pose record, decodes it again and checks the round trip; then tries to open a shared-memory segment
// that does not exist and expects the reader's error. Exit 0 when both behave.
#include <cstdio>
#include <string>

#include "mcslam/pose_protocol.hpp"
#include "mcslam/pose_shm.hpp"

int main() {
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
