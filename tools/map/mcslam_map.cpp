// mcslam-map: what a saved map holds (`info`), and its top view (`info --plot`).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "map_summary.hpp"
#include "map_top_view.hpp"
#include "mcslam/core/binary_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/places/map_contents.hpp"

using namespace mcslam;
using namespace mcslam::map_tool;

int main(int argc, char** argv) {
  CLI::App app{"mcslam-map: describe a map file written by mcslam-run --map-out or mcslamd. Exit code 2 on bad input."};
  app.require_subcommand(1);
  std::string path, png;
  bool json = false;
  auto* info = app.add_subcommand("info", "Summarize a map: rig, keyframes, landmarks, segments, extent, memory");
  info->add_option("MAP", path, "Map file")->required();
  info->add_option("--plot", png, "Draw the map from above into this PNG");
  info->add_flag("--json", json, "Print the summary as JSON");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& err) {
    return app.exit(err);
  } catch (const CLI::ParseError& err) {
    std::fprintf(stderr, "mcslam-map: %s\nRun 'mcslam-map --help' or 'mcslam-map info --help'.\n", err.what());
    return 2;
  }
  try {
    const std::string bytes = readFileBounded(path, kMaxMapFileBytes, "map file");
    const MapContents contents = readMapContents(bytes, path);
    const MapSummary summary = summarize(contents, path);
    if (json) {
      printSummaryJson(summary);
    } else {
      printSummary(summary);
    }
    if (!png.empty()) {
      plotMap(contents, path, png);
      if (!json) std::printf("wrote %s\n", png.c_str());
    }
  } catch (const InputError& err) {
    std::fprintf(stderr, "mcslam-map: %s\n", err.what());
    return 2;
  } catch (const std::exception& err) {  // e.g. a map too large for this computer's memory
    std::fprintf(stderr, "mcslam-map: %s: %s\n", path.c_str(), err.what());
    return 2;
  }
  return 0;
}
