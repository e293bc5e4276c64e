#include "mcslam/places/map_file.hpp"

#include <cmath>
#include <cstring>

#include "mcslam/core/checksum.hpp"

namespace mcslam {

namespace {

constexpr char kMagic[8] = {'M', 'C', 'S', 'L', 'M', 'A', 'P', 0};
constexpr std::size_t kPayloadSizeAt = sizeof(kMagic) + sizeof(uint32_t);
constexpr std::size_t kCrcAt = kPayloadSizeAt + sizeof(uint64_t);

}  // namespace

std::size_t mapEnvelopeBytes() { return kCrcAt + sizeof(uint32_t); }

std::size_t mapHeaderBytes(int cameras) {
  return sizeof(uint32_t) * (1 + 2 * static_cast<std::size_t>(cameras)) + 6 * sizeof(uint32_t) + sizeof(uint64_t);
}

void beginMapFile(std::string& out, const MapFileHeader& header) {
  out.clear();
  ByteWriter w(out);
  w.putBytes(kMagic, sizeof(kMagic));
  w.put<uint32_t>(MapFileHeader::kVersion);
  w.put<uint64_t>(0);
  w.put<uint32_t>(0);
  w.put<uint32_t>(static_cast<uint32_t>(header.cameras.size()));
  for (const MapFileHeader::Camera& c : header.cameras) {
    w.put<uint32_t>(c.width);
    w.put<uint32_t>(c.height);
  }
  w.put<uint32_t>(header.vocabulary_words);
  w.put<uint32_t>(header.vocabulary_fingerprint);
  w.put<uint32_t>(header.keyframes);
  w.put<uint32_t>(header.max_points_per_keyframe);
  w.put<uint64_t>(header.points);
  w.put<uint32_t>(header.segments);
  w.put<uint32_t>(header.loops);
}

void finishMapFile(std::string& out) {
  const std::size_t payload = out.size() - mapEnvelopeBytes();
  const uint64_t size = payload;
  const uint32_t crc = crc32(out.data() + mapEnvelopeBytes(), payload);
  std::memcpy(out.data() + kPayloadSizeAt, &size, sizeof(size));
  std::memcpy(out.data() + kCrcAt, &crc, sizeof(crc));
}

MapFileHeader openMapFile(std::string_view bytes, const std::string& name, ByteReader& payload) {
  if (bytes.size() < mapEnvelopeBytes() || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    throw InputError(name + ": not an mcslam map file (it does not start with 'MCSLMAP')");
  ByteReader envelope(bytes.substr(sizeof(kMagic)), name);
  const auto version = envelope.take<uint32_t>("the version");
  if (version < MapFileHeader::kOldestVersion || version > MapFileHeader::kVersion)
    throw InputError(name + ": map file version " + std::to_string(version) + ", this build reads versions " +
                     std::to_string(MapFileHeader::kOldestVersion) + " to " + std::to_string(MapFileHeader::kVersion));
  const auto size = envelope.take<uint64_t>("the payload size");
  const auto crc = envelope.take<uint32_t>("the checksum");
  const std::size_t actual = bytes.size() - mapEnvelopeBytes();
  if (size != actual)
    throw InputError(name + ": the map says " + std::to_string(size) + " bytes follow its envelope, the file has " +
                     std::to_string(actual) + (actual < size ? " (truncated)" : " (trailing data)"));
  if (crc32(bytes.data() + mapEnvelopeBytes(), actual) != crc)
    throw InputError(name + ": checksum mismatch: the map file is corrupt");
  payload = ByteReader(bytes.substr(mapEnvelopeBytes()), name);
  MapFileHeader h;
  h.version = version;
  const auto cameras = payload.take<uint32_t>("the camera count");
  if (cameras == 0 || cameras > 64) payload.fail("a map of " + std::to_string(cameras) + " cameras");
  h.cameras.resize(cameras);
  for (MapFileHeader::Camera& c : h.cameras) {
    c.width = payload.take<uint32_t>("a camera's width");
    c.height = payload.take<uint32_t>("a camera's height");
  }
  h.vocabulary_words = payload.take<uint32_t>("the vocabulary's word count");
  h.vocabulary_fingerprint = payload.take<uint32_t>("the vocabulary's fingerprint");
  h.keyframes = payload.take<uint32_t>("the keyframe count");
  h.max_points_per_keyframe = payload.take<uint32_t>("the points of the fullest keyframe");
  h.points = payload.take<uint64_t>("the point count");
  h.segments = payload.take<uint32_t>("the segment count");
  h.loops = payload.take<uint32_t>("the loop count");
  return h;
}

std::size_t keyframeWordsBytes(std::size_t words) { return sizeof(uint32_t) + words * kWordFileBytes; }

void putKeyframeWords(ByteWriter& out, std::span<const BowEntry> entries) {
  out.put<uint32_t>(static_cast<uint32_t>(entries.size()));
  for (const BowEntry& e : entries) {
    out.put<int32_t>(e.word);
    out.put<float>(e.weight);
  }
}

void takeKeyframeWords(ByteReader& in, int vocabulary_words, int64_t keyframe_id, const char* capacity_setting,
                       BowVector& out) {
  const auto count = in.take<uint32_t>("a keyframe's word count");
  if (count > static_cast<uint32_t>(out.capacity()))
    in.fail("keyframe " + std::to_string(keyframe_id) + " has " + std::to_string(count) + " words, more than " +
            capacity_setting + " (" + std::to_string(out.capacity()) + ")");
  out.clear();
  for (uint32_t i = 0; i < count; ++i) {
    const auto word = in.take<WordId>("a word");
    const auto weight = in.take<float>("a word's weight");
    const bool in_order = out.size() == 0 || out.entries().back().word < word;
    if (word < 0 || word >= vocabulary_words || !in_order || !(weight >= 0) || !std::isfinite(weight))
      in.fail("keyframe " + std::to_string(keyframe_id) + " has a word the vocabulary cannot give");
    out.push(word, weight);
  }
}

}  // namespace mcslam
