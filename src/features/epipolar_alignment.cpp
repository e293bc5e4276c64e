#include "mcslam/features/epipolar_alignment.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam {

namespace {

constexpr int kMaxHalf = 6;
constexpr int kMaxSide = 2 * kMaxHalf + 3;  // the template keeps a ring more for its central differences

// Bilinear sample; the caller has checked that (x, y) and (x + 1, y + 1) are inside.
inline float sample(const ImageView& im, float x, float y) {
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float ax = x - static_cast<float>(x0), ay = y - static_cast<float>(y0);
  const uint8_t* p = im.data + static_cast<std::ptrdiff_t>(y0) * im.stride + x0;
  const float top = p[0] + ax * (static_cast<float>(p[1]) - p[0]);
  const float bottom = p[im.stride] + ax * (static_cast<float>(p[im.stride + 1]) - p[im.stride]);
  return top + ay * (bottom - top);
}

bool inside(const ImageView& im, double x, double y, double ex, double ey) {
  return x - ex >= 0 && y - ey >= 0 && x + ex < im.width - 1 && y + ey < im.height - 1;
}

}  // namespace

EpipolarAlignment alignAlongEpipolar(const ImageView& ref, const Vec2& ref_uv, const ImageView& image, const Vec2& uv0,
                                     const Vec2& direction, const Mat2& A, double spacing, double partner_spacing,
                                     const EpipolarAlignmentOptions& options) {
  EpipolarAlignment out;
  out.uv = uv0;
  const int h = std::clamp(options.half_size, 1, kMaxHalf);
  const double det = A.determinant();
  if (ref.empty() || image.empty() || !(std::abs(det) > 1e-6) || !A.allFinite()) return out;
  const double max_shift = options.max_shift_spacings * (spacing + partner_spacing);
  const double ex = spacing * h * (std::abs(A(0, 0)) + std::abs(A(0, 1))) + max_shift + 1;
  const double ey = spacing * h * (std::abs(A(1, 0)) + std::abs(A(1, 1))) + max_shift + 1;
  if (!inside(ref, ref_uv.x(), ref_uv.y(), spacing * (h + 1), spacing * (h + 1)) ||
      !inside(image, uv0.x(), uv0.y(), ex, ey)) {
    return out;
  }

  // Template: the reference patch on its grid, one ring more for the gradient.
  const int side = 2 * h + 3;
  float t_grid[kMaxSide * kMaxSide];
  for (int j = 0; j < side; ++j) {
    const float y = static_cast<float>(ref_uv.y() + spacing * (j - h - 1));
    for (int i = 0; i < side; ++i) t_grid[j * side + i] = sample(ref, static_cast<float>(ref_uv.x() + spacing * (i - h - 1)), y);
  }
  // A shift t along the direction in the partner moves the reference grid by t * w.
  const Vec2 w = A.inverse() * direction;
  const int n = (2 * h + 1) * (2 * h + 1);
  float tmpl[(2 * kMaxHalf + 1) * (2 * kMaxHalf + 1)], grad[(2 * kMaxHalf + 1) * (2 * kMaxHalf + 1)];
  float off_x[(2 * kMaxHalf + 1) * (2 * kMaxHalf + 1)], off_y[(2 * kMaxHalf + 1) * (2 * kMaxHalf + 1)];
  double mean_t = 0;
  int k = 0;
  const float gx_scale = static_cast<float>(w.x() / (2 * spacing)), gy_scale = static_cast<float>(w.y() / (2 * spacing));
  for (int j = 1; j < side - 1; ++j) {
    for (int i = 1; i < side - 1; ++i, ++k) {
      const float* c = t_grid + j * side + i;
      tmpl[k] = c[0];
      grad[k] = (c[1] - c[-1]) * gx_scale + (c[side] - c[-side]) * gy_scale;
      const Vec2 q = A * Vec2(spacing * (i - h - 1), spacing * (j - h - 1));
      off_x[k] = static_cast<float>(q.x());
      off_y[k] = static_cast<float>(q.y());
      mean_t += c[0];
    }
  }
  mean_t /= n;
  double var_t = 0, mean_g = 0;
  for (int m = 0; m < n; ++m) {
    tmpl[m] -= static_cast<float>(mean_t);
    var_t += static_cast<double>(tmpl[m]) * tmpl[m];
    mean_g += grad[m];
  }
  mean_g /= n;
  // Normalised template (zero mean, unit norm) and its derivative; the derivative's mean is removed with the
  // template's own (the residual is blind to a constant).
  if (!(var_t > 1e-6)) return out;
  const double inv_norm_t = 1.0 / std::sqrt(var_t);
  double hessian = 0;
  for (int m = 0; m < n; ++m) {
    tmpl[m] = static_cast<float>(tmpl[m] * inv_norm_t);
    grad[m] = static_cast<float>((grad[m] - mean_g) * inv_norm_t);
    hessian += static_cast<double>(grad[m]) * grad[m];
  }
  if (!(hessian > 1e-12)) return out;

  double t = 0, zncc = 0, residual2 = 0;
  double previous_t = 0, previous_b = 0;
  float values[(2 * kMaxHalf + 1) * (2 * kMaxHalf + 1)];
  bool converged = false;
  for (int it = 0; it < options.max_iterations; ++it) {
    const float cx = static_cast<float>(uv0.x() + t * direction.x()), cy = static_cast<float>(uv0.y() + t * direction.y());
    double sum = 0, sum2 = 0;
    for (int m = 0; m < n; ++m) {
      values[m] = sample(image, cx + off_x[m], cy + off_y[m]);
      sum += values[m];
      sum2 += static_cast<double>(values[m]) * values[m];
    }
    const double mean = sum / n, var = sum2 - sum * mean;
    if (!(var > 1e-6)) return out;
    const double inv_norm = 1.0 / std::sqrt(var);
    double b = 0, cross = 0;
    for (int m = 0; m < n; ++m) {
      const double v = (values[m] - mean) * inv_norm;
      cross += v * tmpl[m];
      b += grad[m] * (v - tmpl[m]);
    }
    zncc = cross;
    residual2 = std::max(0.0, 2.0 - 2.0 * cross);  // both unit norm
    // Gauss-Newton's step uses the template's derivative, which the partner's image (other sampling, other
    // blur) only approximates: convergence is linear. From the second step on, the secant of the measured
    // gradient replaces it where it is plausible (superlinear, same fixed point).
    double step = b / hessian;
    if (it > 0 && t != previous_t) {
      const double slope = (b - previous_b) / (t - previous_t);
      if (slope > 0.2 * hessian && slope < 5 * hessian) step = b / slope;
    }
    previous_t = t;
    previous_b = b;
    t -= step;
    if (!(std::abs(t) <= max_shift)) {
      out.status = AlignmentStatus::Disagrees;
      return out;
    }
    if (std::abs(step) < options.converged_px) {
      converged = true;
      break;
    }
  }
  out.uv = uv0 + t * direction;
  out.shift = t;
  out.zncc = zncc;
  if (!converged || zncc < options.min_zncc) {
    out.status = AlignmentStatus::Disagrees;
    return out;
  }
  // Residual variance per sample (three parameters: shift, gain, bias) over the information along the direction.
  const double sigma2 = residual2 / std::max(1, n - 3) / hessian;
  const double floor = options.sigma_floor_spacings * spacing;
  out.sigma_px = std::sqrt(sigma2 + floor * floor);
  out.status = AlignmentStatus::Ok;
  return out;
}

}  // namespace mcslam
