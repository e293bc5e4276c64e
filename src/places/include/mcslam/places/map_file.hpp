#pragma once
// The map file: the place map of a run, to be reused by later runs (docs/design/places.md, "The map file").
// Little-endian:
//   envelope  "MCSLMAP" 0 | u32 version | u64 payload bytes | u32 CRC-32 of the payload | payload
//   payload   header (below) | the place map's keyframes and points (PlaceMap::write) | each keyframe's words, in
//             the same order (u32 count, then u32 word and f32 weight each) | loops and joined segments
//             (LoopCloser::write)
// The header says what the map needs before anything is read into fixed memory: the rig's cameras (each one's
// image size), the vocabulary (word count and fingerprint) and the counts. Written whole or not at all
// (writeFileSynced): a crash mid-save keeps the previous file.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mcslam/core/binary_io.hpp"
#include "mcslam/recognition/bow_vector.hpp"

namespace mcslam {

struct MapFileHeader {
  // 2: segments' scales, keyframes' units and loops' scales (Sim(3) loop closure). Version 1 files are read as
  // metric maps. 3: keyframes' unit sigmas; earlier files read as made in a known unit (MapFileFields).
  static constexpr uint32_t kVersion = 3;
  static constexpr uint32_t kOldestVersion = 1;
  uint32_t version = kVersion;  // of the file read
  struct Camera {
    uint32_t width = 0, height = 0;
  };
  std::vector<Camera> cameras;
  uint32_t vocabulary_words = 0;
  uint32_t vocabulary_fingerprint = 0;
  uint32_t keyframes = 0;
  uint32_t max_points_per_keyframe = 0;  // the most any keyframe of the file has
  uint64_t points = 0;
  uint32_t segments = 0;
  uint32_t loops = 0;
};

// Bytes of the envelope and of a header for `cameras` cameras.
std::size_t mapEnvelopeBytes();
std::size_t mapHeaderBytes(int cameras);

// Starts a map file in `out` (cleared): the envelope, to be completed by finishMapFile(), and the header.
void beginMapFile(std::string& out, const MapFileHeader& header);
// Fills in the envelope's payload size and checksum.
void finishMapFile(std::string& out);

// Checks the envelope of `bytes` (the file `name`: magic, a version this build reads, size, checksum), reads the
// header (with the file's version), and leaves
// `payload` positioned after it. InputError naming the file and the fault.
MapFileHeader openMapFile(std::string_view bytes, const std::string& name, ByteReader& payload);

// One keyframe's words in the payload: u32 count, then u32 word and f32 weight each, words increasing.
void putKeyframeWords(ByteWriter& out, std::span<const BowEntry> entries);
inline constexpr std::size_t kWordFileBytes = sizeof(int32_t) + sizeof(float);  // one word and its weight
std::size_t keyframeWordsBytes(std::size_t words);  // what putKeyframeWords writes for that many
// Reads them into `out` (its capacity bounds the count: `capacity_setting` names where it comes from). InputError
// from `in` naming keyframe `keyframe_id` for a word outside `vocabulary_words`, out of order or weighted wrongly.
void takeKeyframeWords(ByteReader& in, int vocabulary_words, int64_t keyframe_id, const char* capacity_setting,
                       BowVector& out);

// The largest map file any capacities could ask for: a bound on what is read.
constexpr std::size_t kMaxMapFileBytes = std::size_t{16} << 30;

}  // namespace mcslam
