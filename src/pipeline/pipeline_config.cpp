#include "mcslam/pipeline/pipeline_config.hpp"

#include <cstdio>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "mcslam/core/config_section.hpp"
#include "mcslam/core/error.hpp"

namespace mcslam {

namespace {

constexpr std::pair<const char*, RefineExtrinsics> kRefineExtrinsicsNames[] = {
    {"auto", RefineExtrinsics::Auto}, {"on", RefineExtrinsics::On}, {"off", RefineExtrinsics::Off}};

void readRefineExtrinsics(ConfigSection& s, RefineExtrinsics& value) {
  std::string name = refineExtrinsicsName(value);
  std::vector<std::string> names;
  for (const auto& [n, v] : kRefineExtrinsicsNames) names.push_back(n);
  s.read("refine_extrinsics", name, names);  // throws, listing the names, for any other value
  for (const auto& [n, v] : kRefineExtrinsicsNames)
    if (name == n) value = v;
}

void readCapacity(ConfigSection s, PipelineConfig& c) {
  s.read("max_features_per_camera", c.orb.max_features, 50, 20000);
  s.read("max_keyframes", c.odometry.max_keyframes, 4, 200);
  s.read("window_keyframes", c.odometry.window_keyframes, 2, 100);
  s.read("max_landmarks", c.odometry.max_landmarks, 500, 2000000);
  s.finish();
  if (c.odometry.max_keyframes < c.odometry.window_keyframes + 2) {
    s.fail("max_keyframes", "must exceed window_keyframes by at least 2 (got " +
                                std::to_string(c.odometry.max_keyframes) + " and " +
                                std::to_string(c.odometry.window_keyframes) + ")");
  }
}

void readFeatures(ConfigSection s, PipelineConfig& c) {
  s.read("levels", c.orb.levels, 1, 16);
  s.read("scale_factor", c.orb.scale_factor, 1.05, 2.0);
  s.read("fast_threshold", c.orb.fast_threshold, 1, 255);
  s.read("min_fast_threshold", c.orb.min_fast_threshold, 1, 255);
  s.read("threads", c.feature_threads, 0, 256);
  s.finish();
}

void readMultiView(ConfigSection s, PipelineConfig& c) {
  s.read("cell_size_px", c.overlap.cell_size_px, 8, 512);
  s.read("min_depth", c.overlap.min_depth, 0.01, 1e4);
  s.read("max_depth", c.overlap.max_depth, 0.02, 1e6);
  s.read("max_hamming", c.multiview.max_hamming, 1, 256);
  s.read("ratio", c.multiview.ratio, 0.1, 1.0);
  s.read("epipolar_px", c.multiview.epipolar_px, 0.1, 50.0);
  s.read("metric_depth_sigma", c.multiview.triangulation.max_relative_depth_sigma, 1e-4, 1.0);
  s.read("align_subpixel", c.multiview.align_subpixel);
  s.read("align_recentre", c.multiview.recentre_reference);
  s.read("unique_two_view", c.multiview.unique_two_view);
  s.read("two_view_visibility_check", c.multiview.two_view_visibility_check);
  s.read("landmark_depth_sigma", c.odometry.landmark_max_depth_sigma, 1e-4, 1.0);
  s.finish();
  if (c.overlap.max_depth <= c.overlap.min_depth) s.fail("max_depth", "must be larger than min_depth");
}

void readTracking(ConfigSection s, PipelineConfig& c) {
  OdometryOptions& o = c.odometry;
  s.read("max_hamming", o.max_hamming, 1, 256);
  s.read("ratio", o.ratio, 0.1, 1.0);
  s.read("radius_px", o.track_radius_px, 1.0, 500.0);
  s.read("wide_radius_factor", o.wide_radius_factor, 1.0, 50.0);
  s.read("local_map_radius_px", o.local_map_radius_px, 0.5, 100.0);
  s.read("min_tracked", o.min_tracked, 6, 10000);
  s.finish();
}

void readKeyframes(ConfigSection s, PipelineConfig& c) {
  OdometryOptions& o = c.odometry;
  s.read("tracked_ratio", o.keyframe_tracked_ratio, 0.0, 1.0);
  s.read("max_interval", o.keyframe_max_interval, 1, 10000);
  s.read("still_share", o.keyframe_still_share, 0.0, 1.0);
  s.read("rotation_deg", o.keyframe_rotation_deg, 0.1, 180.0);
  s.read("translation_ratio", o.keyframe_translation_ratio, 0.001, 10.0);
  s.finish();
}

void readInitialization(ConfigSection s, PipelineConfig& c) {
  OdometryOptions& o = c.odometry;
  s.read("min_multiview", o.init_min_multiview, 6, 100000);
  s.read("metric_disparity_px", o.metric_disparity_px, 0.0, 10000.0);
  s.read("min_matches", o.init_min_matches, 20, 100000);
  s.read("max_reference_age", o.init_max_reference_age, 1, 100000);
  s.finish();
}

void readBackend(ConfigSection s, PipelineConfig& c) {
  OdometryOptions& o = c.odometry;
  s.read("enabled", o.backend);
  s.read("iterations", o.backend_iterations, 1, 100);
  s.read("thread", o.backend_thread);
  s.read("apply_after_frames", o.backend_apply_after_frames, 1, 10);
  readRefineExtrinsics(s, c.refine_extrinsics);
  s.read("extrinsic_sigma_translation", o.extrinsic_sigma_translation, 1e-6, 1.0);
  s.read("extrinsic_sigma_rotation_deg", o.extrinsic_sigma_rotation_deg, 1e-4, 45.0);
  s.finish();
}

// The place map and its database are allocated whole at start, max_keyframes times a per-keyframe capacity each:
// each capacity is in range alone, but their product must not ask for more memory than a machine has (the defaults
// ask for 0.9 M point and 3 M word slots).
constexpr int64_t kMaxPlaceSlots = int64_t{1} << 27;

void checkPlaceSlots(const ConfigSection& s, const char* key, int per_keyframe, int keyframes, const char* what) {
  const int64_t slots = int64_t{per_keyframe} * keyframes;
  if (slots > kMaxPlaceSlots)
    s.fail(key, std::to_string(per_keyframe) + " times max_keyframes " + std::to_string(keyframes) + " is " +
                    std::to_string(slots) + " " + what + " slots, more than the " + std::to_string(kMaxPlaceSlots) +
                    " place memory may allocate at start");
}

void readPlaces(ConfigSection s, PipelineConfig& c) {
  PlacesOptions& p = c.places;
  s.read("enabled", p.enabled);
  s.read("vocabulary", p.vocabulary);
  s.read("max_keyframes", p.max_keyframes, 10, 1000000);
  s.read("max_points_per_keyframe", p.max_points_per_keyframe, 50, 100000);
  s.read("max_words_per_keyframe", p.max_words_per_keyframe, 50, 1000000);
  s.read("min_inliers", p.min_inliers, 10, 100000);
  s.read("relocalization_timeout_s", p.relocalization_timeout_s, 0.0, 3600.0);
  s.read("loop_closure", p.loop_closure);
  s.read("monocular_loop_closure", p.monocular_loop_closure);
  s.read("loop_min_keyframes_apart", p.loop_min_keyframes_apart, 1, 1000000);
  s.read("max_loops", p.max_loops, 1, 1000000);
  s.finish();
  checkPlaceSlots(s, "max_points_per_keyframe", p.max_points_per_keyframe, p.max_keyframes, "point");
  checkPlaceSlots(s, "max_words_per_keyframe", p.max_words_per_keyframe, p.max_keyframes, "word");
}

// A YAML double-quoted scalar that reads back as `s`: a path may hold quotes, backslashes or control characters.
std::string yamlQuoted(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20 || c == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
      out += escaped;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

}  // namespace

const char* refineExtrinsicsName(RefineExtrinsics r) {
  for (const auto& [n, v] : kRefineExtrinsicsNames)
    if (v == r) return n;
  return "?";
}

PipelineConfig parsePipelineConfig(const YAML::Node& slam, const std::string& source, const Rig& rig) {
  PipelineConfig c;
  ConfigSection root(slam, "slam", source);
  readCapacity(root.child("capacity"), c);
  readFeatures(root.child("features"), c);
  readMultiView(root.child("multiview"), c);
  readTracking(root.child("tracking"), c);
  readKeyframes(root.child("keyframes"), c);
  readInitialization(root.child("initialization"), c);
  readBackend(root.child("backend"), c);
  readPlaces(root.child("places"), c);
  root.finish();
  // While place memory may find a lost frame, the odometry waits for it before it starts a new map.
  if (c.places.enabled) c.odometry.lost_timeout_s = c.places.relocalization_timeout_s;
  // One pyramid for extraction, multi-view matching and tracking.
  c.multiview.octave_scale = c.orb.scale_factor;
  c.odometry.scale_factor = c.orb.scale_factor;
  c.odometry.levels = c.orb.levels;
  c.odometry.new_points.min_depth = c.overlap.min_depth;
  c.multiview.triangulation.min_depth = c.overlap.min_depth;
  if (rig.size() < 1) throw InputError(source + ": the rig has no cameras");
  if (rig.size() > 64)
    throw InputError(source + ": at most 64 cameras per rig (got " + std::to_string(rig.size()) + ")");
  return c;
}

std::string formatPipelineConfig(const PipelineConfig& c) {
  const OdometryOptions& o = c.odometry;
  std::ostringstream os;
  os << "slam:\n"
     << "  capacity:\n"
     << "    max_features_per_camera: " << c.orb.max_features << "\n"
     << "    max_keyframes: " << o.max_keyframes << "\n"
     << "    window_keyframes: " << o.window_keyframes << "\n"
     << "    max_landmarks: " << o.max_landmarks << "\n"
     << "  features:\n"
     << "    levels: " << c.orb.levels << "\n"
     << "    scale_factor: " << c.orb.scale_factor << "\n"
     << "    fast_threshold: " << c.orb.fast_threshold << "\n"
     << "    min_fast_threshold: " << c.orb.min_fast_threshold << "\n"
     << "    threads: " << c.feature_threads << "\n"
     << "  multiview:\n"
     << "    cell_size_px: " << c.overlap.cell_size_px << "\n"
     << "    min_depth: " << c.overlap.min_depth << "\n"
     << "    max_depth: " << c.overlap.max_depth << "\n"
     << "    max_hamming: " << c.multiview.max_hamming << "\n"
     << "    ratio: " << c.multiview.ratio << "\n"
     << "    epipolar_px: " << c.multiview.epipolar_px << "\n"
     << "    metric_depth_sigma: " << c.multiview.triangulation.max_relative_depth_sigma << "\n"
     << "    align_subpixel: " << (c.multiview.align_subpixel ? "true" : "false") << "\n"
     << "    align_recentre: " << (c.multiview.recentre_reference ? "true" : "false") << "\n"
     << "    unique_two_view: " << (c.multiview.unique_two_view ? "true" : "false") << "\n"
     << "    two_view_visibility_check: " << (c.multiview.two_view_visibility_check ? "true" : "false") << "\n"
     << "    landmark_depth_sigma: " << o.landmark_max_depth_sigma << "\n"
     << "  tracking:\n"
     << "    max_hamming: " << o.max_hamming << "\n"
     << "    ratio: " << o.ratio << "\n"
     << "    radius_px: " << o.track_radius_px << "\n"
     << "    wide_radius_factor: " << o.wide_radius_factor << "\n"
     << "    local_map_radius_px: " << o.local_map_radius_px << "\n"
     << "    min_tracked: " << o.min_tracked << "\n"
     << "  keyframes:\n"
     << "    tracked_ratio: " << o.keyframe_tracked_ratio << "\n"
     << "    max_interval: " << o.keyframe_max_interval << "\n"
     << "    still_share: " << o.keyframe_still_share << "\n"
     << "    rotation_deg: " << o.keyframe_rotation_deg << "\n"
     << "    translation_ratio: " << o.keyframe_translation_ratio << "\n"
     << "  initialization:\n"
     << "    min_multiview: " << o.init_min_multiview << "\n"
     << "    metric_disparity_px: " << o.metric_disparity_px << "\n"
     << "    min_matches: " << o.init_min_matches << "\n"
     << "    max_reference_age: " << o.init_max_reference_age << "\n"
     << "  backend:\n"
     << "    enabled: " << (o.backend ? "true" : "false") << "\n"
     << "    iterations: " << o.backend_iterations << "\n"
     << "    thread: " << (o.backend_thread ? "true" : "false") << "\n"
     << "    apply_after_frames: " << o.backend_apply_after_frames << "\n"
     << "    refine_extrinsics: " << refineExtrinsicsName(c.refine_extrinsics) << "\n"
     << "    extrinsic_sigma_translation: " << o.extrinsic_sigma_translation << "\n"
     << "    extrinsic_sigma_rotation_deg: " << o.extrinsic_sigma_rotation_deg << "\n"
     << "  places:\n"
     << "    enabled: " << (c.places.enabled ? "true" : "false") << "\n"
     << "    vocabulary: " << yamlQuoted(c.places.vocabulary) << "\n"
     << "    max_keyframes: " << c.places.max_keyframes << "\n"
     << "    max_points_per_keyframe: " << c.places.max_points_per_keyframe << "\n"
     << "    max_words_per_keyframe: " << c.places.max_words_per_keyframe << "\n"
     << "    min_inliers: " << c.places.min_inliers << "\n"
     << "    relocalization_timeout_s: " << c.places.relocalization_timeout_s << "\n"
     << "    loop_closure: " << (c.places.loop_closure ? "true" : "false") << "\n"
     << "    monocular_loop_closure: " << (c.places.monocular_loop_closure ? "true" : "false") << "\n"
     << "    loop_min_keyframes_apart: " << c.places.loop_min_keyframes_apart << "\n"
     << "    max_loops: " << c.places.max_loops << "\n";
  return os.str();
}

}  // namespace mcslam
