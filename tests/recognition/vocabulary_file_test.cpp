// The vocabulary file: what is written is read back bit for bit; a wrong, truncated, corrupt or foreign file is
// refused with a message naming the file and the fault; the shipped vocabulary loads.
#include <gtest/gtest.h>

#include <fstream>

#include "mcslam/core/error.hpp"
#include "mcslam/recognition/vocabulary.hpp"
#include "mcslam/recognition/vocabulary_trainer.hpp"
#include "recognition_test_data.hpp"
#include "test_support.hpp"

namespace mcslam {
namespace {

Vocabulary smallVocabulary() {
  const auto data = test::clusteredDescriptors(40, 10, 10, 3);
  VocabularyTrainingOptions options;
  options.branching = 5;
  options.depth = 3;
  return trainVocabulary(data.descriptors, data.image_offsets, options);
}

void expectErrorMentions(const std::string& path, const std::string& what) {
  try {
    readVocabularyFile(path);
    ADD_FAILURE() << "no error for " << path;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(what), std::string::npos) << message;
  }
}

TEST(VocabularyFile, RoundTripsExactly) {
  test::TempDir dir;
  const Vocabulary v = smallVocabulary();
  writeVocabularyFile(v, dir.file("v.mcvoc"));
  const Vocabulary r = readVocabularyFile(dir.file("v.mcvoc"));
  ASSERT_EQ(r.branching(), 5);
  ASSERT_EQ(r.depth(), 3);
  EXPECT_EQ(r.training_images, v.training_images);
  EXPECT_EQ(r.training_descriptors, v.training_descriptors);
  for (int64_t n = 0; n < v.nodeCount(); ++n) {
    ASSERT_EQ(r.present(n), v.present(n));
    ASSERT_EQ(r.descriptor(n), v.descriptor(n));
  }
  for (WordId w = 0; w < v.wordCount(); ++w) ASSERT_EQ(r.idf(w), v.idf(w));
  EXPECT_FALSE(std::filesystem::exists(dir.file("v.mcvoc.tmp")));
}

TEST(VocabularyFile, BadFilesAreRefusedWithTheReason) {
  test::TempDir dir;
  const std::string good = dir.file("good.mcvoc");
  writeVocabularyFile(smallVocabulary(), good);
  const std::string bytes = test::readFile(good);

  expectErrorMentions(dir.file("missing.mcvoc"), "cannot open");
  expectErrorMentions(test::writeFile(dir.file("empty.mcvoc"), ""), "not an mcslam vocabulary");
  expectErrorMentions(test::writeFile(dir.file("text.mcvoc"), "slam:\n  capacity: {}\n"), "not an mcslam vocabulary");
  expectErrorMentions(test::writeFile(dir.file("cut.mcvoc"), bytes.substr(0, bytes.size() - 100)), "truncated");
  expectErrorMentions(test::writeFile(dir.file("long.mcvoc"), bytes + "x"), "trailing data");
  std::string flipped = bytes;
  flipped[bytes.size() / 2] = static_cast<char>(flipped[bytes.size() / 2] ^ 0x10);
  expectErrorMentions(test::writeFile(dir.file("flipped.mcvoc"), flipped), "corrupt");
  std::string version = bytes;
  version[8] = 9;
  expectErrorMentions(test::writeFile(dir.file("version.mcvoc"), version), "version 9");
  std::string shape = bytes;
  shape[12] = 100;  // branching
  expectErrorMentions(test::writeFile(dir.file("shape.mcvoc"), shape), "branching 100");
  expectErrorMentions("/dev/zero", "not a regular file");
  expectErrorMentions(dir.path().string(), "not a regular file");
}

TEST(VocabularyFile, AFailedWriteKeepsThePreviousFile) {
  test::TempDir dir;
  const std::string path = dir.file("v.mcvoc");
  writeVocabularyFile(smallVocabulary(), path);
  const std::string before = test::readFile(path);
  EXPECT_THROW(writeVocabularyFile(smallVocabulary(), dir.file("no/such/folder/v.mcvoc")), InputError);
  std::filesystem::create_directory(dir.file("v.mcvoc.tmp"));  // the temporary cannot be created
  EXPECT_THROW(writeVocabularyFile(Vocabulary(4, 2), path), InputError);
  EXPECT_EQ(test::readFile(path), before);
}

TEST(VocabularyFile, TheShippedVocabularyLoads) {
  const Vocabulary v = readVocabularyFile(std::string(MCSLAM_SOURCE_DIR) + "/config/places/orb_vocabulary.mcvoc");
  EXPECT_GE(v.wordCount(), 10000);
  EXPECT_GE(v.training_images, 1000u);
}

}  // namespace
}  // namespace mcslam
