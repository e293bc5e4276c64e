// The vocabulary file, little-endian:
//   "MCSLVOC" 0 | u32 version | u32 branching | u32 depth | u32 descriptor bits (256)
//   | u64 training images | u64 training descriptors
//   | node presence, one byte per node | node descriptors, 32 bytes per node | idf, one f32 per word
//   | u32 CRC-32 of everything before it
#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>

#include "mcslam/core/binary_io.hpp"
#include "mcslam/core/checksum.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/core/synced_file.hpp"
#include "mcslam/recognition/vocabulary.hpp"

namespace mcslam {

namespace {

constexpr char kMagic[8] = {'M', 'C', 'S', 'L', 'V', 'O', 'C', 0};
constexpr uint32_t kVersion = 1;
constexpr uint32_t kDescriptorBits = 256;
constexpr std::size_t kHeaderBytes = 8 + 4 * 4 + 8 * 2;
// Larger than any vocabulary within Vocabulary's limits would need only for absurd shapes: a bound on what is read.
constexpr std::size_t kMaxFileBytes = std::size_t{1} << 30;

std::size_t bodyBytes(const Vocabulary& v) {
  return static_cast<std::size_t>(v.nodeCount()) * (1 + sizeof(Descriptor)) +
         static_cast<std::size_t>(v.wordCount()) * sizeof(float);
}

// Presence, descriptors and idf: what a vocabulary is, apart from its shape and provenance.
void writeBody(const Vocabulary& v, ByteWriter& out) {
  for (int64_t n = 0; n < v.nodeCount(); ++n) out.put<uint8_t>(v.present(n) ? 1 : 0);
  for (int64_t n = 0; n < v.nodeCount(); ++n) out.putBytes(v.descriptor(n).data(), sizeof(Descriptor));
  for (WordId w = 0; w < v.wordCount(); ++w) out.put<float>(v.idf(w));
}

}  // namespace

Vocabulary readVocabularyFile(const std::string& path) {
  const std::string bytes = readFileBounded(path, kMaxFileBytes, "vocabulary file");
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    throw InputError(path + ": not an mcslam vocabulary file (it does not start with 'MCSLVOC')");
  ByteReader in(bytes, path);
  char magic[sizeof(kMagic)];
  in.takeBytes(magic, sizeof(magic), "the magic");
  const auto version = in.take<uint32_t>("the version");
  if (version != kVersion)
    throw InputError(path + ": vocabulary file version " + std::to_string(version) + ", this build reads version " +
                     std::to_string(kVersion));
  const auto branching = in.take<uint32_t>("branching");
  const auto depth = in.take<uint32_t>("depth");
  const auto bits = in.take<uint32_t>("descriptor bits");
  if (bits != kDescriptorBits)
    throw InputError(path + ": descriptors of " + std::to_string(bits) + " bits, this build uses 256-bit ORB");
  if (branching > Vocabulary::kMaxBranching || depth > Vocabulary::kMaxDepth)
    throw InputError(path + ": branching " + std::to_string(branching) + ", depth " + std::to_string(depth) +
                     " is outside the limits (branching 2-64, depth 1-8)");
  Vocabulary v;
  try {
    v = Vocabulary(static_cast<int>(branching), static_cast<int>(depth));
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
  v.training_images = in.take<uint64_t>("training images");
  v.training_descriptors = in.take<uint64_t>("training descriptors");
  const std::size_t expected = kHeaderBytes + bodyBytes(v) + sizeof(uint32_t);
  if (bytes.size() != expected)
    throw InputError(path + ": " + std::to_string(bytes.size()) + " bytes where a vocabulary of branching " +
                     std::to_string(branching) + " and depth " + std::to_string(depth) + " has " +
                     std::to_string(expected) + (bytes.size() < expected ? " (truncated)" : " (trailing data)"));
  const std::size_t crc_at = expected - sizeof(uint32_t);
  uint32_t stored_crc = 0;
  std::memcpy(&stored_crc, bytes.data() + crc_at, sizeof(stored_crc));
  if (stored_crc != crc32(bytes.data(), crc_at))
    throw InputError(path + ": checksum mismatch: the vocabulary file is corrupt");
  const std::size_t nodes = static_cast<std::size_t>(v.nodeCount());
  const std::size_t presence_at = in.offset();
  const std::size_t descriptors_at = presence_at + nodes;
  for (std::size_t n = 0; n < nodes; ++n) {
    if (bytes[presence_at + n] == 0) continue;
    Descriptor d;
    std::memcpy(d.data(), bytes.data() + descriptors_at + n * sizeof(Descriptor), sizeof(Descriptor));
    v.setNode(static_cast<int64_t>(n), d);
  }
  ByteReader idf(std::string_view(bytes).substr(descriptors_at + nodes * sizeof(Descriptor)), path);
  for (WordId w = 0; w < v.wordCount(); ++w) v.setIdf(w, idf.take<float>("idf"));
  if (v.empty()) throw InputError(path + ": the vocabulary has no words");
  return v;
}

uint32_t vocabularyFingerprint(const Vocabulary& v) {
  std::string body;
  body.reserve(bodyBytes(v));
  ByteWriter out(body);
  writeBody(v, out);
  return crc32(body.data(), body.size());
}

std::vector<std::string> defaultVocabularyCandidates() {
  namespace fs = std::filesystem;
  std::vector<std::string> out;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec)
    out.push_back((exe.parent_path() / "../share/mcslam/places" / MCSLAM_VOCABULARY_FILE_NAME).lexically_normal());
  for (const char* fixed : {MCSLAM_VOCABULARY_SOURCE_PATH, MCSLAM_VOCABULARY_INSTALL_PATH})
    if (std::find(out.begin(), out.end(), fixed) == out.end()) out.push_back(fixed);
  return out;
}

Vocabulary loadVocabulary(const std::string& path) {
  if (!path.empty()) return readVocabularyFile(path);
  std::string tried;
  for (const std::string& candidate : defaultVocabularyCandidates()) {
    std::error_code ec;
    if (std::filesystem::exists(candidate, ec)) return readVocabularyFile(candidate);
    tried += (tried.empty() ? "" : ", ") + candidate;
  }
  throw InputError("no vocabulary file: the shipped one is in none of " + tried +
                   " (give one with places.vocabulary, or turn place memory off with places.enabled: false)");
}

void writeVocabularyFile(const Vocabulary& v, const std::string& path) {
  std::string bytes;
  bytes.reserve(kHeaderBytes + bodyBytes(v) + sizeof(uint32_t));
  ByteWriter out(bytes);
  out.putBytes(kMagic, sizeof(kMagic));
  out.put<uint32_t>(kVersion);
  out.put<uint32_t>(static_cast<uint32_t>(v.branching()));
  out.put<uint32_t>(static_cast<uint32_t>(v.depth()));
  out.put<uint32_t>(kDescriptorBits);
  out.put<uint64_t>(v.training_images);
  out.put<uint64_t>(v.training_descriptors);
  writeBody(v, out);
  out.put<uint32_t>(crc32(bytes.data(), bytes.size()));
  std::string error;
  if (!writeFileSynced(path, bytes, &error)) throw InputError("cannot write the vocabulary: " + error);
}

}  // namespace mcslam
