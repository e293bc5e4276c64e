#pragma once
// What mcslam-eval prints and draws for a result: aligned text, JSON, and the top-view plot.
#include <string>

#include "mcslam/eval/trajectory_metrics.hpp"

namespace mcslam::eval_tool {

struct Inputs {
  std::string reference_path, estimate_path;
  std::size_t reference_poses = 0, estimate_poses = 0;
};

void printApeText(const ApeResult& r, const EvalOptions& o, const Inputs& in);
void printApeJson(const ApeResult& r, const EvalOptions& o, const Inputs& in);
void plotApe(const std::string& png, const ApeResult& r, const EvalOptions& o, const Inputs& in);

void printRpeText(const RpeResult& r, const RpeOptions& o, const Inputs& in);
void printRpeJson(const RpeResult& r, const RpeOptions& o, const Inputs& in);
void plotRpe(const std::string& png, const RpeResult& r, const RpeOptions& o, const Inputs& in);

}  // namespace mcslam::eval_tool
