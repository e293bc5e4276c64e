// The ORB extractor's contract: FAST scores, SIMD = scalar, budgets, spread, sizes, orientation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "integer_image.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/features/orb_extractor.hpp"
#include "orb_fast.hpp"
#include "orb_grid.hpp"
#include "orb_pyramid.hpp"
#include "orb_test_images.hpp"

namespace mcslam {
namespace {

using test::texturedFrame;

const Image& frame640() {
  static const Image image = texturedFrame(640, 480, 21);
  return image;
}

FeatureSet extractWith(const OrbOptions& options, const ImageView& view, int max_w = 640, int max_h = 480) {
  OrbExtractor extractor(options, max_w, max_h);
  FeatureSet out(options.max_features);
  EXPECT_EQ(extractor.extract(view, out), OrbStatus::kOk);
  return out;
}

void expectSame(const FeatureSet& a, const FeatureSet& b) {
  ASSERT_EQ(a.count, b.count);
  for (int i = 0; i < a.count; ++i) {
    const Keypoint &p = a.keypoints[i], &q = b.keypoints[i];
    ASSERT_EQ(p.x, q.x) << i;
    ASSERT_EQ(p.y, q.y) << i;
    ASSERT_EQ(p.angle, q.angle) << i;
    ASSERT_EQ(p.response, q.response) << i;
    ASSERT_EQ(p.octave, q.octave) << i;
    ASSERT_EQ(a.descriptors[i], b.descriptors[i]) << i;
  }
}

// FAST-9 score straight from its definition.
int bruteForceFastScore(const Image& img, int x, int y) {
  static const int cx[16] = {0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3, -3, -3, -2, -1};
  static const int cy[16] = {-3, -3, -2, -1, 0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3};
  const int c = img.data()[y * img.width() + x];
  int best = 0;
  for (int start = 0; start < 16; ++start) {
    int bright = 255, dark = 255;
    for (int k = 0; k < 9; ++k) {
      const int p = img.data()[(y + cy[(start + k) % 16]) * img.width() + x + cx[(start + k) % 16]];
      bright = std::min(bright, std::max(p - c, 0));
      dark = std::min(dark, std::max(c - p, 0));
    }
    best = std::max({best, bright, dark});
  }
  return best;
}

TEST(OrbFast, ScoresMatchTheDefinitionOnEveryKernel) {
  // kWide is the AVX2 kernel where this CPU has it (else it runs kNative again): say which one was checked.
  std::printf("FAST kernels checked: scalar, %s, %s\n", orb_detail::fastHasNativeSimd() ? "16-lane SIMD" : "scalar",
              orb_detail::fastHasWideSimd() ? "32-lane AVX2" : "16-lane (no AVX2 here)");
  const Image& img = frame640();
  std::vector<uint8_t> row(img.width() + 16);
  int corners_seen = 0;
  for (int threshold : {7, 20, 40}) {
    for (int y = 3; y < 200; ++y) {
      for (auto backend :
           {orb_detail::FastBackend::kScalar, orb_detail::FastBackend::kNative, orb_detail::FastBackend::kWide}) {
        // An odd segment end exercises the partial last group.
        const int x0 = 3, x1 = img.width() - 3 - (y % 7);
        const int n = orb_detail::fastScoreRow(img.data(), img.width(), y, x0, x1, threshold, row.data(), backend);
        int counted = 0;
        for (int x = x0; x < x1; ++x) {
          const int expected = bruteForceFastScore(img, x, y);
          ASSERT_EQ(row[x - x0], expected > threshold ? expected : 0) << "x " << x << " y " << y << " t " << threshold;
          counted += row[x - x0] != 0;
        }
        EXPECT_EQ(n, counted);
        corners_seen += counted;
      }
    }
  }
  EXPECT_GT(corners_seen, 1000);  // the frame has corners at all three thresholds
}

// The 3x3 suppression against its definition (ties go to the later pixel in raster order), on both kernels,
// on sparse random score maps with many ties, for rects of every alignment and a capacity that runs out.
TEST(OrbFast, LocalMaximaMatchTheDefinitionOnBothKernels) {
  constexpr int kW = 97, kH = 41, kStride = 128;
  std::vector<uint8_t> map(static_cast<size_t>(kStride) * (kH + 2) + 64, 0);
  uint32_t state = 12345;
  auto next = [&] { return state = state * 1664525u + 1013904223u; };
  int total = 0;
  for (int round = 0; round < 60; ++round) {
    std::fill(map.begin(), map.end(), 0);
    for (int y = 1; y <= kH; ++y) {
      for (int x = 1; x <= kW; ++x) {
        if (next() % 3 == 0) map[static_cast<size_t>(y) * kStride + x] = static_cast<uint8_t>(1 + (next() >> 24) % 4);
      }
    }
    const orb_detail::ConstPlane plane{map.data(), kW + 2, kH + 2, kStride};
    const orb_detail::Rect rect{1 + round % 17, 1 + round % 5, kW + 1 - round % 13, kH + 1 - round % 3};
    // The definition, with the frame outside the rect read as it is (as the extractor's fallback cells do).
    std::vector<orb_detail::Corner> expected;
    for (int y = rect.y0; y < rect.y1; ++y) {
      for (int x = rect.x0; x < rect.x1; ++x) {
        auto at = [&](int dx, int dy) { return int(map[static_cast<size_t>(y + dy) * kStride + x + dx]); };
        const int s = at(0, 0);
        if (s == 0) continue;
        bool is_max = true;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            if (dx == 0 && dy == 0) continue;
            const bool earlier = dy < 0 || (dy == 0 && dx < 0);
            is_max = is_max && (earlier ? s >= at(dx, dy) : s > at(dx, dy));
          }
        }
        if (is_max) expected.push_back({x, y, static_cast<float>(s)});
      }
    }
    const size_t capacity = round % 4 == 3 ? expected.size() / 2 : expected.size() + 5;
    for (const bool simd : {false, true}) {
      std::vector<orb_detail::Corner> got;
      got.reserve(capacity);
      const size_t reserved = got.capacity();
      orb_detail::collectLocalMaxima(plane, rect, got, simd);
      ASSERT_EQ(got.size(), std::min(expected.size(), reserved)) << "round " << round << " simd " << simd;
      for (size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i].x, expected[i].x) << "round " << round << " simd " << simd;
        ASSERT_EQ(got[i].y, expected[i].y);
        ASSERT_EQ(got[i].score, expected[i].score);
      }
    }
    total += static_cast<int>(expected.size());
  }
  EXPECT_GT(total, 1000);
}

TEST(OrbExtractor, SimdAndScalarKernelsGiveIdenticalFeatures) {
  OrbOptions simd, scalar;
  scalar.use_simd = false;
  const FeatureSet a = extractWith(simd, frame640().view());
  const FeatureSet b = extractWith(scalar, frame640().view());
  EXPECT_EQ(a.count, simd.max_features);
  expectSame(a, b);
}

// The same image gives the same keypoints and descriptors on every architecture and every kernel: an image made of
// integers only, each kernel's output from the vector (SSE2/AVX2 or NEON) and the portable path, and digests of them
// recorded on x86-64. tools/test-arm64.sh runs this test on an arm64 build under qemu-user.
TEST(OrbExtractor, SameFeaturesOnEveryArchitectureAndKernel) {
  // Recorded on x86-64 (AVX2 and SSE2 kernels, and the portable ones, agree there).
  constexpr uint64_t kImage = 0x0f6064f9e469504e, kFast = 0x55560c9df8960aa4, kBlur = 0x3969d2e0910d68bf,
                     kDownscale = 0xf036ca1b8695bad4, kFeatures = 0x21e6c9120c6a6bab;
  const Image img = test::integerFrame(640, 480, 7);
  const int w = img.width(), h = img.height();
  test::Fnv1a image_digest;
  image_digest.bytes(img.data(), static_cast<size_t>(w) * static_cast<size_t>(h));

  // FAST scores of every row at a low threshold, from each kernel.
  std::vector<uint8_t> padded(static_cast<size_t>(w) * static_cast<size_t>(h) + 64, 0);
  std::copy(img.data(), img.data() + static_cast<size_t>(w) * static_cast<size_t>(h), padded.begin());
  test::Fnv1a fast_digest;
  std::vector<uint8_t> scalar_row(static_cast<size_t>(w)), row(static_cast<size_t>(w));
  int corners = 0;
  for (int y = 3; y < h - 3; ++y) {
    const int n = orb_detail::fastScoreRow(padded.data(), w, y, 3, w - 3, 10, scalar_row.data(),
                                           orb_detail::FastBackend::kScalar);
    for (auto backend : {orb_detail::FastBackend::kNative, orb_detail::FastBackend::kWide}) {
      ASSERT_EQ(orb_detail::fastScoreRow(padded.data(), w, y, 3, w - 3, 10, row.data(), backend), n) << y;
      ASSERT_TRUE(std::equal(row.begin(), row.begin() + (w - 6), scalar_row.begin())) << "row " << y;
    }
    fast_digest.bytes(scalar_row.data(), static_cast<size_t>(w - 6));
    corners += n;
  }
  EXPECT_GT(corners, 5000);

  // The descriptor's smoothing and the pyramid's resampling, both kernels.
  const orb_detail::ConstPlane source(padded.data(), w, h, w);
  std::vector<uint8_t> tmp(padded.size()), blurred(padded.size()), blurred_portable(padded.size());
  orb_detail::gaussianBlur7(source, {blurred.data(), w, h, w}, {tmp.data(), w, h, w}, true);
  orb_detail::gaussianBlur7(source, {blurred_portable.data(), w, h, w}, {tmp.data(), w, h, w}, false);
  ASSERT_EQ(blurred, blurred_portable);
  test::Fnv1a blur_digest;
  blur_digest.bytes(blurred.data(), static_cast<size_t>(w) * static_cast<size_t>(h));
  const int dw = static_cast<int>(std::lround(w / 1.2)), dh = static_cast<int>(std::lround(h / 1.2));
  std::vector<int32_t> src_x(static_cast<size_t>(w) + 1);
  std::vector<uint32_t> weights(static_cast<size_t>(w) + 1);
  std::vector<int16_t> resample_row(static_cast<size_t>(w) + 1);
  std::vector<uint8_t> small(padded.size()), small_portable(padded.size());
  const orb_detail::DownscaleScratch scratch{src_x.data(), weights.data(), resample_row.data()};
  orb_detail::downscale(source, {small.data(), dw, dh, w}, 1.2f, scratch, true);
  orb_detail::downscale(source, {small_portable.data(), dw, dh, w}, 1.2f, scratch, false);
  ASSERT_EQ(small, small_portable);
  test::Fnv1a downscale_digest;
  downscale_digest.bytes(small.data(), static_cast<size_t>(w) * static_cast<size_t>(dh));

  // The whole extractor: keypoints (position, angle, response, octave) and descriptors, bit for bit.
  OrbOptions simd, portable;
  portable.use_simd = false;
  const FeatureSet a = extractWith(simd, img.view());
  const FeatureSet b = extractWith(portable, img.view());
  EXPECT_EQ(a.count, simd.max_features);
  expectSame(a, b);
  test::Fnv1a features_digest;
  for (int i = 0; i < a.count; ++i) {
    const Keypoint& k = a.keypoints[i];
    features_digest.add(k.x);
    features_digest.add(k.y);
    features_digest.add(k.angle);
    features_digest.add(k.response);
    features_digest.add(k.octave);
    features_digest.add(a.descriptors[i]);
  }

  std::printf("digests: image 0x%016llx fast 0x%016llx blur 0x%016llx downscale 0x%016llx features 0x%016llx\n",
              static_cast<unsigned long long>(image_digest.h), static_cast<unsigned long long>(fast_digest.h),
              static_cast<unsigned long long>(blur_digest.h), static_cast<unsigned long long>(downscale_digest.h),
              static_cast<unsigned long long>(features_digest.h));
  EXPECT_EQ(image_digest.h, kImage) << "the test image itself differs";
  EXPECT_EQ(fast_digest.h, kFast);
  EXPECT_EQ(blur_digest.h, kBlur);
  EXPECT_EQ(downscale_digest.h, kDownscale);
  EXPECT_EQ(features_digest.h, kFeatures);
}

TEST(OrbExtractor, FillsTheBudgetInsideTheImageAndSpreadsIt) {
  OrbOptions options;
  const FeatureSet f = extractWith(options, frame640().view());
  ASSERT_EQ(f.count, options.max_features);
  const auto scales = orbLevelScales(options);
  int per_level[8] = {};
  int blocks[6][8] = {};  // 80x80 blocks
  for (int i = 0; i < f.count; ++i) {
    const Keypoint& k = f.keypoints[i];
    ASSERT_GE(k.octave, 0);
    ASSERT_LT(k.octave, options.levels);
    const float margin = options.edge_margin * scales.scale[k.octave] - 1.0f;
    EXPECT_GE(k.x, margin);
    EXPECT_GE(k.y, margin);
    EXPECT_LE(k.x, 639 - margin);
    EXPECT_LE(k.y, 479 - margin);
    EXPECT_GE(k.angle, 0.0f);
    EXPECT_LT(k.angle, 2 * std::numbers::pi_v<float>);
    EXPECT_GT(k.response, 0.0f);
    ++per_level[k.octave];
    ++blocks[std::min(5, static_cast<int>(k.y / 80))][std::min(7, static_cast<int>(k.x / 80))];
  }
  // Every level contributes, finer levels more (ORB's geometric split).
  for (int l = 0; l < options.levels; ++l) EXPECT_GT(per_level[l], 0) << l;
  EXPECT_GT(per_level[0], per_level[options.levels - 1]);
  // Spread: against the strongest-only choice, more 80x80 blocks hold features and the fullest holds
  // fewer; nearly all blocks are used (the frame has a few flat, saturated patches).
  OrbOptions strongest = options;
  strongest.spacing_ratio = 0;
  const FeatureSet g = extractWith(strongest, frame640().view());
  int strongest_blocks[6][8] = {};
  for (int i = 0; i < g.count; ++i)
    ++strongest_blocks[std::min(5, static_cast<int>(g.keypoints[i].y / 80))]
                      [std::min(7, static_cast<int>(g.keypoints[i].x / 80))];
  auto occupied = [](const int(&b)[6][8]) {
    int n = 0;
    for (auto& r : b)
      for (int v : r) n += v > 0;
    return n;
  };
  auto fullest = [](const int(&b)[6][8]) {
    int n = 0;
    for (auto& r : b)
      for (int v : r) n = std::max(n, v);
    return n;
  };
  EXPECT_GE(occupied(blocks), 44);
  EXPECT_GE(occupied(blocks), occupied(strongest_blocks));
  EXPECT_LT(fullest(blocks), fullest(strongest_blocks));
  // No two features of a level at the same pixel.
  for (int i = 0; i < f.count; ++i) {
    for (int j = i + 1; j < f.count; ++j) {
      const Keypoint &p = f.keypoints[i], &q = f.keypoints[j];
      ASSERT_FALSE(p.octave == q.octave && p.x == q.x && p.y == q.y);
    }
  }
}

TEST(OrbExtractor, LowThresholdFallbackFindsFeaturesInWeakTexture) {
  // A faint texture: few corners pass threshold 20, many pass 7.
  Image faint(320, 240);
  const Image source = texturedFrame(320, 240, 5);
  for (int i = 0; i < 320 * 240; ++i) faint.data()[i] = static_cast<uint8_t>(100 + source.data()[i] / 4);
  OrbOptions with_fallback, without;
  with_fallback.max_features = without.max_features = 500;
  without.min_fast_threshold = without.fast_threshold;
  const FeatureSet a = extractWith(with_fallback, faint.view(), 320, 240);
  const FeatureSet b = extractWith(without, faint.view(), 320, 240);
  EXPECT_GT(a.count, b.count + 100) << a.count << " vs " << b.count;
}

TEST(OrbExtractor, EmptyTinyAndOversizedImages) {
  OrbExtractor extractor(OrbOptions{}, 640, 480);
  FeatureSet out(1000);
  out.count = 5;
  EXPECT_EQ(extractor.extract(ImageView{}, out), OrbStatus::kOk);
  EXPECT_EQ(out.count, 0);
  for (int size : {1, 2, 10, 31, 32, 33}) {
    Image tiny(size, size);
    std::fill(tiny.data(), tiny.data() + size * size, uint8_t{77});
    for (int i = 0; i < size * size; i += 3) tiny.data()[i] = 200;
    EXPECT_EQ(extractor.extract(tiny.view(), out), OrbStatus::kOk) << size;
    EXPECT_EQ(out.count, 0) << size;
  }
  Image wide(641, 100);
  EXPECT_EQ(extractor.extract(wide.view(), out), OrbStatus::kImageTooLarge);
  EXPECT_EQ(out.count, 0);
  FeatureSet small(999);
  EXPECT_EQ(extractor.extract(frame640().view(), small), OrbStatus::kOutputTooSmall);
  EXPECT_EQ(small.count, 0);
  // A flat image has no corner anywhere.
  Image flat(640, 480);
  std::fill(flat.data(), flat.data() + 640 * 480, uint8_t{90});
  EXPECT_EQ(extractor.extract(flat.view(), out), OrbStatus::kOk);
  EXPECT_EQ(out.count, 0);
}

TEST(OrbExtractor, SmallerImagesAndStridedViewsWork) {
  // A 300x200 window of the frame, seen through the frame's stride, equals the same pixels copied.
  const Image& big = frame640();
  const ImageView window{big.data() + 50 * big.width() + 70, 300, 200, big.width()};
  Image copy(300, 200);
  for (int y = 0; y < 200; ++y) std::copy(window.row(y), window.row(y) + 300, copy.row(y));
  OrbOptions options;
  options.max_features = 300;
  const FeatureSet a = extractWith(options, window);
  const FeatureSet b = extractWith(options, copy.view());
  EXPECT_GT(a.count, 200);
  expectSame(a, b);
  // And the same extractor reused for the full frame afterwards gives the fresh-extractor answer.
  OrbExtractor reused(options, 640, 480);
  FeatureSet c(300), d(300);
  reused.extract(window, c);
  reused.extract(big.view(), c);
  OrbExtractor fresh(options, 640, 480);
  fresh.extract(big.view(), d);
  expectSame(c, d);
}

TEST(OrbExtractor, RotatingTheImageBy90DegreesRotatesAnglesAndKeepsDescriptors) {
  // Exact 90-degree rotation (no resampling at level 0): FAST, the centroid and the smoothing are
  // symmetric under it, so each level-0 keypoint reappears with its angle + 90 degrees and, the
  // pattern being steered, nearly the same descriptor.
  const Image& src = frame640();
  const int w = src.width(), h = src.height();
  Image rotated(h, w);  // (x, y) -> (h - 1 - y, x): clockwise on screen, +90 degrees with y down
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) rotated.row(x)[h - 1 - y] = src.data()[y * w + x];
  OrbOptions options;
  options.levels = 1;
  options.max_features = 300;
  options.spacing_ratio = 0;  // strongest first: the same corners in both images
  const FeatureSet a = extractWith(options, src.view(), 640, 640);
  const FeatureSet b = extractWith(options, rotated.view(), 640, 640);
  int found = 0, close_descriptors = 0;
  for (int i = 0; i < a.count; ++i) {
    const float rx = h - 1 - a.keypoints[i].y, ry = a.keypoints[i].x;
    for (int j = 0; j < b.count; ++j) {
      if (b.keypoints[j].x != rx || b.keypoints[j].y != ry) continue;
      ++found;
      float turn = b.keypoints[j].angle - a.keypoints[i].angle;
      if (turn < 0) turn += 2 * std::numbers::pi_v<float>;
      EXPECT_NEAR(turn, std::numbers::pi_v<float> / 2, 1e-3);
      close_descriptors += hammingDistance(a.descriptors[i], b.descriptors[j]) <= 16;
    }
  }
  EXPECT_GT(found, 250);  // ties at the budget's edge may differ
  EXPECT_GT(close_descriptors, 0.9 * found);
}

TEST(OrbExtractor, IsDeterministicAcrossRunsAndInstances) {
  OrbOptions options;
  OrbExtractor one(options, 640, 480), two(options, 640, 480);
  FeatureSet a(1000), b(1000), c(1000);
  one.extract(frame640().view(), a);
  one.extract(frame640().view(), b);
  two.extract(frame640().view(), c);
  expectSame(a, b);
  expectSame(a, c);
}

TEST(OrbExtractor, LevelScalesAndOptionChecks) {
  OrbOptions options;
  const OrbLevelScales s = orbLevelScales(options);
  ASSERT_EQ(s.scale.size(), 8u);
  for (int l = 0; l < 8; ++l) {
    EXPECT_NEAR(s.scale[l], std::pow(1.2, l), 1e-5);
    EXPECT_NEAR(s.sigma2[l], std::pow(1.44, l), 1e-4);
    EXPECT_NEAR(s.inv_scale[l] * s.scale[l], 1.0f, 1e-6);
    EXPECT_NEAR(s.inv_sigma2[l] * s.sigma2[l], 1.0f, 1e-6);
  }
  EXPECT_EQ(OrbExtractor(options, 10, 10).levelScales().scale, s.scale);
  auto bad = [](auto change) {
    OrbOptions o;
    change(o);
    EXPECT_THROW(OrbExtractor(o, 100, 100), InputError);
  };
  bad([](OrbOptions& o) { o.levels = 0; });
  bad([](OrbOptions& o) { o.scale_factor = 1.0f; });
  bad([](OrbOptions& o) { o.max_features = 0; });
  bad([](OrbOptions& o) { o.edge_margin = 10; });
  bad([](OrbOptions& o) { o.min_fast_threshold = 30; });
}

}  // namespace
}  // namespace mcslam
