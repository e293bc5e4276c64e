// The front-end (ORB on the per-camera workers + multi-view matching) on rendered frames of the isec preset,
// indoor world, ground trajectory: kFrames frames spread over the trajectory, rendered once, cycled through.
//
//   FrontEnd/<n>OV, FrontEnd/3NOV   camera subsets (table of docs/benchmarks/frontend.md); counters per rig frame:
//                                   features per camera, multi-view features, total (mono + multi-view once),
//                                   extraction and multi-view milliseconds (extract_ms: ORB with the pairwise
//                                   matching that runs on the workers as soon as a pair's cameras are done;
//                                   match_ms: the merge into tracks and the triangulation)
//   FrontEnd5Cam/mcslam             the whole front-end of the 5 overlapping cameras on 2 threads, the subpixel
//                                   alignment off (what the anchor's matcher does too)
//   FrontEnd5Cam/cv_orb             anchor: cv::ORB per camera (2 threads), then the same multi-view matcher with
//                                   its cameras and pairs on 2 threads (extract_ms: ORB only)
//   FrontEnd5CamAligned/mcslam      the default front-end: FrontEnd5Cam/mcslam with the subpixel alignment of
//                                   multi-view partners on (multiview: align_subpixel; counters aligned,
//                                   disagreeing: partners per frame)
//   FrontEnd5CamAligned/off         anchor: the same front-end and input with the alignment off
//   FrontEnd5CamUnique/mcslam       the default front-end again (counter ambiguous: two-view tracks dropped per
//                                   frame because the partner's patch recurs along the epipolar curve)
//   FrontEnd5CamUnique/off          anchor: the same with that check off (multiview: unique_two_view)
// Every case also reports process_cpu_ms: the CPU of all threads per rig frame (the CPU column is the main thread's
// alone, and work moved onto the workers leaves it).
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include <chrono>
#include <cstring>
#include <ctime>
#include <memory>
#include <vector>

#include "mcslam/features/multiview_matcher.hpp"
#include "mcslam/pipeline/front_end.hpp"
#include "mcslam/pipeline/pipeline_config.hpp"
#include "mcslam/sim/simulation.hpp"

namespace {

using namespace mcslam;

constexpr int kFrames = 30;
constexpr int kThreads = 2;

struct RenderedSequence {
  std::unique_ptr<sim::Simulation> sim;
  std::vector<std::vector<Image>> images;  // [frame][camera of the preset]
};

const RenderedSequence& sequence() {
  static const RenderedSequence seq = [] {
    RenderedSequence s;
    sim::SimulationConfig cfg;  // isec, indoor, ground, seed 1
    s.sim = std::make_unique<sim::Simulation>(cfg);
    const int n = s.sim->frameCount();
    s.images.resize(kFrames);
    for (int k = 0; k < kFrames; ++k) {
      s.images[k].resize(s.sim->rig().size());
      for (int c = 0; c < s.sim->rig().size(); ++c) s.sim->render(k * n / kFrames, c, s.images[k][c]);
    }
    return s;
  }();
  return seq;
}

struct Subset {
  const char* name;
  std::vector<int> cameras;
};

const std::vector<Subset>& subsets() {
  static const std::vector<Subset> s = {{"1OV", {2}},          {"2OV", {1, 2}},          {"3OV", {1, 2, 3}},
                                        {"4OV", {0, 1, 2, 3}}, {"5OV", {0, 1, 2, 3, 4}}, {"3NOV", {2, 5, 6}}};
  return s;
}

PipelineConfig configFor(const Rig& rig, bool align_subpixel = false, bool unique_two_view = true) {
  PipelineConfig config = parsePipelineConfig(YAML::Node(), "defaults", rig);
  config.feature_threads = kThreads;
  config.multiview.align_subpixel = align_subpixel;
  config.multiview.unique_two_view = unique_two_view;
  return config;
}

double processCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

// Per-frame counters, averaged over the iterations.
struct Totals {
  double keypoints = 0, multiview = 0, mono = 0, extraction_ms = 0, multiview_ms = 0, process_cpu_ms = 0;
  double aligned = 0, disagreeing = 0, ambiguous = 0;
  int frames = 0;
  void add(const FrameFeatures& f, double ext_ms, double mv_ms) {
    keypoints += f.keypointCount();
    multiview += f.mv_count;
    mono += f.monoCount();
    extraction_ms += ext_ms;
    multiview_ms += mv_ms;
    ++frames;
  }
  void report(benchmark::State& state, int cameras) const {
    const double n = std::max(1, frames);
    state.counters["features_per_cam"] = keypoints / n / cameras;
    state.counters["multiview"] = multiview / n;
    state.counters["total"] = (mono + multiview) / n;
    state.counters["extract_ms"] = extraction_ms / n;
    state.counters["match_ms"] = multiview_ms / n;
    state.counters["process_cpu_ms"] = process_cpu_ms / n;
    if (aligned + disagreeing > 0) {
      state.counters["aligned"] = aligned / n;
      state.counters["disagreeing"] = disagreeing / n;
      state.counters["ambiguous"] = ambiguous / n;
    }
  }
};

void runFrontEnd(benchmark::State& state, const std::vector<int>& cameras, bool align_subpixel = false,
                 bool unique_two_view = true) {
  const RenderedSequence& seq = sequence();
  const Rig rig = seq.sim->rig().subset(cameras);
  FrontEnd front_end(rig, configFor(rig, align_subpixel, unique_two_view));
  FrameFeatures f(rig.size(), front_end.capacityPerCamera());
  std::vector<ImageView> views(rig.size());
  std::unique_ptr<bool[]> present(new bool[rig.size()]);
  for (int c = 0; c < rig.size(); ++c) present[c] = true;
  RigFrameView view;
  view.cameras = rig.size();
  view.images = views.data();
  view.present = present.get();
  Totals totals;
  int k = 0;
  for (auto _ : state) {
    for (int c = 0; c < rig.size(); ++c) views[c] = seq.images[k][cameras[c]].view();
    const double cpu0 = processCpuMs();
    front_end.compute(view, f);
    totals.process_cpu_ms += processCpuMs() - cpu0;
    totals.aligned += front_end.multiViewStats().aligned;
    totals.disagreeing += front_end.multiViewStats().disagreeing;
    totals.ambiguous += front_end.multiViewStats().ambiguous;
    totals.add(f, front_end.timing().extraction_ms, front_end.timing().multiview_ms);
    k = (k + 1) % kFrames;
  }
  totals.report(state, rig.size());
}

void FrontEnd5CamMcslam(benchmark::State& state) { runFrontEnd(state, {0, 1, 2, 3, 4}); }
void FrontEnd5CamAlignedMcslam(benchmark::State& state) { runFrontEnd(state, {0, 1, 2, 3, 4}, true); }
void FrontEnd5CamAlignedOff(benchmark::State& state) { runFrontEnd(state, {0, 1, 2, 3, 4}, false); }
void FrontEnd5CamUniqueOff(benchmark::State& state) { runFrontEnd(state, {0, 1, 2, 3, 4}, true, false); }

// cv::ORB with the same feature count and pyramid, one camera per OpenCV task on 2 threads, then our matcher.
void FrontEnd5CamCvOrb(benchmark::State& state) {
  const RenderedSequence& seq = sequence();
  const std::vector<int> cameras = {0, 1, 2, 3, 4};
  const Rig rig = seq.sim->rig().subset(cameras);
  const PipelineConfig config = configFor(rig);
  const OverlapMap overlap(rig, config.overlap);
  MultiViewMatcher matcher(rig, overlap, config.multiview, config.orb.max_features, kThreads);
  FrameFeatures f(rig.size(), config.orb.max_features);
  std::vector<cv::Ptr<cv::ORB>> orbs;
  for (int c = 0; c < rig.size(); ++c) {
    orbs.push_back(
        cv::ORB::create(config.orb.max_features, static_cast<float>(config.orb.scale_factor), config.orb.levels));
  }
  std::vector<std::vector<cv::KeyPoint>> keypoints(rig.size());
  std::vector<cv::Mat> descriptors(rig.size());
  std::vector<ImageView> views(rig.size());  // the matcher aligns partners on the images, as in FrontEnd
  const int previous_threads = cv::getNumThreads();
  cv::setNumThreads(kThreads);
  Totals totals;
  int k = 0;
  using Clock = std::chrono::steady_clock;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    const double cpu0 = processCpuMs();
    cv::parallel_for_(cv::Range(0, rig.size()), [&](const cv::Range& r) {
      for (int c = r.start; c < r.end; ++c) {
        const Image& img = seq.images[k][cameras[c]];
        const cv::Mat mat(img.height(), img.width(), CV_8U, const_cast<uint8_t*>(img.data()));
        orbs[c]->detectAndCompute(mat, cv::noArray(), keypoints[c], descriptors[c]);
        FeatureSet& set = f.sets[c];
        set.count = std::min<int>(static_cast<int>(keypoints[c].size()), set.capacity());
        for (int i = 0; i < set.count; ++i) {
          const cv::KeyPoint& kp = keypoints[c][i];
          set.keypoints[i] = Keypoint{kp.pt.x, kp.pt.y, kp.angle * static_cast<float>(CV_PI / 180.0), kp.response,
                                      static_cast<int8_t>(kp.octave)};
          std::memcpy(set.descriptors[i].data(), descriptors[c].ptr(i), 32);
        }
        f.present[c] = 1;
        views[c] = img.view();
      }
    });
    const auto t1 = Clock::now();
    matcher.beginFrame(f, views.data());
    cv::parallel_for_(cv::Range(0, rig.size()), [&](const cv::Range& r) {
      for (int c = r.start; c < r.end; ++c) matcher.prepareCamera(f, c);
    });
    // One stripe per thread, so the stripe index is a distinct scratch index among concurrent stripes.
    cv::parallel_for_(
        cv::Range(0, kThreads),
        [&](const cv::Range& r) {
          for (int thread = r.start; thread < r.end; ++thread) {
            for (int p = thread; p < matcher.pairCount(); p += kThreads) matcher.matchPair(f, p, thread);
          }
        },
        kThreads);
    matcher.finishFrame(f);
    const auto t2 = Clock::now();
    totals.process_cpu_ms += processCpuMs() - cpu0;
    totals.add(f, std::chrono::duration<double, std::milli>(t1 - t0).count(),
               std::chrono::duration<double, std::milli>(t2 - t1).count());
    k = (k + 1) % kFrames;
  }
  cv::setNumThreads(previous_threads);
  totals.report(state, rig.size());
}

}  // namespace

// Names carry the subset: FrontEnd/1OV ... FrontEnd/3NOV.
static const bool kRegistered = [] {
  for (std::size_t i = 0; i < subsets().size(); ++i) {
    benchmark::RegisterBenchmark((std::string("FrontEnd/") + subsets()[i].name).c_str(),
                                 [i](benchmark::State& s) { runFrontEnd(s, subsets()[i].cameras); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(3 * kFrames);
  }
  return true;
}();
BENCHMARK(FrontEnd5CamMcslam)
    ->Name("FrontEnd5Cam/mcslam")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3 * kFrames);
BENCHMARK(FrontEnd5CamCvOrb)
    ->Name("FrontEnd5Cam/cv_orb")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3 * kFrames);
BENCHMARK(FrontEnd5CamAlignedMcslam)
    ->Name("FrontEnd5CamAligned/mcslam")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3 * kFrames);
BENCHMARK(FrontEnd5CamAlignedOff)
    ->Name("FrontEnd5CamAligned/off")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3 * kFrames);
BENCHMARK(FrontEnd5CamAlignedMcslam)
    ->Name("FrontEnd5CamUnique/mcslam")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3 * kFrames);
BENCHMARK(FrontEnd5CamUniqueOff)
    ->Name("FrontEnd5CamUnique/off")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3 * kFrames);
