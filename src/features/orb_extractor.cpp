#include "mcslam/features/orb_extractor.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "mcslam/core/error.hpp"
#include "orb_descriptor.hpp"
#include "orb_fast.hpp"
#include "orb_grid.hpp"
#include "orb_pyramid.hpp"
#include "orb_spacing.hpp"

namespace mcslam {

using namespace orb_detail;

namespace {

// SIMD loads read up to 16 bytes past a row's last used pixel: every plane ends with this much slack.
constexpr int kPadding = 64;

void checkOptions(const OrbOptions& o, int max_width, int max_height) {
  auto fail = [](const std::string& field, const std::string& value, const std::string& why) {
    throw InputError("ORB option " + field + " = " + value + ": " + why);
  };
  if (o.max_features < 1) fail("max_features", std::to_string(o.max_features), "must be at least 1");
  if (o.levels < 1 || o.levels > 32) fail("levels", std::to_string(o.levels), "must be in [1, 32]");
  if (!(o.scale_factor > 1.0f) || o.scale_factor > 4.0f)
    fail("scale_factor", std::to_string(o.scale_factor), "must be in (1, 4]");
  if (o.fast_threshold < 1 || o.fast_threshold > 254)
    fail("fast_threshold", std::to_string(o.fast_threshold), "must be in [1, 254]");
  if (o.min_fast_threshold < 1 || o.min_fast_threshold > o.fast_threshold)
    fail("min_fast_threshold", std::to_string(o.min_fast_threshold), "must be in [1, fast_threshold]");
  if (o.fallback_cell < 8) fail("fallback_cell", std::to_string(o.fallback_cell), "must be at least 8");
  if (!(o.spacing_ratio >= 0.0f) || o.spacing_ratio > 2.0f)
    fail("spacing_ratio", std::to_string(o.spacing_ratio), "must be in [0, 2]");
  if (o.edge_margin < kPatchRadius)
    fail("edge_margin", std::to_string(o.edge_margin), "must be at least the patch radius 15");
  if (max_width < 0 || max_height < 0)
    fail("max size", std::to_string(max_width) + "x" + std::to_string(max_height), "must not be negative");
}

// Features wanted at each level: a geometric share in 1/scale (ORB's split), the rounding rest to the top.
std::vector<int> levelBudgets(const OrbOptions& o) {
  std::vector<int> budget(static_cast<size_t>(o.levels));
  const double f = 1.0 / o.scale_factor;
  double share = o.max_features * (1.0 - f) / (1.0 - std::pow(f, o.levels));
  int assigned = 0;
  for (int l = 0; l + 1 < o.levels; ++l, share *= f) {
    budget[static_cast<size_t>(l)] = static_cast<int>(std::lround(share));
    assigned += budget[static_cast<size_t>(l)];
  }
  budget.back() = std::max(o.max_features - assigned, 0);
  return budget;
}

int levelSize(int size, float scale) { return static_cast<int>(std::lround(size / static_cast<double>(scale))); }

}  // namespace

OrbLevelScales orbLevelScales(const OrbOptions& options) {
  OrbLevelScales s;
  const int n = std::max(options.levels, 1);
  for (int l = 0; l < n; ++l) {
    const float scale = l == 0 ? 1.0f : s.scale.back() * options.scale_factor;
    s.scale.push_back(scale);
    s.inv_scale.push_back(1.0f / scale);
    s.sigma2.push_back(scale * scale);
    s.inv_sigma2.push_back(1.0f / (scale * scale));
  }
  return s;
}

struct OrbExtractor::Impl {
  OrbOptions options;
  int max_width, max_height;
  OrbLevelScales scales;
  std::vector<int> budgets;
  // Planes as large as level 0, all with the row stride of the largest image (so one table of pattern
  // offsets serves every level): the current and previous pyramid levels (levels are processed one at
  // a time), the smoothed level, the blur's intermediate and the FAST score map.
  std::vector<uint8_t> level_a, level_b, smoothed, blur_tmp, score_map;
  std::vector<int32_t> src_x;
  std::vector<uint32_t> resample_weights;
  std::vector<int16_t> resample_row;
  std::vector<Corner> corners;  // capacity fixed: local maxima of one level
  std::vector<int> per_cell;    // corners per fallback cell
  std::vector<Corner> chosen;
  SpacedSelector selector;
  PatternOffsets pattern;

  Impl(const OrbOptions& o, int w, int h)
      : options(o),
        max_width(w),
        max_height(h),
        scales(orbLevelScales(o)),
        budgets(levelBudgets(o)),
        selector(maxLocalMaxima(w, h), w, h),
        pattern(std::max(w, 1)) {
    const size_t plane = static_cast<size_t>(w) * static_cast<size_t>(h) + kPadding;
    for (auto* buffer : {&level_a, &level_b, &smoothed, &blur_tmp, &score_map}) buffer->assign(plane, 0);
    src_x.resize(static_cast<size_t>(w) + 1);
    resample_weights.resize(static_cast<size_t>(w) + 1);
    resample_row.resize(static_cast<size_t>(w) + 1);
    corners.reserve(static_cast<size_t>(maxLocalMaxima(w, h)));
    per_cell.resize(static_cast<size_t>(Grid::maxCells(w, h, o.fallback_cell)));
    chosen.resize(static_cast<size_t>(o.max_features));
  }

  Plane plane(std::vector<uint8_t>& buffer, int w, int h) const { return {buffer.data(), w, h, pattern.stride()}; }

  void scoreRect(const Plane& image, const Plane& scores, const Rect& r, int threshold) const;
  void detect(const Plane& image, const Rect& region);
  int extractLevel(int level, const Plane& image, int budget, FeatureSet& out);
};

void OrbExtractor::Impl::scoreRect(const Plane& image, const Plane& scores, const Rect& r, int threshold) const {
  const FastBackend backend = options.use_simd ? FastBackend::kWide : FastBackend::kScalar;
  for (int y = r.y0; y < r.y1; ++y)
    fastScoreRow(image.data, image.stride, y, r.x0, r.x1, threshold, scores.row(y) + r.x0, backend);
}

// FAST corners of the region, 3x3 local maxima only, into `corners`.
void OrbExtractor::Impl::detect(const Plane& image, const Rect& region) {
  const Plane scores = plane(score_map, image.width, image.height);
  // The suppression reads one pixel around the region: that frame stays zero.
  const size_t frame_width = static_cast<size_t>(region.x1 - region.x0 + 2);
  std::memset(scores.row(region.y0 - 1) + region.x0 - 1, 0, frame_width);
  std::memset(scores.row(region.y1) + region.x0 - 1, 0, frame_width);
  for (int y = region.y0; y < region.y1; ++y) scores.row(y)[region.x0 - 1] = scores.row(y)[region.x1] = 0;

  corners.clear();
  scoreRect(image, scores, region, options.fast_threshold);
  collectLocalMaxima(scores, region, corners, options.use_simd);
  if (options.min_fast_threshold >= options.fast_threshold) return;

  // Cells where the threshold found nothing try the lower one (ORB-SLAM's fallback), so weakly
  // textured parts of the image still get features.
  const Grid grid(region, options.fallback_cell);
  std::fill(per_cell.begin(), per_cell.begin() + grid.cells(), 0);
  for (const Corner& c : corners) ++per_cell[static_cast<size_t>(grid.cellOf(c.x, c.y))];
  for (int c = 0; c < grid.cells(); ++c) {
    if (per_cell[static_cast<size_t>(c)] != 0) continue;
    const Rect cell = grid.cellRect(c);
    scoreRect(image, scores, cell, options.min_fast_threshold);
    collectLocalMaxima(scores, cell, corners, options.use_simd);
  }
}

int OrbExtractor::Impl::extractLevel(int level, const Plane& image, int budget, FeatureSet& out) {
  const int m = options.edge_margin;
  const Rect region{m, m, image.width - m, image.height - m};
  const int room = std::min(budget, out.capacity() - out.count);
  if (region.empty() || room <= 0) return 0;

  detect(image, region);
  const double area = static_cast<double>(region.x1 - region.x0) * (region.y1 - region.y0);
  const float spacing = static_cast<float>(options.spacing_ratio * std::sqrt(area / budget));
  const int n = selector.select(corners, region, spacing, room, chosen.data());
  if (n == 0) return 0;

  // Orientation on the level itself, the descriptor on its smoothed copy.
  const Plane smooth = plane(smoothed, image.width, image.height);
  gaussianBlur7(image, smooth, plane(blur_tmp, image.width, image.height), options.use_simd);
  const float scale = scales.scale[static_cast<size_t>(level)];
  for (int i = 0; i < n; ++i) {
    const Corner& c = chosen[static_cast<size_t>(i)];
    const long offset = static_cast<long>(c.y) * image.stride + c.x;
    Keypoint& kp = out.keypoints[static_cast<size_t>(out.count)];
    kp.angle = intensityCentroidAngle(image.data + offset, image.stride);
    // Level pixel centres map to level 0 as the pyramid's resampling does.
    kp.x = (static_cast<float>(c.x) + 0.5f) * scale - 0.5f;
    kp.y = (static_cast<float>(c.y) + 0.5f) * scale - 0.5f;
    kp.response = c.score;
    kp.octave = static_cast<int8_t>(level);
    steeredBrief(smooth.data + offset, pattern.forAngle(kp.angle), out.descriptors[static_cast<size_t>(out.count)]);
    ++out.count;
  }
  return n;
}

OrbExtractor::OrbExtractor(const OrbOptions& options, int max_width, int max_height) {
  checkOptions(options, max_width, max_height);
  impl_ = std::make_unique<Impl>(options, max_width, max_height);
}
OrbExtractor::~OrbExtractor() = default;
OrbExtractor::OrbExtractor(OrbExtractor&&) noexcept = default;
OrbExtractor& OrbExtractor::operator=(OrbExtractor&&) noexcept = default;

const OrbOptions& OrbExtractor::options() const { return impl_->options; }
int OrbExtractor::maxWidth() const { return impl_->max_width; }
int OrbExtractor::maxHeight() const { return impl_->max_height; }
const OrbLevelScales& OrbExtractor::levelScales() const { return impl_->scales; }

OrbStatus OrbExtractor::extract(const ImageView& image, FeatureSet& out) {
  Impl& s = *impl_;
  out.count = 0;
  if (out.capacity() < s.options.max_features) return OrbStatus::kOutputTooSmall;
  if (image.width > s.max_width || image.height > s.max_height) return OrbStatus::kImageTooLarge;
  if (image.empty()) return OrbStatus::kOk;

  // Level 0 is copied into our padded plane: the SIMD kernel may read past the caller's last row.
  Plane current = s.plane(s.level_a, image.width, image.height);
  for (int y = 0; y < image.height; ++y) std::memcpy(current.row(y), image.row(y), static_cast<size_t>(image.width));

  int carry = 0;  // budget a level could not use passes to the next one
  for (int level = 0; level < s.options.levels; ++level) {
    if (level > 0) {
      const int w = levelSize(image.width, s.scales.scale[static_cast<size_t>(level)]);
      const int h = levelSize(image.height, s.scales.scale[static_cast<size_t>(level)]);
      if (w <= 2 * s.options.edge_margin || h <= 2 * s.options.edge_margin) break;
      const Plane previous = current;
      current = s.plane(previous.data == s.level_a.data() ? s.level_b : s.level_a, w, h);
      downscale(previous, current, s.options.scale_factor,
                {s.src_x.data(), s.resample_weights.data(), s.resample_row.data()}, s.options.use_simd);
    }
    const int budget = s.budgets[static_cast<size_t>(level)] + carry;
    carry = budget - s.extractLevel(level, current, budget, out);
  }
  return OrbStatus::kOk;
}

}  // namespace mcslam
