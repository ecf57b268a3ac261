// End-to-end replay in the library of the built-in synthetic camera loop driven ten times
// (`ratslam synthesize --laps 10`: 12,114 frames) with configs/synthetic.toml, images decoded
// once before timing. Two map sizes: the shipped config (333 templates, 375 experiences), and
// OpenRatSLAM's scale, the same with [camera] match_threshold 0.015 (1,924 templates, 1,934
// experiences, 2,414 links: the size of map OpenRatSLAM's St Lucia-like settings make of this
// route). Three relaxation settings in the same run: the full scheme (OpenRatSLAM's, the
// baseline), the incremental scheme (the default), and no relaxation at all (the cost of
// everything else: the difference to it is what relaxation costs). Each run also reports the
// stages' share of a frame (front end, pose cells, experience map).
#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "common/scratch_dir.h"
#include "dataset/synthetic_dataset.h"
#include "fusion/replay_pipeline.h"
#include "io/config.h"
#include "tests/test_paths.h"

namespace ratslam {
namespace {

class MemoryImages : public ImageLoader {
 public:
  StatusOr<GrayImage> Load(const std::string& path) override {
    auto it = images_.find(path);
    if (it == images_.end()) return Status::Error("not preloaded: " + path);
    return it->second;
  }
  std::map<std::string, GrayImage> images_;
};

struct Workload {
  ScratchDir folder{"replay_benchmark"};
  dataset::Dataset dataset;
  MemoryImages images;
  fusion::PipelineOptions options;
  std::string error;
};

Workload* GetWorkload() {
  static Workload* w = [] {
    auto* w = new Workload;
    dataset::SyntheticOptions synthetic;
    synthetic.laps = 10;
    StatusOr<dataset::Dataset> d =
        dataset::WriteSyntheticDataset(synthetic, (w->folder.path() / "d").string());
    StatusOr<fusion::PipelineOptions> o =
        io::LoadConfigFile(test_paths::SourceDir() + "/configs/synthetic.toml");
    if (!d.ok() || !o.ok()) {
      w->error = !d.ok() ? d.status().message() : o.status().message();
      return w;
    }
    w->dataset = std::move(*d);
    w->options = *o;
    dataset::FileImageLoader files;
    for (const ImageRow& row : w->dataset.images) {
      const std::string path = w->dataset.ImagePath(row);
      StatusOr<GrayImage> image = files.Load(path);
      if (!image.ok()) {
        w->error = image.status().message();
        return w;
      }
      w->images.images_[path] = std::move(*image);
    }
    return w;
  }();
  return w;
}

// Arguments: map size (0 shipped config, 1 OpenRatSLAM scale); 0 full relaxation, 1
// incremental, 2 none, 3 least squares at loop closures.
void BM_SyntheticReplay(benchmark::State& state) {
  Workload* w = GetWorkload();
  if (!w->error.empty()) {
    state.SkipWithError(w->error.c_str());
    return;
  }
  fusion::PipelineOptions options = w->options;
  if (state.range(0) == 1) options.sensors.classic_camera.match_threshold = 0.015;
  ExperienceMapOptions& map = options.ratslam.experience_map;
  map.relaxation_scheme = state.range(1) == 0   ? RelaxationScheme::kFull
                          : state.range(1) == 3 ? RelaxationScheme::kLeastSquares
                                                : RelaxationScheme::kIncremental;
  if (state.range(1) == 2) map.relaxation_sweeps = 0;
  uint64_t frames = 0, link_updates = 0;
  size_t templates = 0, experiences = 0, links = 0;
  StageTimes stages;
  for (auto _ : state) {
    fusion::ReplayPipeline pipeline(options, w->dataset, &w->images);
    pipeline.AttachStageTimes(&stages);
    const Status s = pipeline.Run({});
    if (!s.ok()) {
      state.SkipWithError(s.message().c_str());
      return;
    }
    frames = pipeline.state().frames.size();
    const Ratslam& slam = pipeline.slam();
    templates = slam.local_view().size();
    experiences = slam.experience_map().num_experiences();
    links = slam.experience_map().num_links();
    link_updates = slam.experience_map().relaxation_link_updates();
  }
  state.counters["frames"] = static_cast<double>(frames);
  state.counters["templates"] = static_cast<double>(templates);
  state.counters["experiences"] = static_cast<double>(experiences);
  state.counters["links"] = static_cast<double>(links);
  state.counters["link_updates_per_frame"] =
      static_cast<double>(link_updates) / static_cast<double>(frames);
  // The stages' share of a frame in microseconds, averaged over the iterations: template
  // matching, pose cells, experience map (what the rest of the frame costs is time_per_frame
  // less these: reading events, records, odometry).
  const double per_frame_us =
      1e6 / (static_cast<double>(frames) * static_cast<double>(state.iterations()));
  state.counters["front_end_us"] = stages.front_end_s * per_frame_us;
  state.counters["pose_cells_us"] = stages.pose_cells_s * per_frame_us;
  state.counters["experience_map_us"] = stages.experience_map_s * per_frame_us;
  // Time per frame (shown in seconds with a prefix): the inverse rate of frames.
  state.counters["time_per_frame"] = benchmark::Counter(
      static_cast<double>(frames),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SyntheticReplay)
    ->ArgNames({"openratslam_scale", "scheme_full0_incremental1_none2_lsq3"})
    ->ArgsProduct({{0, 1}, {0, 1, 2, 3}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
