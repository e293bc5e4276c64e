// Subpixel alignment along the epipolar direction on synthetic image pairs: a smooth random texture seen by a
// second camera rotated, scaled, shifted by a fraction of a pixel and with another gain and bias.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "integer_image.hpp"
#include "mcslam/features/epipolar_alignment.hpp"

using namespace mcslam;

namespace {

// Sum of sinusoids with wavelengths of 4-16 px (the detail around a FAST corner): band-limited, so bilinear
// sampling of the rendered image is close to the function itself.
struct Texture {
  double a[12], kx[12], ky[12], phase[12];
  explicit Texture(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    for (int k = 0; k < 12; ++k) {
      const double wavelength = 4 + 12 * u(rng), angle = 2 * M_PI * u(rng);
      kx[k] = 2 * M_PI / wavelength * std::cos(angle);
      ky[k] = 2 * M_PI / wavelength * std::sin(angle);
      a[k] = 8 + 8 * u(rng);
      phase[k] = 2 * M_PI * u(rng);
    }
  }
  double operator()(double x, double y) const {
    double v = 128;
    for (int k = 0; k < 12; ++k) v += a[k] * std::sin(kx[k] * x + ky[k] * y + phase[k]);
    return v;
  }
};

// Image whose pixel q shows the texture at M^-1 (q - t): texture point p appears at M p + t.
Image render(const Texture& tex, const Mat2& M, const Vec2& t, double gain, double bias) {
  Image im(240, 200);
  const Mat2 Minv = M.inverse();
  for (int y = 0; y < im.height(); ++y) {
    for (int x = 0; x < im.width(); ++x) {
      const Vec2 p = Minv * (Vec2(x, y) - t);
      im.row(y)[x] = static_cast<uint8_t>(std::clamp(std::lround(gain * tex(p.x(), p.y()) + bias), 0L, 255L));
    }
  }
  return im;
}

Mat2 rotationScale(double degrees, double scale) {
  const double a = degrees * M_PI / 180;
  Mat2 R;
  R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  return scale * R;
}

}  // namespace

TEST(EpipolarAlignment, RecoversSubpixelShiftOfRotatedScaledPatch) {
  const Texture tex(7);
  const Image ref = render(tex, Mat2::Identity(), Vec2::Zero(), 1.0, 0.0);
  const EpipolarAlignmentOptions options;
  int trials = 0;
  for (const double degrees : {0.0, 25.0, 90.0, 180.0}) {
    for (const double scale : {1.0, 1.15}) {
      const Mat2 M = rotationScale(degrees, scale);
      const Vec2 centre(120, 100), t = centre - M * centre + Vec2(0.37, 0.81);  // about the image centre
      const Image image = render(tex, M, t, 0.8, 20.0);
      for (const Vec2& ref_uv : {Vec2(110, 95), Vec2(125.5, 104.25)}) {
        const Vec2 truth = M * ref_uv + t;
        const Vec2 direction = Vec2(std::cos(0.3), std::sin(0.3));
        for (const double start : {-0.7, 0.45}) {  // the partner keypoint's rounding along the curve
          const EpipolarAlignment a = alignAlongEpipolar(ref.view(), ref_uv, image.view(), truth + start * direction,
                                                         direction, M, 1.0, 1.0, options);
          ASSERT_TRUE(a.ok()) << degrees << " deg, scale " << scale << ", zncc " << a.zncc;
          EXPECT_LT((a.uv - truth).norm(), 0.1) << degrees << " deg, scale " << scale;
          EXPECT_GT(a.zncc, 0.95);
          EXPECT_GT(a.sigma_px, 0.0);
          EXPECT_LT(a.sigma_px, 0.2);
          ++trials;
        }
      }
    }
  }
  EXPECT_EQ(trials, 32);
}

// The octave scale spaces the samples: a coarse keypoint is aligned on its own scale.
TEST(EpipolarAlignment, CoarseOctaveSpacingStillConverges) {
  const Texture tex(11);
  const Image ref = render(tex, Mat2::Identity(), Vec2::Zero(), 1.0, 0.0);
  const Mat2 M = rotationScale(10, 1.0);
  const Vec2 t(-8.6, 3.3);
  const Image image = render(tex, M, t, 1.1, -10.0);
  const Vec2 ref_uv(120, 100), truth = M * ref_uv + t, direction(1, 0);
  const EpipolarAlignment a =
      alignAlongEpipolar(ref.view(), ref_uv, image.view(), truth + Vec2(1.2, 0), direction, M, 2.07, 2.07, {});
  ASSERT_TRUE(a.ok());
  EXPECT_LT((a.uv - truth).norm(), 0.1);
}

TEST(EpipolarAlignment, RejectsPatchesOfDifferentTexture) {
  const Image ref = render(Texture(3), Mat2::Identity(), Vec2::Zero(), 1.0, 0.0);
  int rejected = 0, trials = 0;
  for (unsigned seed = 100; seed < 110; ++seed) {
    const Image other = render(Texture(seed), Mat2::Identity(), Vec2::Zero(), 1.0, 0.0);
    for (const Vec2& uv : {Vec2(60, 50), Vec2(100, 70), Vec2(150, 120)}) {
      const EpipolarAlignment a =
          alignAlongEpipolar(ref.view(), uv, other.view(), uv, Vec2(1, 0), Mat2::Identity(), 1.0, 1.0, {});
      ++trials;
      rejected += a.status == AlignmentStatus::Disagrees ? 1 : 0;
      if (a.status != AlignmentStatus::Disagrees)
        std::printf("seed %u zncc %.3f shift %.3f status %d\n", seed, a.zncc, a.shift, int(a.status));
    }
  }
  EXPECT_EQ(rejected, trials);
}

TEST(EpipolarAlignment, NotRefinableWithoutTextureAlongTheDirectionOrOutsideTheImage) {
  // Stripes along the search direction: no information about the shift.
  Image stripes(100, 100);
  for (int y = 0; y < 100; ++y) {
    for (int x = 0; x < 100; ++x) stripes.row(y)[x] = static_cast<uint8_t>(128 + 60 * std::sin(y * 0.7));
  }
  const EpipolarAlignment flat = alignAlongEpipolar(stripes.view(), Vec2(50, 50), stripes.view(), Vec2(50, 50),
                                                    Vec2(1, 0), Mat2::Identity(), 1.0, 1.0, {});
  EXPECT_NE(flat.status, AlignmentStatus::Ok);
  const EpipolarAlignment outside = alignAlongEpipolar(stripes.view(), Vec2(2, 50), stripes.view(), Vec2(50, 50),
                                                       Vec2(1, 0), Mat2::Identity(), 1.0, 1.0, {});
  EXPECT_EQ(outside.status, AlignmentStatus::NotRefinable);
}

// A patch of one edge measures that edge's disparity: its information lies on the edge, not at the patch's
// centre (a corner beside a silhouette against a flat background).
TEST(EpipolarAlignment, InformationCentroidMovesTowardTheOnlyEdge) {
  Image step(100, 100);
  for (int y = 0; y < 100; ++y) {
    for (int x = 0; x < 100; ++x) step.row(y)[x] = x < 52 ? 160 : 80;  // the edge between columns 51 and 52
  }
  AlignmentTemplate t;
  ASSERT_TRUE(makeAlignmentTemplate(step.view(), Vec2(49, 50), 1.0, {}, t));
  const Vec2 c = informationCentroid(t);
  // The central differences straddle the edge at offsets 2 and 3; with the mean removed (as the residual removes
  // it) the other five columns keep a small share of the information: (2 * 25 * 2.5 - 5 * 4 * 1) / (50 + 20).
  EXPECT_NEAR(c.x(), 1.5, 0.01);
  EXPECT_NEAR(c.y(), 0.0, 1e-6);
  // A textured patch keeps its centre.
  const Image tex = render(Texture(5), Mat2::Identity(), Vec2::Zero(), 1.0, 0.0);
  ASSERT_TRUE(makeAlignmentTemplate(tex.view(), Vec2(120, 100), 1.0, {}, t));
  EXPECT_LT(informationCentroid(t).norm(), 1.0);
}

// The vector kernels (SSE2 on x86-64, NEON on AArch64) and the portable ones give identical templates and
// alignments, and the same as recorded on x86-64: the templates bit for bit, the alignments to 1e-9 px (their double
// arithmetic around the kernels goes through Eigen, whose AArch64 products use fused multiply-adds). On an image
// made of integers only, the same bytes everywhere; tools/test-arm64.sh runs it on an arm64 build under qemu-user.
TEST(EpipolarAlignment, SameResultsOnEveryArchitectureAndKernel) {
  // Recorded on x86-64.
  constexpr uint64_t kTemplates = 0x0b06d7e8749a7405, kStatuses = 0x92007402a7e5cb5f;
  constexpr double kShiftSum = 207.01542749239491, kZnccSum = 526.14830390593272;
  const Image image = test::integerFrame(240, 200, 3);
  EpipolarAlignmentOptions simd, portable;
  portable.use_simd = false;
  Mat2 A;
  A << 1.03125, 0.0625, -0.046875, 0.984375;
  test::Fnv1a templates, statuses;
  double shift_sum = 0, zncc_sum = 0;
  int ok = 0;
  for (int y = 20; y < 180; y += 7) {
    for (int x = 20; x < 220; x += 9) {
      const Vec2 uv(x + 0.25 * (y % 4), y + 0.125 * (x % 8));
      const double spacing = (x + y) % 3 == 0 ? 1.2 : 1.0;
      AlignmentTemplate a, b;
      const bool made = makeAlignmentTemplate(image.view(), uv, spacing, simd, a);
      ASSERT_EQ(makeAlignmentTemplate(image.view(), uv, spacing, portable, b), made);
      if (!made) continue;
      const size_t bytes = sizeof(float) * static_cast<size_t>(a.padded);
      ASSERT_EQ(std::memcmp(a.value, b.value, bytes), 0);
      ASSERT_EQ(std::memcmp(a.dx, b.dx, bytes), 0);
      ASSERT_EQ(std::memcmp(a.dy, b.dy, bytes), 0);
      templates.bytes(a.value, bytes);
      templates.bytes(a.dx, bytes);
      templates.bytes(a.dy, bytes);
      // The partner: the same image, started off the point along a direction, through a mild affine warp.
      // Unit directions from Pythagorean triples: no libm, the same doubles everywhere.
      static const double kTriples[6][2] = {{3, 4}, {-5, 12}, {8, -15}, {-7, -24}, {20, 21}, {12, -35}};
      const double* t = kTriples[(x * 7 + y) % 6];
      const double norm = std::sqrt(t[0] * t[0] + t[1] * t[1]);
      const Vec2 direction(t[0] / norm, t[1] / norm);
      const Vec2 start = uv + 0.4 * direction;
      const EpipolarAlignment p = alignAlongEpipolar(a, image.view(), start, direction, A, spacing, simd);
      const EpipolarAlignment q = alignAlongEpipolar(b, image.view(), start, direction, A, spacing, portable);
      ASSERT_EQ(p.status, q.status);
      ASSERT_EQ(p.uv, q.uv);
      ASSERT_EQ(p.shift, q.shift);
      ASSERT_EQ(p.sigma_px, q.sigma_px);
      ASSERT_EQ(p.zncc, q.zncc);
      statuses.add(p.status);
      shift_sum += std::abs(p.shift);
      zncc_sum += p.zncc;
      ok += p.ok();
    }
  }
  EXPECT_GT(ok, 100);
  std::printf("templates 0x%016llx statuses 0x%016llx shift sum %.17g zncc sum %.17g (%d aligned)\n",
              static_cast<unsigned long long>(templates.h), static_cast<unsigned long long>(statuses.h), shift_sum,
              zncc_sum, ok);
  EXPECT_EQ(templates.h, kTemplates);
  EXPECT_EQ(statuses.h, kStatuses);
  EXPECT_NEAR(shift_sum, kShiftSum, 1e-9);
  EXPECT_NEAR(zncc_sum, kZnccSum, 1e-9);
}
