// The vocabulary file, little-endian:
//   "MCSLVOC" 0 | u32 version | u32 branching | u32 depth | u32 descriptor bits (256)
//   | u64 training images | u64 training descriptors
//   | node presence, one byte per node | node descriptors, 32 bytes per node | idf, one f32 per word
//   | u32 CRC-32 of everything before it
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>

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

template <class T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

template <class T>
T take(const std::string& in, std::size_t& at) {
  T value;
  std::memcpy(&value, in.data() + at, sizeof(T));
  at += sizeof(T);
  return value;
}

std::string readBounded(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw InputError(path + ": cannot open the vocabulary file");
  if (!S_ISREG(st.st_mode)) throw InputError(path + ": not a regular file, so not a vocabulary file");
  if (static_cast<std::size_t>(st.st_size) > kMaxFileBytes)
    throw InputError(path + ": " + std::to_string(st.st_size) + " bytes, more than any vocabulary file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the vocabulary file");
  std::string bytes(static_cast<std::size_t>(st.st_size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (static_cast<std::size_t>(in.gcount()) != bytes.size()) throw InputError(path + ": cannot read the whole file");
  return bytes;
}

}  // namespace

Vocabulary readVocabularyFile(const std::string& path) {
  const std::string bytes = readBounded(path);
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    throw InputError(path + ": not an mcslam vocabulary file (it does not start with 'MCSLVOC')");
  std::size_t at = sizeof(kMagic);
  const auto version = take<uint32_t>(bytes, at);
  if (version != kVersion)
    throw InputError(path + ": vocabulary file version " + std::to_string(version) + ", this build reads version " +
                     std::to_string(kVersion));
  const auto branching = take<uint32_t>(bytes, at);
  const auto depth = take<uint32_t>(bytes, at);
  const auto bits = take<uint32_t>(bytes, at);
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
  v.training_images = take<uint64_t>(bytes, at);
  v.training_descriptors = take<uint64_t>(bytes, at);
  const std::size_t expected = kHeaderBytes + bodyBytes(v) + sizeof(uint32_t);
  if (bytes.size() != expected)
    throw InputError(path + ": " + std::to_string(bytes.size()) + " bytes where a vocabulary of branching " +
                     std::to_string(branching) + " and depth " + std::to_string(depth) + " has " +
                     std::to_string(expected) + (bytes.size() < expected ? " (truncated)" : " (trailing data)"));
  const std::size_t crc_at = expected - sizeof(uint32_t);
  std::size_t crc_pos = crc_at;
  if (take<uint32_t>(bytes, crc_pos) != crc32(bytes.data(), crc_at))
    throw InputError(path + ": checksum mismatch: the vocabulary file is corrupt");
  const std::size_t nodes = static_cast<std::size_t>(v.nodeCount());
  const std::size_t presence_at = at;
  const std::size_t descriptors_at = presence_at + nodes;
  for (std::size_t n = 0; n < nodes; ++n) {
    if (bytes[presence_at + n] == 0) continue;
    Descriptor d;
    std::memcpy(d.data(), bytes.data() + descriptors_at + n * sizeof(Descriptor), sizeof(Descriptor));
    v.setNode(static_cast<int64_t>(n), d);
  }
  std::size_t idf_at = descriptors_at + nodes * sizeof(Descriptor);
  for (WordId w = 0; w < v.wordCount(); ++w) v.setIdf(w, take<float>(bytes, idf_at));
  if (v.empty()) throw InputError(path + ": the vocabulary has no words");
  return v;
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
  std::string out;
  out.reserve(kHeaderBytes + bodyBytes(v) + sizeof(uint32_t));
  out.append(kMagic, sizeof(kMagic));
  put<uint32_t>(out, kVersion);
  put<uint32_t>(out, static_cast<uint32_t>(v.branching()));
  put<uint32_t>(out, static_cast<uint32_t>(v.depth()));
  put<uint32_t>(out, kDescriptorBits);
  put<uint64_t>(out, v.training_images);
  put<uint64_t>(out, v.training_descriptors);
  for (int64_t n = 0; n < v.nodeCount(); ++n) out.push_back(v.present(n) ? 1 : 0);
  for (int64_t n = 0; n < v.nodeCount(); ++n) {
    const Descriptor& d = v.descriptor(n);
    out.append(reinterpret_cast<const char*>(d.data()), sizeof(Descriptor));
  }
  for (WordId w = 0; w < v.wordCount(); ++w) put<float>(out, v.idf(w));
  put<uint32_t>(out, crc32(out.data(), out.size()));
  std::string error;
  if (!writeFileSynced(path, out, &error)) throw InputError("cannot write the vocabulary: " + error);
}

}  // namespace mcslam
