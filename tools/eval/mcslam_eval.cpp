// mcslam-eval: absolute and relative pose errors of an estimated trajectory against a reference, with evo's
// conventions (association by nearest timestamp, Umeyama alignment, numpy statistics).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <string>

#include "eval_report.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/dataset/trajectory.hpp"

using namespace mcslam;

namespace {

struct CommonArgs {
  std::string reference, estimate;
  std::string align = "se3";
  std::string format = "tum";
  std::string reference_times, estimate_times;
  double max_diff = 0.01;
  double t_offset = 0.0;
  std::string plot;
  bool json = false;
};

void addCommon(CLI::App* cmd, CommonArgs& a) {
  cmd->add_option(
         "GT", a.reference,
         "Reference (ground truth) trajectory, or a dataset folder (ASL, EuRoC, KITTI) to use its ground truth")
      ->required();
  cmd->add_option("EST", a.estimate, "Estimated trajectory")->required();
  cmd->add_option("--align", a.align,
                  "Alignment of the estimate onto the reference before measuring: se3 (rotation and translation, "
                  "Umeyama), sim3 (also scale, for monocular estimates) or none")
      ->check(CLI::IsMember({"se3", "sim3", "none"}))
      ->capture_default_str();
  cmd->add_option("--format", a.format,
                  "Trajectory file format of both files: tum ('t tx ty tz qx qy qz qw', seconds) or kitti (12 numbers "
                  "per line, 3x4 row-major [R|t]; frame i at i seconds unless --gt-times/--est-times)")
      ->check(CLI::IsMember({"tum", "kitti"}))
      ->capture_default_str();
  cmd->add_option("--gt-times", a.reference_times, "kitti: times file of the reference (one time in seconds per line)");
  cmd->add_option("--est-times", a.estimate_times, "kitti: times file of the estimate");
  cmd->add_option("--max-diff", a.max_diff,
                  "Largest time difference (s) of an associated pair: each pose of the trajectory with fewer poses "
                  "takes the nearest stamp of the other one (evo's association)")
      ->capture_default_str();
  cmd->add_option("--t-offset", a.t_offset, "Time offset (s) added to the estimate's stamps before association")
      ->capture_default_str();
  cmd->add_option("--plot", a.plot, "Write a top-view PNG of both trajectories, the estimate coloured by its error");
  cmd->add_flag("--json", a.json, "Print the result as JSON instead of text");
}

Trajectory load(const std::string& path, const std::string& format, const std::string& times) {
  if (std::filesystem::is_directory(path)) {
    const Dataset ds = Dataset::open(path);
    return ds.requireGroundTruth();
  }
  if (format == "kitti") return readKittiTrajectory(path, times);
  if (!times.empty()) throw InputError(times + ": a times file only goes with --format kitti");
  return readTumTrajectory(path);
}

EvalOptions evalOptions(const CommonArgs& a) {
  EvalOptions o;
  o.align = parseAlignMode(a.align);
  o.max_diff_s = a.max_diff;
  o.t_offset_s = a.t_offset;
  o.reference_name = a.reference;
  o.estimate_name = a.estimate;
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "mcslam-eval: trajectory errors like evo_ape / evo_rpe.\n"
      "Both files are read, associated by timestamp, the estimate aligned onto the reference, then measured.\n"
      "Prints rmse, mean, median, std (population), min, max, the number of pairs, the path length of the\n"
      "associated reference and the rmse as % of it (and the scale with --align sim3). Exit code 2 on bad input."};
  app.require_subcommand(1);

  CommonArgs ape_args;
  auto* ape = app.add_subcommand("ape", "Absolute pose error: distance between associated positions after alignment");
  addCommon(ape, ape_args);

  CommonArgs rpe_args;
  double delta = 1;
  std::string delta_unit = "f";
  bool all_pairs = false, pairs_from_reference = false;
  auto* rpe = app.add_subcommand("rpe",
                                 "Relative pose error over index pairs (i, j): translation (m) and rotation (deg) of "
                                 "(Q_i^-1 Q_j)^-1 (P_i^-1 P_j)");
  addCommon(rpe, rpe_args);
  rpe->add_option("--delta", delta, "Distance between the poses of a pair, in --delta-unit")->capture_default_str();
  rpe->add_option("--delta-unit", delta_unit,
                  "f: frames (pairs (0,d), (d,2d), ...); m: metres of travelled path (a new pair each time the "
                  "path since the last pose reaches delta)")
      ->check(CLI::IsMember({"f", "m"}))
      ->capture_default_str();
  rpe->add_flag("--all-pairs", all_pairs, "Start a pair at every pose instead of consecutive, non-overlapping pairs");
  rpe->add_flag("--pairs-from-reference", pairs_from_reference,
                "Choose the pairs on the reference's path (default: the estimate's, as evo)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "mcslam-eval: %s\nRun 'mcslam-eval --help' or 'mcslam-eval <ape|rpe> --help' for usage.\n",
                 e.what());
    return 2;
  }

  try {
    const bool is_ape = ape->parsed();
    const CommonArgs& a = is_ape ? ape_args : rpe_args;
    const Trajectory ref = load(a.reference, a.format, a.reference_times);
    const Trajectory est = load(a.estimate, a.format, a.estimate_times);
    eval_tool::Inputs in{a.reference, a.estimate, ref.size(), est.size()};
    if (is_ape) {
      const EvalOptions o = evalOptions(a);
      const ApeResult r = computeApe(ref, est, o);
      if (!a.plot.empty()) eval_tool::plotApe(a.plot, r, o, in);
      if (a.json)
        eval_tool::printApeJson(r, o, in);
      else
        eval_tool::printApeText(r, o, in);
    } else {
      RpeOptions o;
      o.eval = evalOptions(a);
      o.delta = delta;
      o.unit = delta_unit == "m" ? DeltaUnit::Meters : DeltaUnit::Frames;
      o.all_pairs = all_pairs;
      o.pairs_from_reference = pairs_from_reference;
      const RpeResult r = computeRpe(ref, est, o);
      if (!a.plot.empty()) eval_tool::plotRpe(a.plot, r, o, in);
      if (a.json)
        eval_tool::printRpeJson(r, o, in);
      else
        eval_tool::printRpeText(r, o, in);
    }
  } catch (const InputError& e) {
    std::fprintf(stderr, "mcslam-eval: %s\n", e.what());
    return 2;
  }
  return 0;
}
