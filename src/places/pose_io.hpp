#pragma once
// Poses in the map file: rotation (row-major) and translation, 12 doubles; a pose read back must be finite and a
// rotation.
#include "mcslam/core/binary_io.hpp"
#include "mcslam/core/se3.hpp"

namespace mcslam {

inline void putPose(ByteWriter& out, const SE3& T) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.put<double>(T.R(r, c));
  for (int r = 0; r < 3; ++r) out.put<double>(T.t[r]);
}

inline SE3 takePose(ByteReader& in, const char* field) {
  SE3 T;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) T.R(r, c) = in.take<double>(field);
  for (int r = 0; r < 3; ++r) T.t[r] = in.take<double>(field);
  if (!T.R.allFinite() || !T.t.allFinite() || (T.R.transpose() * T.R - Mat3::Identity()).norm() > 1e-6)
    in.fail(std::string("not a pose in ") + field + " (byte " + std::to_string(in.offset()) + ")");
  return T;
}

}  // namespace mcslam
