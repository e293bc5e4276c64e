// The 104-byte pose record: exact bytes at the documented offsets (docs/pose-protocol.md), round trip,
// and rejection of foreign datagrams.
#include <gtest/gtest.h>

#include "mcslam/pose_protocol.hpp"

using namespace mcslam::pose;

TEST(PoseProtocol, BytesSitAtTheDocumentedOffsetsLittleEndian) {
  PoseRecord r;
  r.sequence = 0x0102030405060708ull;
  r.frame_sequence = 42;
  r.capture_time_ns = 1500000000123456789ll;
  r.publish_time_ns = -2;
  r.position[0] = 1.0;
  r.position[1] = -2.5;
  r.position[2] = 0.0;
  r.orientation[0] = 0;
  r.orientation[1] = 0;
  r.orientation[2] = 0;
  r.orientation[3] = 1.0;
  r.tracking = Tracking::Lost;
  r.flags = kFlagValid | kFlagKeyframe | kFlagUnscaled;
  r.quality = 0.5f;
  r.world_revision = 0x0203;
  uint8_t b[kPacketSize];
  encodePacket(r, b);
  const uint8_t magic[4] = {'M', 'C', 'S', 'P'};
  EXPECT_EQ(std::memcmp(b, magic, 4), 0);
  EXPECT_EQ(b[4], 1);  // version
  EXPECT_EQ(b[5], 0);
  EXPECT_EQ(b[6], 104);  // size
  EXPECT_EQ(b[7], 0);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(b[8 + i], 8 - i) << i;  // sequence, least significant byte first
  EXPECT_EQ(b[16], 42);
  EXPECT_EQ(b[32], 0xFE);  // -2 in two's complement
  EXPECT_EQ(b[39], 0xFF);
  // 1.0 = 0x3FF0000000000000, -2.5 = 0xC004000000000000
  EXPECT_EQ(b[40 + 7], 0x3F);
  EXPECT_EQ(b[40 + 6], 0xF0);
  EXPECT_EQ(b[48 + 7], 0xC0);
  EXPECT_EQ(b[48 + 6], 0x04);
  EXPECT_EQ(b[88 + 7], 0x3F);  // qw = 1.0
  EXPECT_EQ(b[96], 2);
  EXPECT_EQ(b[97], 7);
  EXPECT_EQ(b[98], 3);  // world_revision
  EXPECT_EQ(b[99], 2);
  // 0.5f = 0x3F000000
  EXPECT_EQ(b[100], 0);
  EXPECT_EQ(b[103], 0x3F);
}

TEST(PoseProtocol, RoundTripsEveryField) {
  PoseRecord r;
  r.sequence = 7;
  r.frame_sequence = 9;
  r.capture_time_ns = 123;
  r.publish_time_ns = 456;
  r.position[0] = 0.1;
  r.position[1] = 0.2;
  r.position[2] = 0.3;
  r.orientation[0] = 0.5;
  r.orientation[1] = 0.5;
  r.orientation[2] = 0.5;
  r.orientation[3] = 0.5;
  r.tracking = Tracking::Tracking;
  r.flags = kFlagValid;
  r.quality = 0.75f;
  r.world_revision = 65535;
  uint8_t b[kPacketSize];
  encodePacket(r, b);
  PoseRecord d;
  ASSERT_EQ(decodePacket(b, sizeof(b), d), DecodeStatus::Ok);
  EXPECT_EQ(d.sequence, 7u);
  EXPECT_EQ(d.frame_sequence, 9u);
  EXPECT_EQ(d.capture_time_ns, 123);
  EXPECT_EQ(d.publish_time_ns, 456);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(d.position[i], r.position[i]);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(d.orientation[i], r.orientation[i]);
  EXPECT_EQ(d.tracking, Tracking::Tracking);
  EXPECT_TRUE(d.valid());
  EXPECT_FALSE(d.keyframe());
  EXPECT_EQ(d.quality, 0.75f);
  EXPECT_EQ(d.world_revision, 65535);
}

TEST(PoseProtocol, RejectsShortForeignAndFutureDatagrams) {
  uint8_t b[kPacketSize + 8] = {};
  encodePacket(PoseRecord{}, b);
  PoseRecord d;
  EXPECT_EQ(decodePacket(b, kPacketSize - 1, d), DecodeStatus::TooShort);
  uint8_t other[kPacketSize];
  std::memcpy(other, b, kPacketSize);
  other[0] = 'X';
  EXPECT_EQ(decodePacket(other, kPacketSize, d), DecodeStatus::BadMagic);
  std::memcpy(other, b, kPacketSize);
  other[4] = 2;
  EXPECT_EQ(decodePacket(other, kPacketSize, d), DecodeStatus::BadVersion);
  // A longer record (later minor revision) with a matching size field is accepted.
  b[6] = kPacketSize + 8;
  EXPECT_EQ(decodePacket(b, sizeof(b), d), DecodeStatus::Ok);
  EXPECT_EQ(decodePacket(b, kPacketSize, d), DecodeStatus::BadSize);
}

// The example dump in docs/pose-protocol.md, byte for byte.
TEST(PoseProtocol, MatchesTheExampleInTheDocument) {
  PoseRecord r;
  r.sequence = 1;
  r.frame_sequence = 0;
  r.capture_time_ns = 1403636579763555584ll;
  r.publish_time_ns = 0;
  r.position[0] = 1.0;
  r.position[1] = -2.5;
  r.position[2] = 0.0;
  r.tracking = Tracking::Tracking;
  r.flags = kFlagValid;
  r.quality = 0.5f;
  const uint8_t expected[kPacketSize] = {
      0x4d, 0x43, 0x53, 0x50, 0x01, 0x00, 0x68, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x0d, 0x8d, 0x52, 0x08, 0xb8, 0x7a, 0x13, 0x00, 0x00, 0x00, 0x00,
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xf0, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
      0x04, 0xc0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
      0x00, 0x00, 0x00, 0x00, 0xf0, 0x3f, 0x01, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x3f};
  uint8_t b[kPacketSize];
  encodePacket(r, b);
  for (std::size_t i = 0; i < kPacketSize; ++i) EXPECT_EQ(b[i], expected[i]) << "byte " << i;
}
