// The vocabulary tree and its training: descriptors descend to their nearest child; clusters that training is
// given come out as words; the idf says how rare a word is; bag-of-words vectors and their similarity.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "alloc_testing.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/recognition/bow_vector.hpp"
#include "mcslam/recognition/vocabulary.hpp"
#include "mcslam/recognition/vocabulary_trainer.hpp"
#include "recognition_test_data.hpp"

namespace mcslam {
namespace {

TEST(Vocabulary, ShapesOutsideTheLimitsAreRefused) {
  EXPECT_THROW(Vocabulary(1, 3), InputError);
  EXPECT_THROW(Vocabulary(65, 3), InputError);
  EXPECT_THROW(Vocabulary(10, 0), InputError);
  EXPECT_THROW(Vocabulary(10, 9), InputError);
  EXPECT_THROW(Vocabulary(64, 5), InputError);  // 2^30 words
  const Vocabulary v(10, 3);
  EXPECT_EQ(v.wordCount(), 1000);
  EXPECT_EQ(v.nodeCount(), 1111);
  EXPECT_EQ(v.firstNodeOfLevel(3), 111);
}

TEST(Vocabulary, ADescriptorDescendsToTheNearestPresentChild) {
  std::mt19937_64 rng(3);
  Vocabulary v(3, 2);  // root, 3 children, 9 leaves
  const Descriptor a = test::randomDescriptor(rng), b = test::randomDescriptor(rng);
  v.setNode(0, {});
  v.setNode(1, a);                                   // child 0
  v.setNode(3, b);                                   // child 2; child 1 absent
  v.setNode(1 * 3 + 2, a);                           // leaves under child 0: leaf 1 only
  v.setNode(3 * 3 + 1, b);                           // leaves under child 2: leaf 6 (node 10)
  v.setNode(3 * 3 + 3, test::flipBits(b, 40, rng));  // and leaf 8 (node 12)
  EXPECT_EQ(v.word(test::flipBits(a, 10, rng)), 1);
  EXPECT_EQ(v.word(test::flipBits(b, 10, rng)), 6);
  EXPECT_EQ(v.ancestor(6, 1), 2);
  EXPECT_EQ(v.ancestor(6, 2), 0);
}

TEST(VocabularyTraining, ClustersBecomeWords) {
  // 100 clusters of 30 descriptors, members within 12 bits of their centre (centres are ~128 bits apart).
  const auto data = test::clusteredDescriptors(100, 30, 12, 7);
  VocabularyTrainingOptions options;
  options.branching = 10;
  options.depth = 3;
  options.threads = 2;
  const Vocabulary v = trainVocabulary(data.descriptors, data.image_offsets, options);
  EXPECT_EQ(v.training_images, 100u);
  EXPECT_EQ(v.training_descriptors, 3000u);
  // No two clusters share a word (the tree has 1000 leaves for 100 clusters: the last level splits a cluster's
  // noise, but clusters never merge).
  std::map<WordId, int> cluster_of_word;
  int merged = 0;
  for (std::size_t i = 0; i < data.descriptors.size(); ++i) {
    const WordId w = v.word(data.descriptors[i]);
    const auto [it, fresh] = cluster_of_word.emplace(w, data.cluster_of[i]);
    if (!fresh && it->second != data.cluster_of[i]) ++merged;
  }
  EXPECT_EQ(merged, 0);
  // A new member of a cluster (never seen in training) finds a word of its cluster.
  std::mt19937_64 rng(99);
  for (int c = 0; c < 100; ++c) {
    const WordId w = v.word(test::flipBits(data.centres[static_cast<std::size_t>(c)], 12, rng));
    EXPECT_EQ(cluster_of_word.count(w), 1u);
    if (cluster_of_word.count(w)) {
      EXPECT_EQ(cluster_of_word[w], c);
    }
  }
}

TEST(VocabularyTraining, IdfIsTheLogOfImagesOverImagesContainingTheWord) {
  // Cluster 0 is in every image, each other cluster in one image only.
  auto data = test::clusteredDescriptors(20, 10, 8, 5);
  std::vector<Descriptor> descriptors;
  std::vector<uint64_t> offsets{0};
  std::mt19937_64 rng(1);
  for (int image = 0; image < 20; ++image) {
    for (int i = 0; i < 10; ++i) descriptors.push_back(data.descriptors[static_cast<std::size_t>(image * 10 + i)]);
    for (int i = 0; i < 3; ++i) descriptors.push_back(test::flipBits(data.centres[0], 8, rng));
    offsets.push_back(descriptors.size());
  }
  VocabularyTrainingOptions options;
  options.branching = 8;
  options.depth = 2;
  const Vocabulary v = trainVocabulary(descriptors, offsets, options);
  const WordId common = v.word(data.centres[0]);
  const WordId rare = v.word(data.centres[7]);
  EXPECT_NEAR(v.idf(common), 0.0, 1e-6);
  EXPECT_NEAR(v.idf(rare), std::log(20.0), 1e-5);
}

TEST(VocabularyTraining, TheSameSeedGivesTheSameTreeWhateverTheThreads) {
  const auto data = test::clusteredDescriptors(50, 20, 20, 11);
  VocabularyTrainingOptions options;
  options.branching = 6;
  options.depth = 3;
  options.threads = 1;
  const Vocabulary one = trainVocabulary(data.descriptors, data.image_offsets, options);
  options.threads = 3;
  const Vocabulary three = trainVocabulary(data.descriptors, data.image_offsets, options);
  ASSERT_EQ(one.nodeCount(), three.nodeCount());
  for (int64_t n = 0; n < one.nodeCount(); ++n) {
    ASSERT_EQ(one.present(n), three.present(n)) << n;
    ASSERT_EQ(one.descriptor(n), three.descriptor(n)) << n;
  }
}

TEST(VocabularyTraining, TooFewDescriptorsAreRefused) {
  const auto data = test::clusteredDescriptors(1, 5, 4, 1);
  EXPECT_THROW(trainVocabulary(data.descriptors, data.image_offsets, {}), InputError);
}

// A frame of `cameras` cameras whose features are the given descriptors, spread over the cameras in turn.
FrameFeatures frameOf(const std::vector<Descriptor>& descriptors, int cameras, int capacity) {
  FrameFeatures f(cameras, capacity);
  for (int c = 0; c < cameras; ++c) {
    f.present[static_cast<std::size_t>(c)] = 1;
    f.sets[static_cast<std::size_t>(c)].count = 0;
  }
  for (std::size_t i = 0; i < descriptors.size(); ++i) {
    FeatureSet& set = f.sets[i % static_cast<std::size_t>(cameras)];
    set.descriptors[static_cast<std::size_t>(set.count++)] = descriptors[i];
  }
  return f;
}

class BowFixture : public ::testing::Test {
 protected:
  BowFixture() : data_(test::clusteredDescriptors(60, 20, 10, 21)) {
    VocabularyTrainingOptions options;
    options.branching = 8;
    options.depth = 3;
    vocabulary_ = trainVocabulary(data_.descriptors, data_.image_offsets, options);
  }
  // Members of clusters [first, first + count), `per` of each, freshly drawn.
  std::vector<Descriptor> placeOf(int first, int count, int per, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<Descriptor> out;
    for (int c = first; c < first + count; ++c)
      for (int i = 0; i < per; ++i) out.push_back(test::flipBits(data_.centres[static_cast<std::size_t>(c)], 10, rng));
    return out;
  }
  test::ClusteredDescriptors data_;
  Vocabulary vocabulary_;
};

TEST_F(BowFixture, VectorsAreSortedNormalizedAndScoreOneWithThemselves) {
  FrameWords words(3, 200);
  words.compute(vocabulary_, frameOf(placeOf(0, 20, 5, 1), 3, 200));
  const BowVector& v = words.bow();
  ASSERT_GT(v.size(), 10);
  double sum = 0;
  for (int i = 0; i < v.size(); ++i) {
    sum += v.entries()[static_cast<std::size_t>(i)].weight;
    if (i > 0) {
      EXPECT_LT(v.entries()[static_cast<std::size_t>(i - 1)].word, v.entries()[static_cast<std::size_t>(i)].word);
    }
  }
  EXPECT_NEAR(sum, 1.0, 1e-5);
  EXPECT_NEAR(bowSimilarity(v, v), 1.0, 1e-5);
}

TEST_F(BowFixture, APlaceIsTheSameWhicheverCameraSeesWhat) {
  // The same features over 1 camera or spread over 4: the same vector.
  const auto place = placeOf(10, 20, 5, 2);
  FrameWords one(1, 400), four(4, 400);
  one.compute(vocabulary_, frameOf(place, 1, 400));
  four.compute(vocabulary_, frameOf(place, 4, 400));
  EXPECT_NEAR(bowSimilarity(one.bow(), four.bow()), 1.0, 1e-5);
}

TEST_F(BowFixture, SimilarityFallsWithTheShareOfSharedStructure) {
  FrameWords a(2, 400), b(2, 400), c(2, 400);
  a.compute(vocabulary_, frameOf(placeOf(0, 20, 5, 3), 2, 400));
  b.compute(vocabulary_, frameOf(placeOf(10, 20, 5, 4), 2, 400));  // half the clusters in common, new draws
  c.compute(vocabulary_, frameOf(placeOf(40, 20, 5, 5), 2, 400));  // none in common
  const float half = bowSimilarity(a.bow(), b.bow());
  EXPECT_GT(half, 0.3f);
  EXPECT_LT(half, 0.7f);
  EXPECT_LT(bowSimilarity(a.bow(), c.bow()), 0.05f);
}

TEST_F(BowFixture, ComputingWordsAllocatesNothing) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  FrameWords words(3, 200);
  const FrameFeatures f = frameOf(placeOf(0, 20, 5, 1), 3, 200);
  alloc::ThreadScope scope;
  for (int i = 0; i < 3; ++i) words.compute(vocabulary_, f);
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace mcslam
