// The keyframe database: scores equal the brute-force similarity; erased places are gone and their slots reused;
// a place with more words than the capacity keeps its heaviest; queries allocate nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "alloc_testing.hpp"
#include "mcslam/recognition/place_database.hpp"

namespace mcslam {
namespace {

// A random normalized vector over `words` words with about `size` entries.
BowVector randomVector(int words, int size, std::mt19937_64& rng) {
  std::vector<WordId> ids(static_cast<std::size_t>(size));
  std::uniform_int_distribution<WordId> word(0, words - 1);
  for (WordId& w : ids) w = word(rng);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  BowVector v(size);
  std::uniform_real_distribution<float> weight(0.1f, 1.0f);
  for (WordId w : ids) v.push(w, weight(rng));
  v.normalize();
  return v;
}

TEST(PlaceDatabase, ScoresAreTheSimilarityOfTheVectors) {
  std::mt19937_64 rng(5);
  PlaceDatabase db(500, 40, 200);
  std::vector<BowVector> stored;
  for (int p = 0; p < 40; ++p) {
    stored.push_back(randomVector(500, 100, rng));
    db.insert(p, stored.back());
  }
  EXPECT_EQ(db.size(), 40);
  const BowVector query = randomVector(500, 100, rng);
  std::vector<PlaceScore> out(40);
  const int n = db.query(query, 0.0f, out);
  ASSERT_EQ(n, 40);  // 100 of 500 words each: every pair shares some
  for (int i = 0; i < n; ++i) {
    const PlaceScore& s = out[static_cast<std::size_t>(i)];
    EXPECT_NEAR(s.score, bowSimilarity(query, stored[static_cast<std::size_t>(s.place)]), 1e-5);
    if (i > 0) {
      EXPECT_GE(out[static_cast<std::size_t>(i - 1)].score, s.score);
    }
  }
  // The place itself comes first with score 1.
  EXPECT_EQ(db.query(stored[17], 0.0f, std::span(out.data(), 1)), 1);
  EXPECT_EQ(out[0].place, 17);
  EXPECT_NEAR(out[0].score, 1.0f, 1e-5);
}

TEST(PlaceDatabase, ErasedPlacesAreGoneAndTheirSlotsReused) {
  std::mt19937_64 rng(6);
  PlaceDatabase db(300, 10, 100);
  std::vector<BowVector> stored;
  for (int p = 0; p < 10; ++p) {
    stored.push_back(randomVector(300, 60, rng));
    db.insert(p, stored.back());
  }
  db.erase(3);
  db.erase(3);  // twice: no effect
  EXPECT_FALSE(db.contains(3));
  EXPECT_EQ(db.size(), 9);
  std::vector<PlaceScore> out(10);
  const int n = db.query(stored[3], 0.0f, out);
  for (int i = 0; i < n; ++i) EXPECT_NE(out[static_cast<std::size_t>(i)].place, 3);
  // Reuse the slot with another place; replace a stored one in place.
  const BowVector fresh = randomVector(300, 60, rng);
  db.insert(3, fresh);
  db.insert(5, stored[3]);
  EXPECT_EQ(db.size(), 10);
  ASSERT_GE(db.query(fresh, 0.0f, std::span(out.data(), 1)), 1);
  EXPECT_EQ(out[0].place, 3);
  ASSERT_GE(db.query(stored[3], 0.0f, std::span(out.data(), 1)), 1);
  EXPECT_EQ(out[0].place, 5);
  EXPECT_NEAR(out[0].score, 1.0f, 1e-5);
  // The filter and the threshold.
  const int filtered = db.query(stored[3], 0.0f, out, [](int place) { return place != 5; });
  for (int i = 0; i < filtered; ++i) EXPECT_NE(out[static_cast<std::size_t>(i)].place, 5);
  EXPECT_EQ(db.query(stored[3], 1.5f, out), 0);
}

TEST(PlaceDatabase, APlaceKeepsItsHeaviestWords) {
  PlaceDatabase db(100, 2, 3);
  BowVector v(5);
  v.push(1, 0.1f);
  v.push(2, 0.4f);
  v.push(3, 0.05f);
  v.push(4, 0.3f);
  v.push(5, 0.15f);
  db.insert(0, v);
  BowVector probe(1);
  std::vector<PlaceScore> out(2);
  for (WordId w : {1, 2, 3, 4, 5}) {
    probe.clear();
    probe.push(w, 1.0f);
    const bool kept = w == 2 || w == 4 || w == 5;
    EXPECT_EQ(db.query(probe, 0.0f, out), kept ? 1 : 0) << "word " << w;
  }
}

TEST(PlaceDatabase, InsertingErasingAndQueryingAllocateNothing) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  std::mt19937_64 rng(8);
  PlaceDatabase db(1000, 50, 150);
  std::vector<BowVector> vectors;
  for (int i = 0; i < 60; ++i) vectors.push_back(randomVector(1000, 200, rng));  // more words than kept
  std::vector<PlaceScore> out(8);
  alloc::ThreadScope scope;
  for (int i = 0; i < 60; ++i) {
    if (i >= 50) db.erase(i - 50);
    db.insert(i % 50, vectors[static_cast<std::size_t>(i)]);
    db.query(vectors[static_cast<std::size_t>(i)], 0.01f, out);
  }
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace mcslam
