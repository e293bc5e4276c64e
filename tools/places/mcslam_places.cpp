// mcslam-places: place recognition offline. Trains the vocabulary (train-vocabulary), measures precision and
// recall of recognition on a dataset with ground truth (evaluate) and describes a vocabulary file (info).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>

#include "mcslam/calib/rig.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/recognition/vocabulary.hpp"
#include "mcslam/recognition/vocabulary_trainer.hpp"
#include "revisit_evaluation.hpp"
#include "training_set.hpp"

using namespace mcslam;
using namespace mcslam::places_tool;

namespace {

struct TrainArgs {
  std::vector<std::string> datasets, image_folders;
  int every = 5;
  VocabularyTrainingOptions training;
  std::string out;
};

struct EvaluateArgs {
  std::string dataset, vocabulary, csv, cameras;
  RevisitOptions revisit;
  bool json = false;
};

void train(const TrainArgs& a) {
  TrainingSetBuilder builder(OrbOptions{});
  for (const std::string& d : a.datasets) builder.addDataset(d, a.every);
  for (const std::string& d : a.image_folders) builder.addImageFolder(d, a.every);
  const TrainingSet set = builder.take();
  for (const std::string& s : set.sources) std::printf("  %s\n", s.c_str());
  std::printf("training on %zu descriptors of %zu images\n", set.descriptors.size(), set.image_offsets.size() - 1);
  const Vocabulary v = trainVocabulary(set.descriptors, set.image_offsets, a.training);
  writeVocabularyFile(v, a.out);
  std::printf("wrote %s: %d words\n", a.out.c_str(), v.wordCount());
}

void info(const std::string& path) {
  const Vocabulary v = readVocabularyFile(path);
  int present = 0;
  for (WordId w = 0; w < v.wordCount(); ++w) present += v.present(v.firstNodeOfLevel(v.depth()) + w) ? 1 : 0;
  std::printf("%s: branching %d, depth %d, %d words (%d present), trained on %llu descriptors of %llu images\n",
              path.c_str(), v.branching(), v.depth(), v.wordCount(), present,
              static_cast<unsigned long long>(v.training_descriptors),
              static_cast<unsigned long long>(v.training_images));
}

void evaluate(const EvaluateArgs& a) {
  const Vocabulary v = readVocabularyFile(a.vocabulary);
  RevisitOptions options = a.revisit;
  if (!a.cameras.empty()) options.cameras = parseCameraList(a.cameras);
  const RevisitResult r = evaluateRevisits(a.dataset, v, OrbOptions{}, options);
  int revisits = 0;
  for (const RevisitQuery& q : r.queries) revisits += q.has_revisit ? 1 : 0;
  const PrPoint raw = bestAtFullPrecision(precisionRecall(r, false));
  const PrPoint normalized = bestAtFullPrecision(precisionRecall(r, true));
  if (a.json) {
    std::printf(
        "{\"dataset\": \"%s\", \"keyframes\": %d, \"revisits\": %d, \"recall_at_full_precision\": %.4f, "
        "\"threshold\": %.4f, \"recall_at_full_precision_normalized\": %.4f, \"threshold_normalized\": %.4f, "
        "\"mean_query_ms\": %.3f, \"max_query_ms\": %.3f, \"mean_features\": %.0f}\n",
        a.dataset.c_str(), r.keyframes, revisits, raw.recall, raw.threshold, normalized.recall, normalized.threshold,
        r.mean_query_ms, r.max_query_ms, r.mean_features);
  } else {
    std::printf("%s: %d keyframes, %d with a revisit (%.1f m, %.0f deg), %.0f features each\n", a.dataset.c_str(),
                r.keyframes, revisits, a.revisit.revisit_distance_m, a.revisit.revisit_angle_deg, r.mean_features);
    std::printf("  raw score:        recall %.3f at 100%% precision (threshold %.4f, %d accepted)\n", raw.recall,
                raw.threshold, raw.accepted);
    std::printf("  normalized score: recall %.3f at 100%% precision (threshold %.4f, %d accepted)\n", normalized.recall,
                normalized.threshold, normalized.accepted);
    std::printf("  words + query: %.2f ms mean, %.2f ms max per keyframe\n", r.mean_query_ms, r.max_query_ms);
  }
  if (!a.csv.empty()) {
    std::ofstream out(a.csv);
    if (!out) throw InputError(a.csv + ": cannot write the curve");
    out << "score,threshold,precision,recall,accepted,correct\n";
    for (bool norm : {false, true})
      for (const PrPoint& p : precisionRecall(r, norm))
        out << (norm ? "normalized," : "raw,") << p.threshold << ',' << p.precision << ',' << p.recall << ','
            << p.accepted << ',' << p.correct << '\n';
    out.flush();
    if (!out) throw InputError(a.csv + ": cannot write the curve");
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "mcslam-places: place recognition offline (vocabulary training, precision-recall, file info). Exit "
      "code 2 on bad input."};
  app.require_subcommand(1);

  TrainArgs t;
  auto* train_cmd = app.add_subcommand("train-vocabulary", "Train the vocabulary on ORB features of images");
  train_cmd->add_option("--dataset", t.datasets, "Dataset folder (ASL, EuRoC, KITTI); repeatable");
  train_cmd->add_option("--images", t.image_folders, "Folder of image files (PNG, JPEG, PGM); repeatable");
  train_cmd->add_option("--every", t.every, "Use every n-th rig frame or image")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  train_cmd->add_option("--branching", t.training.branching, "Children per node")
      ->check(CLI::Range(2, 64))
      ->capture_default_str();
  train_cmd->add_option("--depth", t.training.depth, "Levels below the root")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  train_cmd->add_option("--iterations", t.training.iterations, "k-majority iterations per node")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  train_cmd->add_option("--seed", t.training.seed, "Seed of the clustering")->capture_default_str();
  train_cmd->add_option("--threads", t.training.threads, "0: all cores")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  train_cmd->add_option("--out", t.out, "Vocabulary file to write")->required();

  EvaluateArgs e;
  auto* eval_cmd = app.add_subcommand("evaluate", "Precision-recall of recognition on a dataset's revisits");
  eval_cmd->add_option("--dataset", e.dataset, "Dataset folder with ground truth")->required();
  eval_cmd->add_option("--vocabulary", e.vocabulary, "Vocabulary file")->required();
  eval_cmd->add_option("--keyframe-distance", e.revisit.keyframe_distance_m, "Metres between keyframes")
      ->capture_default_str();
  eval_cmd->add_option("--keyframe-angle", e.revisit.keyframe_angle_deg, "Degrees between keyframes")
      ->capture_default_str();
  eval_cmd->add_option("--exclude-recent", e.revisit.exclude_recent_s, "Seconds of recent keyframes not queried")
      ->capture_default_str();
  eval_cmd->add_option("--revisit-distance", e.revisit.revisit_distance_m, "A revisit: within this many metres")
      ->capture_default_str();
  eval_cmd->add_option("--revisit-angle", e.revisit.revisit_angle_deg, "... and this many degrees")
      ->capture_default_str();
  eval_cmd->add_option("--cameras", e.cameras, "Cameras of the rig to use, by calibration index (default: all)");
  eval_cmd->add_option("--csv", e.csv, "Write the precision-recall curves");
  eval_cmd->add_flag("--json", e.json, "Print the summary as JSON");

  std::string info_path;
  auto* info_cmd = app.add_subcommand("info", "Describe a vocabulary file");
  info_cmd->add_option("FILE", info_path, "Vocabulary file")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& err) {
    return app.exit(err);
  } catch (const CLI::ParseError& err) {
    std::fprintf(stderr, "mcslam-places: %s\nRun 'mcslam-places --help' or 'mcslam-places <command> --help'.\n",
                 err.what());
    return 2;
  }
  try {
    if (train_cmd->parsed()) {
      if (t.datasets.empty() && t.image_folders.empty()) throw InputError("train-vocabulary: no --dataset or --images");
      train(t);
    } else if (eval_cmd->parsed()) {
      evaluate(e);
    } else {
      info(info_path);
    }
  } catch (const InputError& err) {
    std::fprintf(stderr, "mcslam-places: %s\n", err.what());
    return 2;
  }
  return 0;
}
