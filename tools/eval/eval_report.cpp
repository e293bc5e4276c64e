#include "eval_report.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>

#include "mcslam/core/json_writer.hpp"
#include "mcslam/eval/trajectory_plot.hpp"

namespace mcslam::eval_tool {

namespace {

const char* alignmentText(AlignMode mode) {
  switch (mode) {
    case AlignMode::SE3: return "SE(3) Umeyama";
    case AlignMode::Sim3: return "Sim(3) Umeyama (with scale)";
    case AlignMode::None: return "none";
  }
  return "?";
}

std::string fileName(const std::string& path) { return std::filesystem::path(path).filename().string(); }

std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

void printHeader(const EvalOptions& o, const Inputs& in, std::size_t pairs) {
  std::printf("  reference    %s (%zu poses)\n", in.reference_path.c_str(), in.reference_poses);
  std::printf("  estimate     %s (%zu poses)\n", in.estimate_path.c_str(), in.estimate_poses);
  std::printf("  association  %zu poses matched, max. time difference %g s", pairs, o.max_diff_s);
  if (o.t_offset_s != 0) std::printf(", estimate time offset %g s", o.t_offset_s);
  std::printf("\n  alignment    %s\n", alignmentText(o.align));
}

void printFooter(const AlignedTrajectories& d, double rmse_percent, const EvalOptions& o) {
  std::printf("  path length  %.6f m (associated reference)\n", d.ref_path_length);
  std::printf("  rmse / path  %.4f %%\n", rmse_percent);
  if (o.align == AlignMode::Sim3) std::printf("  scale        %.6f (applied to the estimate)\n", d.alignment.s);
}

void jsonStats(JsonWriter& j, const ErrorStats& s) {
  j.key("rmse").value(s.rmse);
  j.key("mean").value(s.mean);
  j.key("median").value(s.median);
  j.key("std").value(s.std);
  j.key("min").value(s.min);
  j.key("max").value(s.max);
  j.key("sse").value(s.sse);
}

void jsonCommon(JsonWriter& j, const char* metric, const EvalOptions& o, const Inputs& in) {
  j.key("metric").value(metric);
  j.key("reference").value(in.reference_path);
  j.key("estimate").value(in.estimate_path);
  j.key("reference_poses").value(in.reference_poses);
  j.key("estimate_poses").value(in.estimate_poses);
  j.key("align").value(alignModeName(o.align));
  j.key("max_diff").value(o.max_diff_s);
  j.key("t_offset").value(o.t_offset_s);
}

void jsonFooter(JsonWriter& j, const AlignedTrajectories& d, double rmse_percent, const EvalOptions& o) {
  j.key("path_length").value(d.ref_path_length);
  j.key("rmse_percent").value(rmse_percent);
  if (o.align == AlignMode::Sim3) j.key("scale").value(d.alignment.s);
}

std::string viewTail(const EvalOptions& o, const Inputs& in, std::size_t pairs) {
  return std::string(o.align == AlignMode::None  ? "not aligned"
                     : o.align == AlignMode::SE3 ? "SE(3) aligned"
                                                 : "Sim(3) aligned") +
         ", " + std::to_string(pairs) + " pairs  |  reference: " + fileName(in.reference_path) +
         "  |  estimate: " + fileName(in.estimate_path);
}

std::string estimateLabel(const EvalOptions& o) {
  return o.align == AlignMode::None  ? "estimate"
         : o.align == AlignMode::SE3 ? "estimate (SE(3) aligned)"
                                     : "estimate (Sim(3) aligned)";
}

std::string deltaText(const RpeOptions& o) {
  if (o.unit == DeltaUnit::Frames) {
    const long d = std::lround(o.delta);
    return std::to_string(d) + (d == 1 ? " frame" : " frames");
  }
  return format("%g m", o.delta);
}

}  // namespace

void printApeText(const ApeResult& r, const EvalOptions& o, const Inputs& in) {
  std::printf("APE w.r.t. translation part (m)\n");
  printHeader(o, in, r.stats.count);
  const ErrorStats& s = r.stats;
  std::printf("  pairs        %zu\n", s.count);
  std::printf("  rmse         %.6f m\n", s.rmse);
  std::printf("  mean         %.6f m\n", s.mean);
  std::printf("  median       %.6f m\n", s.median);
  std::printf("  std          %.6f m\n", s.std);
  std::printf("  min          %.6f m\n", s.min);
  std::printf("  max          %.6f m\n", s.max);
  printFooter(r.data, r.rmse_percent, o);
}

void printApeJson(const ApeResult& r, const EvalOptions& o, const Inputs& in) {
  JsonWriter j(std::cout);
  j.beginObject();
  jsonCommon(j, "ape", o, in);
  j.key("unit").value("m");
  j.key("pairs").value(r.stats.count);
  jsonStats(j, r.stats);
  jsonFooter(j, r.data, r.rmse_percent, o);
  j.endObject();
}

void plotApe(const std::string& png, const ApeResult& r, const EvalOptions& o, const Inputs& in) {
  TrajectoryPlot p;
  p.title = "APE (translation): rmse " + format("%.4g m", r.stats.rmse) + " = " + format("%.3g %%", r.rmse_percent) +
            " of " + format("%.3g m", r.data.ref_path_length) + " path";
  p.subtitle = viewTail(o, in, r.stats.count);
  p.reference = positionsOf(r.data.ref);
  p.estimate = positionsOf(r.data.est);
  p.estimate_error = r.errors;
  p.error_label = "APE [m]";
  p.estimate_label = estimateLabel(o);
  writeTrajectoryPlot(png, p);
}

void printRpeText(const RpeResult& r, const RpeOptions& o, const Inputs& in) {
  std::printf("RPE for delta = %s, %s pairs from the %s\n", deltaText(o).c_str(), o.all_pairs ? "all" : "consecutive",
              o.pairs_from_reference ? "reference" : "estimate");
  printHeader(o.eval, in, r.data.ref.size());
  const ErrorStats& t = r.translation;
  const ErrorStats& a = r.rotation_deg;
  std::printf("  pairs        %zu\n", t.count);
  std::printf("               translation (m)  rotation (deg)\n");
  const auto row = [](const char* name, double tv, double av) {
    std::printf("  %-11s  %-15.6f  %.6f\n", name, tv, av);
  };
  row("rmse", t.rmse, a.rmse);
  row("mean", t.mean, a.mean);
  row("median", t.median, a.median);
  row("std", t.std, a.std);
  row("min", t.min, a.min);
  row("max", t.max, a.max);
  printFooter(r.data, r.rmse_percent, o.eval);
}

void printRpeJson(const RpeResult& r, const RpeOptions& o, const Inputs& in) {
  JsonWriter j(std::cout);
  j.beginObject();
  jsonCommon(j, "rpe", o.eval, in);
  j.key("delta").value(o.delta);
  j.key("delta_unit").value(o.unit == DeltaUnit::Frames ? "f" : "m");
  j.key("all_pairs").value(o.all_pairs);
  j.key("pairs_from_reference").value(o.pairs_from_reference);
  j.key("associated_poses").value(r.data.ref.size());
  j.key("unit").value("m");
  j.key("pairs").value(r.translation.count);
  jsonStats(j, r.translation);  // the translation part at the top level, like ape
  jsonFooter(j, r.data, r.rmse_percent, o.eval);
  j.key("rotation_deg").beginObject();
  jsonStats(j, r.rotation_deg);
  j.endObject();
  j.endObject();
}

void plotRpe(const std::string& png, const RpeResult& r, const RpeOptions& o, const Inputs& in) {
  TrajectoryPlot p;
  p.title = "RPE (translation, delta " + deltaText(o) + "): rmse " + format("%.4g m", r.translation.rmse) +
            ", rotation rmse " + format("%.3g deg", r.rotation_deg.rmse);
  p.subtitle = viewTail(o.eval, in, r.translation.count);
  p.reference = positionsOf(r.data.ref);
  p.estimate = positionsOf(r.data.est);
  // Each pair colours the stretch of the estimate it spans.
  p.estimate_error.assign(p.estimate.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t k = 0; k < r.pairs.size(); ++k) {
    for (std::size_t i = r.pairs[k].first; i <= r.pairs[k].second; ++i) p.estimate_error[i] = r.translation_errors[k];
  }
  p.error_label = "RPE [m]";
  p.estimate_label = estimateLabel(o.eval);
  writeTrajectoryPlot(png, p);
}

}  // namespace mcslam::eval_tool
