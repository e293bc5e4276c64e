#pragma once
// The pose record that mcslamd publishes, as one fixed 104-byte little-endian block. The same bytes are
// the payload of every UDP datagram and of every slot of the shared-memory segment (pose_shm.hpp), so a
// consumer needs one decoder. docs/pose-protocol.md describes it byte by byte.
//
// Header-only and free of the rest of mcslam: a consumer includes this file (and pose_shm.hpp) only.
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace mcslam::pose {

inline constexpr uint32_t kPacketMagic = 0x5053434Du;  // bytes 'M' 'C' 'S' 'P' on the wire
inline constexpr uint16_t kProtocolVersion = 1;
inline constexpr std::size_t kPacketSize = 104;

// Mirrors mcslam::TrackingState (kept separate so consumers need no other header).
enum class Tracking : uint8_t { NotInitialized = 0, Tracking = 1, Lost = 2, Localizing = 3 };

inline constexpr uint8_t kFlagValid = 1u << 0;     // position/orientation hold an estimate
inline constexpr uint8_t kFlagKeyframe = 1u << 1;  // the pipeline made this frame a keyframe
// The position's unit is arbitrary, not metres: one camera, or a rig without overlapping cameras whose map has
// not yet found its metric scale (it starts up to scale and finds it in turns). Orientation is unaffected.
inline constexpr uint8_t kFlagUnscaled = 1u << 2;
// Where the pose lies in the world is a guess: tracking was lost, relocalization did not bridge the loss, and the
// new map is not yet joined to the old one. Poses are consistent among themselves; the flag clears, with
// world_revision one higher, when a recognized place joins the maps (the pose then jumps by the correction).
inline constexpr uint8_t kFlagUnanchored = 1u << 3;
// Set with kFlagUnscaled: the unit is the metre as the rig's overlapping cameras measure it from points too far for
// their baseline (cameras centimetres apart, a far scene), and lengths can be tens of percent off; it clears with
// kFlagUnscaled once the rig sees enough near points. Readers before it was defined see only kFlagUnscaled.
inline constexpr uint8_t kFlagRoughlyMetric = 1u << 4;

struct PoseRecord {
  uint64_t sequence = 0;                 // publish counter, 1 for the first pose of a daemon run, +1 per pose
  uint64_t frame_sequence = 0;           // trigger count / frame index of the rig frame (gaps = dropped frames)
  int64_t capture_time_ns = 0;           // capture time, the time base of the trajectory file
  int64_t publish_time_ns = 0;           // CLOCK_REALTIME when the daemon published the pose
  double position[3] = {0, 0, 0};        // T_w_b translation, metres
  double orientation[4] = {0, 0, 0, 1};  // T_w_b rotation, unit quaternion x, y, z, w
  Tracking tracking = Tracking::NotInitialized;
  uint8_t flags = 0;
  float quality = 0;  // 0..1
  // Times the world estimate has moved (loop closures, map merges), modulo 2^16. When it changes between two
  // records, the jump between them is a correction of the world, not motion. Readers before it was defined read
  // 0 here (it was a reserved field) and see only the jump.
  uint16_t world_revision = 0;

  bool valid() const { return (flags & kFlagValid) != 0; }
  bool keyframe() const { return (flags & kFlagKeyframe) != 0; }
  bool unscaled() const { return (flags & kFlagUnscaled) != 0; }
  bool unanchored() const { return (flags & kFlagUnanchored) != 0; }
  bool roughlyMetric() const { return (flags & kFlagRoughlyMetric) != 0; }
};

enum class DecodeStatus { Ok, TooShort, BadMagic, BadVersion, BadSize };

inline const char* decodeStatusName(DecodeStatus s) {
  switch (s) {
    case DecodeStatus::Ok: return "ok";
    case DecodeStatus::TooShort: return "too short";
    case DecodeStatus::BadMagic: return "bad magic";
    case DecodeStatus::BadVersion: return "unsupported version";
    case DecodeStatus::BadSize: return "size field mismatch";
  }
  return "?";
}

namespace detail {
// Explicit byte order, so the code is right on any host.
inline void putU16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v);
  p[1] = static_cast<uint8_t>(v >> 8);
}
inline void putU32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
inline void putU64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
inline uint16_t getU16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
inline uint32_t getU32(const uint8_t* p) {
  uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
inline uint64_t getU64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
inline void putF64(uint8_t* p, double d) {
  uint64_t v;
  std::memcpy(&v, &d, 8);
  putU64(p, v);
}
inline double getF64(const uint8_t* p) {
  const uint64_t v = getU64(p);
  double d;
  std::memcpy(&d, &v, 8);
  return d;
}
inline void putF32(uint8_t* p, float f) {
  uint32_t v;
  std::memcpy(&v, &f, 4);
  putU32(p, v);
}
inline float getF32(const uint8_t* p) {
  const uint32_t v = getU32(p);
  float f;
  std::memcpy(&f, &v, 4);
  return f;
}
}  // namespace detail

// Byte offsets (docs/pose-protocol.md, table "pose record").
namespace offset {
inline constexpr std::size_t kMagic = 0, kVersion = 4, kSize = 6, kSequence = 8, kFrameSequence = 16, kCaptureTime = 24,
                             kPublishTime = 32, kPosition = 40, kOrientation = 64, kTracking = 96, kFlags = 97,
                             kWorldRevision = 98, kQuality = 100;
}

inline void encodePacket(const PoseRecord& r, uint8_t out[kPacketSize]) {
  using namespace detail;
  putU32(out + offset::kMagic, kPacketMagic);
  putU16(out + offset::kVersion, kProtocolVersion);
  putU16(out + offset::kSize, static_cast<uint16_t>(kPacketSize));
  putU64(out + offset::kSequence, r.sequence);
  putU64(out + offset::kFrameSequence, r.frame_sequence);
  putU64(out + offset::kCaptureTime, static_cast<uint64_t>(r.capture_time_ns));
  putU64(out + offset::kPublishTime, static_cast<uint64_t>(r.publish_time_ns));
  for (int i = 0; i < 3; ++i) putF64(out + offset::kPosition + 8 * i, r.position[i]);
  for (int i = 0; i < 4; ++i) putF64(out + offset::kOrientation + 8 * i, r.orientation[i]);
  out[offset::kTracking] = static_cast<uint8_t>(r.tracking);
  out[offset::kFlags] = r.flags;
  putU16(out + offset::kWorldRevision, r.world_revision);
  putF32(out + offset::kQuality, r.quality);
}

// Accepts any datagram of at least kPacketSize bytes whose size field is >= kPacketSize, so a later
// minor revision may append fields without breaking this reader.
inline DecodeStatus decodePacket(const uint8_t* data, std::size_t size, PoseRecord& r) {
  using namespace detail;
  if (size < kPacketSize) return DecodeStatus::TooShort;
  if (getU32(data + offset::kMagic) != kPacketMagic) return DecodeStatus::BadMagic;
  if (getU16(data + offset::kVersion) != kProtocolVersion) return DecodeStatus::BadVersion;
  const uint16_t declared = getU16(data + offset::kSize);
  if (declared < kPacketSize || declared > size) return DecodeStatus::BadSize;
  r.sequence = getU64(data + offset::kSequence);
  r.frame_sequence = getU64(data + offset::kFrameSequence);
  r.capture_time_ns = static_cast<int64_t>(getU64(data + offset::kCaptureTime));
  r.publish_time_ns = static_cast<int64_t>(getU64(data + offset::kPublishTime));
  for (int i = 0; i < 3; ++i) r.position[i] = getF64(data + offset::kPosition + 8 * i);
  for (int i = 0; i < 4; ++i) r.orientation[i] = getF64(data + offset::kOrientation + 8 * i);
  r.tracking = static_cast<Tracking>(data[offset::kTracking]);
  r.flags = data[offset::kFlags];
  r.world_revision = getU16(data + offset::kWorldRevision);
  r.quality = getF32(data + offset::kQuality);
  return DecodeStatus::Ok;
}

inline const char* trackingName(Tracking t) {
  switch (t) {
    case Tracking::NotInitialized: return "not_initialized";
    case Tracking::Tracking: return "tracking";
    case Tracking::Lost: return "lost";
    case Tracking::Localizing: return "localizing";
  }
  return "unknown";
}

}  // namespace mcslam::pose
