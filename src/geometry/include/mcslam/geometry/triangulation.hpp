#pragma once
// Triangulation of one point from any number of rays (cameras of one rig frame, or of several frames):
// linear least squares on the rays (midpoint generalised to N lines), then Gauss-Newton on the
// reprojection error in pixels through each camera's full model. The refinement's Hessian gives the
// point's uncertainty, which decides whether the point is metric enough to use (no fixed depth or
// parallax threshold tuned to one rig).
#include <cstdint>

#include "mcslam/calib/camera_model.hpp"

namespace mcslam {

// One observation of the point: the camera model, the camera's pose in the frame the point is solved in
// (T_f_c: camera -> solve frame), the measured pixel and its standard deviation.
struct TriangulationObservation {
  const CameraModel* model = nullptr;
  SE3 T_f_c;
  Vec2 uv;
  Vec3 bearing;  // unit bearing of uv in the camera frame (unproject(uv))
  double sigma_px = 1.0;
};

struct TriangulationOptions {
  int max_iterations = 8;
  double max_reprojection_sigmas = 3.0;    // every observation within this many sigmas after refinement
  double min_parallax_deg = 0.0;           // largest angle between rays must reach this (0 = off)
  double max_relative_depth_sigma = 0.02;  // accept when sigma(depth)/depth below this (per observation camera)
  double min_depth = 0.05;                 // metres in front of every camera
  // > 0: judge the uncertainty against this inverse depth (1/m; the scene's, known without this point) instead
  // of the point's own: accept when sigma(1/depth) <= max_relative_depth_sigma * reference_inverse_depth (and
  // the point's own depth sigma is below its depth). A bound on sigma(depth)/depth accepts a point more readily
  // the nearer its noisy estimate puts it, so the points kept are biased near (1-2% from 5-10 cm baselines at
  // 1 px), and a monocular map built from them shrinks generation after generation. sigma(1/depth) hardly
  // depends on the estimate, so this bound keeps the error of the inverse depth centred.
  double reference_inverse_depth = 0.0;
};

enum class TriangulationStatus : uint8_t {
  Ok = 0,
  TooFewRays,
  Degenerate,         // rays (nearly) parallel: the linear system is singular
  BehindCamera,       // a camera sees the point behind it, or closer than min_depth
  LargeReprojection,  // an observation disagrees
  LowParallax,
  Uncertain,  // the depth is not known well enough
};

const char* triangulationStatusName(TriangulationStatus s);

struct TriangulationResult {
  TriangulationStatus status = TriangulationStatus::TooFewRays;
  Vec3 point = Vec3::Zero();  // in the solve frame
  double max_parallax_deg = 0;
  double relative_depth_sigma = 0;  // worst over the observing cameras
  double inverse_depth_sigma = 0;   // sigma(1/range), 1/m, worst over the observing cameras
  double max_error_sigmas = 0;      // worst reprojection error, in sigmas
  bool ok() const { return status == TriangulationStatus::Ok; }
};

// Solves for the point from obs[0..n). No heap allocation.
TriangulationResult triangulate(const TriangulationObservation* obs, int n, const TriangulationOptions& options);

// Linear step only: the point closest (least squares) to all rays; false when degenerate.
bool triangulateLinear(const TriangulationObservation* obs, int n, Vec3& point);

}  // namespace mcslam
