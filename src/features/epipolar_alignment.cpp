#include "mcslam/features/epipolar_alignment.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "bilinear_sample.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#define MCSLAM_ALIGN_HAVE_SSE2 1
#elif defined(__ARM_NEON) && defined(__aarch64__)
#include <arm_neon.h>
#define MCSLAM_ALIGN_HAVE_NEON 1
#endif

namespace mcslam {

namespace {

constexpr int kMaxHalf = AlignmentTemplate::kMaxHalf;
constexpr int kMaxPadded = AlignmentTemplate::kMaxPadded;
constexpr int kMaxGrid = (2 * kMaxHalf + 3) * (2 * kMaxHalf + 3);  // the template's grid keeps a ring more
constexpr int kMaxGridPadded = (kMaxGrid + 3) / 4 * 4;

bool inside(const ImageView& im, double x, double y, double ex, double ey) {
  return x - ex >= 0 && y - ey >= 0 && x + ex < im.width - 1 && y + ey < im.height - 1;
}

// Bilinear samples at count positions (a multiple of 4), written to out; the caller has checked that every
// (x, y) and (x + 1, y + 1) is inside. The portable reference; the vector kernels below compute the same lanes
// with the same operations in the same order, so all give identical floats.
void sampleBilinearPortable(const ImageView& im, const float* xs, const float* ys, int count, float* out) {
  for (int k = 0; k < count; ++k) out[k] = sampleBilinear(im, xs[k], ys[k]);
}

// Sums of products over padded arrays, in 4 lanes added in a fixed order (the result does not depend on the
// thread, the call site or the kernel).
struct Sums {
  double s[3];
};
double total4(const float* l) { return (static_cast<double>(l[0]) + l[1]) + (static_cast<double>(l[2]) + l[3]); }
Sums dot3Portable(const float* d, const float* a, const float* b, int padded) {
  float l0[4] = {}, l1[4] = {}, l2[4] = {};
  for (int g = 0; g < padded; g += 4) {
    for (int k = 0; k < 4; ++k) {
      const float v = d[g + k];
      l0[k] += v * v;
      l1[k] += v * a[g + k];
      l2[k] += v * b[g + k];
    }
  }
  return {{total4(l0), total4(l1), total4(l2)}};
}
double sumPortable(const float* v, int padded) {
  float l[4] = {};
  for (int g = 0; g < padded; g += 4) {
    for (int k = 0; k < 4; ++k) l[k] += v[g + k];
  }
  return total4(l);
}

// The pixel pairs of both rows of sample k as one 32-bit word (top pair low): the loads, not the arithmetic,
// are the per-sample work.
inline uint32_t pixelWord(const ImageView& im, int32_t x, int32_t y) {
  const uint8_t* p = im.data + static_cast<std::ptrdiff_t>(y) * im.stride + x;
  uint16_t top, bottom;
  std::memcpy(&top, p, 2);
  std::memcpy(&bottom, p + im.stride, 2);
  return static_cast<uint32_t>(top) | (static_cast<uint32_t>(bottom) << 16);
}

#if defined(MCSLAM_ALIGN_HAVE_SSE2)
void sampleBilinearSimd(const ImageView& im, const float* xs, const float* ys, int count, float* out) {
  for (int g = 0; g < count; g += 4) {
    const __m128 x = _mm_loadu_ps(xs + g), y = _mm_loadu_ps(ys + g);
    const __m128i xi = _mm_cvttps_epi32(x), yi = _mm_cvttps_epi32(y);
    const __m128 ax = _mm_sub_ps(x, _mm_cvtepi32_ps(xi)), ay = _mm_sub_ps(y, _mm_cvtepi32_ps(yi));
    alignas(16) int32_t xk[4], yk[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(xk), xi);
    _mm_store_si128(reinterpret_cast<__m128i*>(yk), yi);
    auto word = [&](int k) { return static_cast<int>(pixelWord(im, xk[k], yk[k])); };
    // Built in registers: four 32-bit stores read back as one 128-bit load would stall store forwarding.
    const __m128i w = _mm_set_epi32(word(3), word(2), word(1), word(0));
    const __m128i byte = _mm_set1_epi32(0xFF);
    const __m128 p00 = _mm_cvtepi32_ps(_mm_and_si128(w, byte));
    const __m128 p10 = _mm_cvtepi32_ps(_mm_and_si128(_mm_srli_epi32(w, 8), byte));
    const __m128 p01 = _mm_cvtepi32_ps(_mm_and_si128(_mm_srli_epi32(w, 16), byte));
    const __m128 p11 = _mm_cvtepi32_ps(_mm_srli_epi32(w, 24));
    const __m128 top = _mm_add_ps(p00, _mm_mul_ps(ax, _mm_sub_ps(p10, p00)));
    const __m128 bottom = _mm_add_ps(p01, _mm_mul_ps(ax, _mm_sub_ps(p11, p01)));
    _mm_storeu_ps(out + g, _mm_add_ps(top, _mm_mul_ps(ay, _mm_sub_ps(bottom, top))));
  }
}
double total(__m128 l) {
  alignas(16) float v[4];
  _mm_store_ps(v, l);
  return total4(v);
}
Sums dot3Simd(const float* d, const float* a, const float* b, int padded) {
  __m128 l0 = _mm_setzero_ps(), l1 = _mm_setzero_ps(), l2 = _mm_setzero_ps();
  for (int g = 0; g < padded; g += 4) {
    const __m128 v = _mm_load_ps(d + g);
    l0 = _mm_add_ps(l0, _mm_mul_ps(v, v));
    l1 = _mm_add_ps(l1, _mm_mul_ps(v, _mm_load_ps(a + g)));
    l2 = _mm_add_ps(l2, _mm_mul_ps(v, _mm_load_ps(b + g)));
  }
  return {{total(l0), total(l1), total(l2)}};
}
double sumSimd(const float* v, int padded) {
  __m128 l = _mm_setzero_ps();
  for (int g = 0; g < padded; g += 4) l = _mm_add_ps(l, _mm_load_ps(v + g));
  return total(l);
}
#elif defined(MCSLAM_ALIGN_HAVE_NEON)
// Multiplies and adds stay separate, as on x86-64, which has no fused form (non-x86 builds use -ffp-contract=off).
void sampleBilinearSimd(const ImageView& im, const float* xs, const float* ys, int count, float* out) {
  for (int g = 0; g < count; g += 4) {
    const float32x4_t x = vld1q_f32(xs + g), y = vld1q_f32(ys + g);
    const int32x4_t xi = vcvtq_s32_f32(x), yi = vcvtq_s32_f32(y);  // toward zero, as the portable cast
    const float32x4_t ax = vsubq_f32(x, vcvtq_f32_s32(xi)), ay = vsubq_f32(y, vcvtq_f32_s32(yi));
    int32_t xk[4], yk[4];
    vst1q_s32(xk, xi);
    vst1q_s32(yk, yi);
    uint32_t words[4];
    for (int k = 0; k < 4; ++k) words[k] = pixelWord(im, xk[k], yk[k]);
    const uint32x4_t w = vld1q_u32(words);
    const uint32x4_t byte = vdupq_n_u32(0xFF);
    const float32x4_t p00 = vcvtq_f32_u32(vandq_u32(w, byte));
    const float32x4_t p10 = vcvtq_f32_u32(vandq_u32(vshrq_n_u32(w, 8), byte));
    const float32x4_t p01 = vcvtq_f32_u32(vandq_u32(vshrq_n_u32(w, 16), byte));
    const float32x4_t p11 = vcvtq_f32_u32(vshrq_n_u32(w, 24));
    const float32x4_t top = vaddq_f32(p00, vmulq_f32(ax, vsubq_f32(p10, p00)));
    const float32x4_t bottom = vaddq_f32(p01, vmulq_f32(ax, vsubq_f32(p11, p01)));
    vst1q_f32(out + g, vaddq_f32(top, vmulq_f32(ay, vsubq_f32(bottom, top))));
  }
}
double total(float32x4_t l) {
  float v[4];
  vst1q_f32(v, l);
  return total4(v);
}
Sums dot3Simd(const float* d, const float* a, const float* b, int padded) {
  float32x4_t l0 = vdupq_n_f32(0), l1 = vdupq_n_f32(0), l2 = vdupq_n_f32(0);
  for (int g = 0; g < padded; g += 4) {
    const float32x4_t v = vld1q_f32(d + g);
    l0 = vaddq_f32(l0, vmulq_f32(v, v));
    l1 = vaddq_f32(l1, vmulq_f32(v, vld1q_f32(a + g)));
    l2 = vaddq_f32(l2, vmulq_f32(v, vld1q_f32(b + g)));
  }
  return {{total(l0), total(l1), total(l2)}};
}
double sumSimd(const float* v, int padded) {
  float32x4_t l = vdupq_n_f32(0);
  for (int g = 0; g < padded; g += 4) l = vaddq_f32(l, vld1q_f32(v + g));
  return total(l);
}
#endif

#if defined(MCSLAM_ALIGN_HAVE_SSE2) || defined(MCSLAM_ALIGN_HAVE_NEON)
constexpr bool kHaveSimd = true;
#else
constexpr bool kHaveSimd = false;
void sampleBilinearSimd(const ImageView& im, const float* xs, const float* ys, int count, float* out) {
  sampleBilinearPortable(im, xs, ys, count, out);
}
Sums dot3Simd(const float* d, const float* a, const float* b, int padded) { return dot3Portable(d, a, b, padded); }
double sumSimd(const float* v, int padded) { return sumPortable(v, padded); }
#endif

// The kernels of one alignment: the vector ones where the build has them and the options want them.
struct Kernels {
  bool simd;
  explicit Kernels(const EpipolarAlignmentOptions& o) : simd(kHaveSimd && o.use_simd) {}
  void sampleBilinear(const ImageView& im, const float* xs, const float* ys, int count, float* out) const {
    simd ? sampleBilinearSimd(im, xs, ys, count, out) : sampleBilinearPortable(im, xs, ys, count, out);
  }
  Sums dot3(const float* d, const float* a, const float* b, int padded) const {
    return simd ? dot3Simd(d, a, b, padded) : dot3Portable(d, a, b, padded);
  }
  double sum(const float* v, int padded) const { return simd ? sumSimd(v, padded) : sumPortable(v, padded); }
};

}  // namespace

bool makeAlignmentTemplate(const ImageView& ref, const Vec2& ref_uv, double spacing,
                           const EpipolarAlignmentOptions& options, AlignmentTemplate& t) {
  t.ok = false;
  const int h = std::clamp(options.half_size, 1, kMaxHalf);
  t.half = h;
  t.samples = (2 * h + 1) * (2 * h + 1);
  t.padded = (t.samples + 3) / 4 * 4;
  t.spacing = spacing;
  t.uv = ref_uv;
  if (ref.empty() || !inside(ref, ref_uv.x(), ref_uv.y(), spacing * (h + 1), spacing * (h + 1))) return false;
  // The reference patch on its grid, one ring more for the central differences.
  const int side = 2 * h + 3, grid = side * side, grid_padded = (grid + 3) / 4 * 4;
  alignas(16) float gx[kMaxGridPadded], gy[kMaxGridPadded], g[kMaxGridPadded];
  for (int j = 0, k = 0; j < side; ++j) {
    const float y = static_cast<float>(ref_uv.y() + spacing * (j - h - 1));
    for (int i = 0; i < side; ++i, ++k) {
      gx[k] = static_cast<float>(ref_uv.x() + spacing * (i - h - 1));
      gy[k] = y;
    }
  }
  for (int k = grid; k < grid_padded; ++k) {  // padding: the centre
    gx[k] = static_cast<float>(ref_uv.x());
    gy[k] = static_cast<float>(ref_uv.y());
  }
  const Kernels kernels(options);
  kernels.sampleBilinear(ref, gx, gy, grid_padded, g);
  const float inv_2s = static_cast<float>(1.0 / (2 * spacing));
  int k = 0;
  for (int j = 1; j < side - 1; ++j) {
    for (int i = 1; i < side - 1; ++i, ++k) {
      const float* c = g + j * side + i;
      t.value[k] = c[0];
      t.dx[k] = (c[1] - c[-1]) * inv_2s;
      t.dy[k] = (c[side] - c[-side]) * inv_2s;
    }
  }
  for (; k < t.padded; ++k) t.value[k] = t.dx[k] = t.dy[k] = 0;
  const double n = t.samples;
  const float mean_v = static_cast<float>(kernels.sum(t.value, t.padded) / n);
  const float mean_x = static_cast<float>(kernels.sum(t.dx, t.padded) / n),
              mean_y = static_cast<float>(kernels.sum(t.dy, t.padded) / n);
  for (k = 0; k < t.samples; ++k) {
    t.value[k] -= mean_v;
    t.dx[k] -= mean_x;
    t.dy[k] -= mean_y;
  }
  // Zero mean, unit norm; the derivatives' means are removed with the template's own (the residual is blind to a
  // constant).
  const double var = kernels.dot3(t.value, t.value, t.value, t.padded).s[0];
  if (!(var > 1e-6)) return false;
  const float inv_norm = static_cast<float>(1.0 / std::sqrt(var));
  for (k = 0; k < t.samples; ++k) {
    t.value[k] *= inv_norm;
    t.dx[k] *= inv_norm;
    t.dy[k] *= inv_norm;
  }
  // The dominant gradient's direction: the main axis of the structure tensor.
  double sxx = 0, sxy = 0, syy = 0;
  for (k = 0; k < t.samples; ++k) {
    sxx += static_cast<double>(t.dx[k]) * t.dx[k];
    sxy += static_cast<double>(t.dx[k]) * t.dy[k];
    syy += static_cast<double>(t.dy[k]) * t.dy[k];
  }
  const double axis = 0.5 * std::atan2(2 * sxy, sxx - syy);
  const double ax = std::cos(axis), ay = std::sin(axis);
  t.axis = Vec2(ax, ay);
  t.ok = true;
  return true;
}

Vec2 informationCentroid(const AlignmentTemplate& t) {
  if (!t.ok) return Vec2::Zero();
  double weight = 0, along = 0;
  int k = 0;
  for (int j = -t.half; j <= t.half; ++j) {
    for (int i = -t.half; i <= t.half; ++i, ++k) {
      const double g = t.dx[k] * t.axis.x() + t.dy[k] * t.axis.y();
      weight += g * g;
      along += g * g * (t.axis.x() * i + t.axis.y() * j);
    }
  }
  if (!(weight > 0)) return Vec2::Zero();
  return t.axis * (t.spacing * along / weight);
}

namespace {

// The template as the partner sees it: its derivative along the shift and its samples' offsets in the partner
// image, with the Gauss-Newton information along the shift.
struct PartnerWarp {
  alignas(16) float grad[kMaxPadded];
  alignas(16) float off_x[kMaxPadded];
  alignas(16) float off_y[kMaxPadded];
  double hessian = 0, grad_dot_tmpl = 0;
};

void warpTemplate(const AlignmentTemplate& t, const Vec2& direction, const Mat2& A, const Kernels& kernels,
                  PartnerWarp& pw) {
  const int h = t.half, padded = t.padded;
  const double spacing = t.spacing;
  // A shift s along the direction in the partner moves the reference grid by s * w: the template's derivative
  // along the shift is its gradient along w (zero mean, as the gradients are).
  const Vec2 w = A.inverse() * direction;
  const float wx = static_cast<float>(w.x()), wy = static_cast<float>(w.y());
  for (int k = 0; k < padded; ++k) pw.grad[k] = t.dx[k] * wx + t.dy[k] * wy;  // padding: zero
  const Vec2 step_i = A.col(0) * spacing, step_j = A.col(1) * spacing;
  int k = 0;
  for (int j = -h; j <= h; ++j) {
    for (int i = -h; i <= h; ++i, ++k) {
      pw.off_x[k] = static_cast<float>(step_i.x() * i + step_j.x() * j);
      pw.off_y[k] = static_cast<float>(step_i.y() * i + step_j.y() * j);
    }
  }
  for (; k < padded; ++k) pw.off_x[k] = pw.off_y[k] = 0;  // padding: the centre
  const Sums gs = kernels.dot3(pw.grad, t.value, t.value, padded);
  pw.hessian = gs.s[0];
  pw.grad_dot_tmpl = gs.s[1];
}

enum class ShiftOutcome { Converged, NotConverged, NoTexture, TooFar };

// The shift along the direction that aligns the partner's patch to the template (ZNCC residual), from 0.
ShiftOutcome iterateShift(const AlignmentTemplate& t, const PartnerWarp& pw, const ImageView& image, const Vec2& uv0,
                          const Vec2& direction, double max_shift, const EpipolarAlignmentOptions& options, double& s,
                          double& zncc, double& residual2) {
  const int n = t.samples, padded = t.padded;
  const Kernels kernels(options);
  alignas(16) float xs[kMaxPadded], ys[kMaxPadded], values[kMaxPadded];
  double previous_s = 0, previous_b = 0;
  for (int it = 0; it < options.max_iterations; ++it) {
    const float cx = static_cast<float>(uv0.x() + s * direction.x()),
                cy = static_cast<float>(uv0.y() + s * direction.y());
    for (int k = 0; k < padded; ++k) {
      xs[k] = cx + pw.off_x[k];
      ys[k] = cy + pw.off_y[k];
    }
    kernels.sampleBilinear(image, xs, ys, padded, values);
    for (int k = n; k < padded; ++k) values[k] = 0;
    const float mean = static_cast<float>(kernels.sum(values, padded) / n);
    for (int k = 0; k < n; ++k) values[k] -= mean;
    // With both patches zero mean, and the template and its derivative too: the correlation and the residual's
    // derivative need only the partner's norm and two dot products.
    const Sums vs = kernels.dot3(values, t.value, pw.grad, padded);
    const double var = vs.s[0];
    if (!(var > 1e-6)) return ShiftOutcome::NoTexture;
    const double inv_norm = 1.0 / std::sqrt(var);
    const double cross = vs.s[1] * inv_norm;
    const double b = vs.s[2] * inv_norm - pw.grad_dot_tmpl;
    zncc = cross;
    residual2 = std::max(0.0, 2.0 - 2.0 * cross);  // both unit norm
    // Gauss-Newton's step uses the template's derivative, which the partner's image (other sampling, other
    // blur) only approximates: convergence is linear. From the second step on, the secant of the observed
    // gradient replaces it where it is plausible (superlinear, same fixed point).
    double step = b / pw.hessian;
    if (it > 0 && s != previous_s) {
      const double slope = (b - previous_b) / (s - previous_s);
      if (slope > 0.2 * pw.hessian && slope < 5 * pw.hessian) step = b / slope;
    }
    previous_s = s;
    previous_b = b;
    s -= step;
    if (!(std::abs(s) <= max_shift)) return ShiftOutcome::TooFar;
    if (std::abs(step) < options.converged_px) return ShiftOutcome::Converged;
  }
  return ShiftOutcome::NotConverged;
}

}  // namespace

EpipolarAlignment alignAlongEpipolar(const AlignmentTemplate& t, const ImageView& image, const Vec2& uv0,
                                     const Vec2& direction, const Mat2& A, double partner_spacing,
                                     const EpipolarAlignmentOptions& options) {
  EpipolarAlignment out;
  out.uv = uv0;
  const double det = A.determinant();
  if (!t.ok || image.empty() || !(std::abs(det) > 1e-6) || !A.allFinite()) return out;
  const int h = t.half, n = t.samples;
  const double spacing = t.spacing;
  const double max_shift = options.max_shift_spacings * (spacing + partner_spacing);
  const double ex = spacing * h * (std::abs(A(0, 0)) + std::abs(A(0, 1))) + max_shift + 1;
  const double ey = spacing * h * (std::abs(A(1, 0)) + std::abs(A(1, 1))) + max_shift + 1;
  if (!inside(image, uv0.x(), uv0.y(), ex, ey)) return out;

  PartnerWarp pw;
  warpTemplate(t, direction, A, Kernels(options), pw);
  if (!(pw.hessian > 1e-12)) return out;
  double s = 0, zncc = 0, residual2 = 0;
  const ShiftOutcome outcome = iterateShift(t, pw, image, uv0, direction, max_shift, options, s, zncc, residual2);
  if (outcome == ShiftOutcome::NoTexture) return out;
  if (outcome == ShiftOutcome::TooFar) {
    out.status = AlignmentStatus::Disagrees;
    return out;
  }
  out.uv = uv0 + s * direction;
  out.shift = s;
  out.zncc = zncc;
  if (outcome != ShiftOutcome::Converged || zncc < options.min_zncc) {
    out.status = AlignmentStatus::Disagrees;
    return out;
  }
  // Residual variance per sample (three parameters: shift, gain, bias) over the information along the direction.
  const double sigma2 = residual2 / std::max(1, n - 3) / pw.hessian;
  const double floor = options.sigma_floor_spacings * spacing;
  out.sigma_px = std::sqrt(sigma2 + floor * floor);
  out.status = AlignmentStatus::Ok;
  return out;
}

EpipolarAlignment alignAlongEpipolar(const ImageView& ref, const Vec2& ref_uv, const ImageView& image, const Vec2& uv0,
                                     const Vec2& direction, const Mat2& A, double spacing, double partner_spacing,
                                     const EpipolarAlignmentOptions& options) {
  AlignmentTemplate t;
  if (!makeAlignmentTemplate(ref, ref_uv, spacing, options, t)) {
    EpipolarAlignment out;
    out.uv = uv0;
    return out;
  }
  return alignAlongEpipolar(t, image, uv0, direction, A, partner_spacing, options);
}

}  // namespace mcslam
