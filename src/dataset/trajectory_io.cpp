#include <cctype>
#include <climits>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/trajectory.hpp"

namespace mcslam {

namespace {

std::string lineRef(const std::string& source, int line) { return source + ": line " + std::to_string(line); }

// Whole seconds whose nanoseconds (plus up to a second of fraction) fit an int64: about 292 years.
constexpr int64_t kMaxWholeSeconds = INT64_MAX / 1000000000 - 1;

// Parses "1311868164.363181" (or "1e9", "-3.5") as nanoseconds without going through a double when it
// is a plain decimal, so that stamps with 16 significant digits keep every digit. False for anything else,
// and for times beyond kMaxWholeSeconds.
bool parseSecondsToNs(const std::string& s, Timestamp& out) {
  std::size_t i = 0;
  bool neg = false;
  if (i < s.size() && (s[i] == '-' || s[i] == '+')) neg = s[i++] == '-';
  int64_t whole = 0;
  int64_t frac = 0;
  int frac_digits = 0;
  bool any = false;
  for (; i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])); ++i, any = true) {
    whole = whole * 10 + (s[i] - '0');
    if (whole > kMaxWholeSeconds) return false;
  }
  if (i < s.size() && s[i] == '.') {
    for (++i; i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])); ++i, any = true) {
      if (frac_digits < 9) {
        frac = frac * 10 + (s[i] - '0');
        ++frac_digits;
      } else if (frac_digits == 9 && s[i] >= '5') {  // round the tenth digit
        ++frac;
        ++frac_digits;
      }
    }
  }
  if (!any) return false;
  if (i != s.size()) {  // exponent or junk: fall back to a double
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size() || !(std::abs(v) <= static_cast<double>(kMaxWholeSeconds))) return false;
    out = fromSeconds(v);
    return true;
  }
  for (int d = std::min(frac_digits, 9); d < 9; ++d) frac *= 10;
  out = whole * 1000000000 + frac;
  if (neg) out = -out;
  return true;
}

std::size_t countWords(const std::string& line) {
  std::istringstream in(line);
  std::string w;
  std::size_t n = 0;
  while (in >> w) ++n;
  return n;
}

double parseNumber(const std::string& tok, const std::string& where, const char* what) {
  char* end = nullptr;
  const double v = std::strtod(tok.c_str(), &end);
  if (tok.empty() || end != tok.c_str() + tok.size() || !std::isfinite(v)) {
    throw InputError(where + ": " + what + " is not a number: '" + tok + "'");
  }
  return v;
}

}  // namespace

Trajectory parseTumTrajectory(const std::string& text, const std::string& source) {
  static const char* kNames[8] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  Trajectory traj;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream ls(line);
    std::string tok[8];
    int n = 0;
    std::string extra;
    while (n < 8 && ls >> tok[n]) ++n;
    if (n != 8 || (ls >> extra)) {
      const std::size_t count = countWords(line);
      throw InputError(lineRef(source, line_no) + ": expected 8 values 't tx ty tz qx qy qz qw', got '" + line + "'" +
                       (count == 12 ? " (12 numbers: a KITTI pose line? use the kitti format)" : ""));
    }
    StampedPose p;
    if (!parseSecondsToNs(tok[0], p.t)) {
      throw InputError(lineRef(source, line_no) + ": timestamp is not a number of seconds (at most 9.2e9): '" + tok[0] +
                       "'");
    }
    double v[8];
    for (int k = 1; k < 8; ++k) v[k] = parseNumber(tok[k], lineRef(source, line_no), kNames[k]);
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-2) {
      throw InputError(lineRef(source, line_no) + ": quaternion (qx qy qz qw) is not of unit length (norm " +
                       std::to_string(q.norm()) + ")");
    }
    p.T_w_b = SE3(q, Vec3(v[1], v[2], v[3]));
    traj.push_back(p);
  }
  return traj;
}

Trajectory readTumTrajectory(const std::string& path) { return parseTumTrajectory(readTextFile(path), path); }

std::string formatTumTrajectory(const Trajectory& traj) {
  std::ostringstream os;
  char buf[256];
  for (const StampedPose& p : traj) {
    const Eigen::Quaterniond q = p.T_w_b.quaternion();
    std::snprintf(buf, sizeof(buf), "%s %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n", toSecondsString(p.t).c_str(),
                  p.T_w_b.t.x(), p.T_w_b.t.y(), p.T_w_b.t.z(), q.x(), q.y(), q.z(), q.w());
    os << buf;
  }
  return os.str();
}

void writeTumTrajectory(const std::string& path, const Trajectory& traj) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(path + ": cannot write file");
  out << "# timestamp tx ty tz qx qy qz qw\n" << formatTumTrajectory(traj);
  out.flush();
  if (!out) throw InputError(path + ": write failed");
}

std::vector<Timestamp> readTimesFile(const std::string& path) {
  std::vector<Timestamp> times;
  std::istringstream in(readTextFile(path));
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream ls(line);
    std::string tok, extra;
    if (!(ls >> tok) || tok[0] == '#') continue;
    Timestamp t;
    if (!parseSecondsToNs(tok, t))
      throw InputError(lineRef(path, line_no) + ": time is not a number of seconds (at most 9.2e9): '" + tok + "'");
    if (ls >> extra) throw InputError(lineRef(path, line_no) + ": expected one time in seconds, got '" + line + "'");
    times.push_back(t);
  }
  return times;
}

Trajectory readKittiTrajectory(const std::string& path, const std::string& times_path) {
  const std::vector<Timestamp> times = times_path.empty() ? std::vector<Timestamp>() : readTimesFile(times_path);
  Trajectory traj;
  std::istringstream in(readTextFile(path));
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream ls(line);
    std::string tok;
    double v[12];
    int n = 0;
    while (ls >> tok) {
      if (n == 12) throw InputError(lineRef(path, line_no) + ": more than 12 numbers (KITTI poses are 3x4 row-major)");
      v[n] = parseNumber(tok, lineRef(path, line_no), "matrix entry");
      ++n;
    }
    if (n != 12) {
      throw InputError(lineRef(path, line_no) + ": expected 12 numbers (3x4 row-major), got " + std::to_string(n) +
                       (n == 8 ? " (8 numbers: a TUM line? use the tum format)" : ""));
    }
    Mat4 M = Mat4::Identity();
    for (int k = 0; k < 12; ++k) M(k / 4, k % 4) = v[k];
    const Mat3 R = M.topLeftCorner<3, 3>();
    if ((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-3) {
      throw InputError(lineRef(path, line_no) + ": rotation part is not a rotation matrix");
    }
    StampedPose p;
    const std::size_t index = traj.size();
    if (!times.empty()) {
      if (index >= times.size()) throw InputError(times_path + ": has fewer times than " + path + " has poses");
      p.t = times[index];
    } else {
      p.t = static_cast<Timestamp>(index) * 1000000000;
    }
    p.T_w_b = SE3::fromMatrix(M);
    p.T_w_b.normalize();
    traj.push_back(p);
  }
  return traj;
}

void writeKittiTrajectory(const std::string& path, const Trajectory& traj) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(path + ": cannot write file");
  char buf[512];
  for (const StampedPose& p : traj) {
    const Mat4 M = p.T_w_b.matrix();
    std::snprintf(buf, sizeof(buf), "%.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e\n", M(0, 0), M(0, 1),
                  M(0, 2), M(0, 3), M(1, 0), M(1, 1), M(1, 2), M(1, 3), M(2, 0), M(2, 1), M(2, 2), M(2, 3));
    out << buf;
  }
  out.flush();
  if (!out) throw InputError(path + ": write failed");
}

Trajectory readTrajectory(const std::string& path, const std::string& format) {
  if (format == "tum") return readTumTrajectory(path);
  if (format == "kitti") return readKittiTrajectory(path);
  throw InputError("unknown trajectory format '" + format + "' (expected tum or kitti)");
}

double pathLength(const Trajectory& traj) {
  double len = 0;
  for (std::size_t i = 1; i < traj.size(); ++i) len += (traj[i].T_w_b.t - traj[i - 1].T_w_b.t).norm();
  return len;
}

}  // namespace mcslam
