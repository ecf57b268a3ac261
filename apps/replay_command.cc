// `ratslam replay`, `demo`, `print-config`, `import-openratslam`, `import` and `synthesize`.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "apps/demo_config.h"
#include "apps/progress.h"
#include "apps/wifi_sequence_images.h"
#include "common/file_util.h"
#include "common/output_folder.h"
#include "common/provenance.h"
#include "common/version.h"
#include "dataset/dataset.h"
#include "dataset/dataset_loader.h"
#include "dataset/image_loader.h"
#include "dataset/rosbag.h"
#include "dataset/synthetic_dataset.h"
#include "dataset/video.h"
#include "dataset/visual_odometry_source.h"
#include "fusion/replay_pipeline.h"
#include "io/config.h"
#include "io/map_file.h"
#include "io/run_outputs.h"
#include "render/renderer.h"
#include "session/replay_session.h"
#include "sim/world.h"
#include "viewer/animation.h"
#include "viewer/figures.h"
#include "viewer/run_images.h"

namespace ratslam::apps {
namespace {

namespace fs = std::filesystem;

struct ReplayRequest {
  session::ReplaySessionOptions session;
  std::string out;
  bool quiet = false;
  bool render = false;         // write experience_map.png, template_graph.png, pose_cells.png
  uint64_t animate_every = 0;  // events between animation frames; 0: no animation
  bool json = false;           // the summary as JSON on stdout even on a terminal
  std::vector<viewer::FigureFormat> formats{viewer::FigureFormat::kPng};  // of the --render images
  double width_mm = render::kOneColumnMm;
};

// The first and last time of any stream of the data set: the colour range of animation frames.
std::pair<double, double> DataTimeSpan(const dataset::Dataset& d) {
  double first = std::numeric_limits<double>::infinity();
  double last = -std::numeric_limits<double>::infinity();
  auto include = [&](double t) {
    first = std::min(first, t);
    last = std::max(last, t);
  };
  for (const auto& r : d.odometry) include(r.time_s);
  for (const auto& r : d.images) include(r.time_s);
  for (const auto& r : d.wifi) include(r.time_s);
  for (const auto& r : d.compass) include(r.time_s);
  if (!(first < last)) return {0.0, 1.0};
  return {first, last};
}

// The end of a run on a terminal: what was built and how good it is, in three lines.
std::string HumanSummary(const io::RunSummary& s, const session::ReplayResult& result,
                         const fusion::ReplayPipeline& pipeline, const std::string& out) {
  char line[256];
  std::string text;
  if (result.calibration) {
    const std::optional<fusion::FabmapLearningReport> l = pipeline.fabmap_learning();
    const double in_use = l && l->earlier_session_log_odds ? *l->earlier_session_log_odds : 0.0;
    if (result.calibration->earlier_session_log_odds) {
      std::snprintf(line, sizeof line,
                    "%scalibration pass (%.1f s): earlier sessions' places at %.2f nats, learnt "
                    "from %llu verified revisits\n",
                    MessagePrefix().c_str(), result.calibration_wall_seconds, in_use,
                    static_cast<unsigned long long>(result.calibration->verified_revisits));
    } else {
      std::snprintf(line, sizeof line,
                    "%scalibration pass (%.1f s): %llu verified revisits, too few to learn from; "
                    "earlier sessions' places at the configured %.2f nats\n",
                    MessagePrefix().c_str(), result.calibration_wall_seconds,
                    static_cast<unsigned long long>(result.calibration->verified_revisits), in_use);
    }
    text += line;
  }
  std::snprintf(
      line, sizeof line, "%s%llu frames: %llu templates, %llu experiences, %llu loop closures\n",
      MessagePrefix().c_str(), static_cast<unsigned long long>(s.frames),
      static_cast<unsigned long long>(s.templates), static_cast<unsigned long long>(s.experiences),
      static_cast<unsigned long long>(s.loop_closures));
  text += line;
  if (s.map_ate_m && s.odometry_ate_m) {
    std::snprintf(line, sizeof line,
                  "%smap error %.2f m against %.2f m for dead reckoning (ATE over %zu "
                  "points, rigid fit)\n",
                  MessagePrefix().c_str(), *s.map_ate_m, *s.odometry_ate_m, s.ate_points);
    text += line;
  }
  if (s.lost_fraction) {
    std::snprintf(line, sizeof line, "%slocalised in %.1f %% of the frames",
                  MessagePrefix().c_str(), 100.0 * (1.0 - *s.lost_fraction));
    text += line;
    if (s.localisation_median_error_m) {
      std::snprintf(line, sizeof line, ", median error %.2f m (rigid fit)",
                    *s.localisation_median_error_m);
      text += line;
    }
    text += "\n";
  }
  text += MessagePrefix() + "outputs in " + out + " (summary.json; --json prints it here)\n";
  return text;
}

// Parses nothing and decides nothing: runs a replay session and reports what it did.
int RunReplay(const ReplayRequest& request) {
  auto fail = [](const Status& s) {
    std::cerr << MessagePrefix() << s.message() << "\n";
    return kExitError;
  };
  StatusOr<std::unique_ptr<DiskFolder>> out = DiskFolder::Open(request.out);
  if (!out.ok()) return fail(out.status());
  // Messages name the folder the outputs end up in, not the staging folder they are written to.
  auto shown = [&](const std::string& path) { return request.session.provenance.Recorded(path); };
  ProgressPrinter progress(stderr, request.quiet);
  session::SessionEnvironment environment;
  environment.out = out->get();
  environment.progress = &progress;
  environment.stop_requested = &StopFlag();
  session::ReplaySession session(request.session, environment);
  // Ctrl-C stops the replay cleanly; the handler stays until the outputs and the map are saved,
  // so a second signal during the writes cannot lose them.
  StopOnSignals();
  struct RestoreSignals {
    ~RestoreSignals() {
      std::signal(SIGINT, SIG_DFL);
      std::signal(SIGTERM, SIG_DFL);
    }
  } restore_signals;

  // Animation: a frame of the experience map every `animate_every` events.
  std::unique_ptr<render::SceneRenderer> animation_renderer;
  std::unique_ptr<viewer::AnimationWriter> animation;
  session::ReplayCheckpoint checkpoint;
  if (request.animate_every > 0) {
    StatusOr<std::unique_ptr<render::SceneRenderer>> renderer = render::CreateOsMesaRenderer();
    if (!renderer.ok()) return fail(renderer.status().WithContext("--animate"));
    animation_renderer = std::move(renderer.value());
    animation = std::make_unique<viewer::AnimationWriter>(
        (fs::path(request.out) / "animation").string(), 10.0);
    checkpoint.every = request.animate_every;
    checkpoint.callback = [&](const fusion::ReplayPipeline& p) -> Status {
      viewer::ExperienceMapImageOptions options;
      options.width_px = 960;
      options.height_px = 720;
      char title[96];
      std::snprintf(title, sizeof title, "%s  t = %.1f s", session.dataset().name.c_str(),
                    p.state().trajectory.empty() ? 0.0 : p.state().trajectory.back().time_s);
      options.title = title;
      // One colour scale for the whole animation (each frame used to stretch it over its own
      // experiences, so a colour meant a different time in every frame).
      options.time_range_s = DataTimeSpan(session.dataset());
      StatusOr<render::RgbaImage> frame = animation_renderer->Render(viewer::ExperienceMapScene(
          viewer::ExperienceMapDataOf(p.View(), session.dataset()), options));
      if (!frame.ok()) return frame.status();
      return animation->AddFrame(frame.value());
    };
  }
  if (Status loaded = session.Load(); !loaded.ok()) return fail(loaded);
  if (Status prepared = session.Prepare(); !prepared.ok()) return fail(prepared);
  (void)session.Replay(checkpoint);
  if (animation) {
    const bool video = animation->Close();
    std::cerr << MessagePrefix() << "wrote " << animation->frames() << " animation frames"
              << (video ? " and animation.avi" : " (no video writer available)") << " to "
              << shown((fs::path(request.out) / "animation").string()) << "\n";
  }
  (void)session.WriteOutputs();
  (void)session.SaveMap();
  const session::ReplayResult& result = session.result();

  int exit_code = kExitOk;
  if (result.summary) {
    PrintOutcome(request.json, request.quiet, result.summary->json,
                 HumanSummary(*result.summary, result, session.pipeline(), shown(request.out)));
  }
  if (!result.outputs.ok()) exit_code = fail(result.outputs);
  if (!result.save.ok()) exit_code = fail(result.save);
  if (request.render && result.outputs.ok()) {
    const bool png = std::find(request.formats.begin(), request.formats.end(),
                               viewer::FigureFormat::kPng) != request.formats.end();
    StatusOr<std::unique_ptr<render::SceneRenderer>> renderer =
        png ? render::CreateOsMesaRenderer()
            : StatusOr<std::unique_ptr<render::SceneRenderer>>(nullptr);
    Status rendered =
        renderer.ok()
            ? viewer::WriteRunImages(renderer->get(), session.pipeline().View(), session.dataset(),
                                     request.out, request.formats, request.width_mm)
            : renderer.status();
    if (rendered.ok() && session.pipeline().wifi_sequence().options().enabled) {
      rendered = WriteWifiSequenceImages(renderer->get(), session.pipeline(), request.out,
                                         request.formats, request.width_mm);
    }
    if (!rendered.ok()) exit_code = fail(rendered.WithContext("images not written"));
  }
  if (!result.replay.ok()) {
    std::cerr << MessagePrefix() << result.replay.message() << "\n";
    if (result.outputs.ok()) {
      std::cerr << MessagePrefix() << "outputs up to the last complete event are in "
                << shown(request.out) << "\n";
    }
    if (!result.saved_map.empty()) {
      std::cerr << MessagePrefix() << "the state is saved in " << shown(result.saved_map) << "\n";
    }
    return kExitError;
  }
  if (exit_code != kExitOk) return exit_code;
  if (result.interrupted) {
    std::cerr << MessagePrefix() << "interrupted; state saved in " << shown(result.saved_map)
              << "\n";
    return kExitInterrupted;
  }
  if (result.summary && result.summary->frames == 0) {
    std::cerr << MessagePrefix()
              << "the run processed no frame (no view for the front end to judge); "
                 "the outputs in "
              << shown(request.out) << " hold dead reckoning only\n";
    return kExitError;
  }
  return kExitOk;
}

}  // namespace

int ReplayCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  ReplayRequest request;
  auto options = LoadOptions(*args, &request.session.config_path);
  if (!options) return kExitError;
  request.session.pipeline = *options;
  request.session.data = args->all.at("--data");
  request.session.provenance = args->Provenance();
  request.session.lenient = args->lenient;
  request.out = args->values.at("--out");
  request.session.save_map = args->Value("--save-map");
  request.session.load_map = args->Value("--load-map");
  request.session.localise = args->values.count("--localise") > 0;
  if (args->values.count("--lost-after") && !request.session.localise) {
    std::cerr << MessagePrefix() << "--lost-after applies only with --localise\n";
    return kExitUsage;
  }
  if (args->Has("--lost-after")) request.session.lost_after_m = args->Number("--lost-after");
  if (args->Has("--until")) request.session.until_s = args->Number("--until");
  if (args->Has("--animate"))
    request.animate_every = static_cast<uint64_t>(args->Whole("--animate"));
  request.quiet = args->quiet;
  request.render = args->render;
  request.json = args->values.count("--json") > 0;
  StatusOr<FigureOptions> figure = FigureOptionsOf(*args);
  if (!figure.ok()) {
    std::cerr << MessagePrefix() << figure.status().message() << "\n";
    return kExitUsage;
  }
  if (figure->formats) request.formats = *figure->formats;
  request.width_mm = figure->width_mm;
  return RunReplay(request);
}

int Synthesize(const dataset::SyntheticOptions& options, const std::string& folder,
               const std::string& shown_folder, const std::string& bag_path,
               const std::string& video_path, bool quiet) {
  StatusOr<dataset::Dataset> d = dataset::WriteSyntheticDataset(options, folder);
  if (!d.ok()) {
    std::cerr << MessagePrefix() << d.status().message() << "\n";
    return kExitError;
  }
  if (!quiet) {
    std::cerr << MessagePrefix() << "wrote " << d->images.size() << " frames of '" << d->name
              << "' to " << shown_folder << "\n";
  }
  if (!bag_path.empty()) {
    // OpenRatSLAM's topic names under the root "synthetic" (what topic_root=synthetic implies).
    const dataset::BagTopics topics{"/synthetic/camera/image/compressed", "/synthetic/odom",
                                    "/synthetic/ground_truth", ""};
    StatusOr<dataset::Dataset> written = dataset::ReadDataset(folder);
    dataset::FileImageLoader images;
    Status s =
        written.ok() ? dataset::WriteRosbag(*written, &images, topics, bag_path) : written.status();
    if (!s.ok()) {
      std::cerr << MessagePrefix() << s.message() << "\n";
      return kExitError;
    }
    if (!quiet) {
      std::cerr << MessagePrefix() << "wrote the same frames as a ROS bag to " << bag_path << " ("
                << topics.image_topic << ", " << topics.odometry_topic << ", "
                << topics.ground_truth_topic << ")\n";
    }
  }
  if (!video_path.empty()) {
    StatusOr<dataset::Dataset> written = dataset::ReadDataset(folder);
    dataset::FileImageLoader images;
    Status s = written.ok() ? dataset::WriteVideo(*written, &images, video_path, options.rate_hz)
                            : written.status();
    if (!s.ok()) {
      std::cerr << MessagePrefix() << s.message() << "\n";
      return kExitError;
    }
    if (!quiet) {
      std::cerr << MessagePrefix() << "wrote the same frames as a video to " << video_path
                << " with OpenRatSLAM's odometry log beside it\n";
    }
  }
  return kExitOk;
}

int DemoCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  const std::string out = args->values.at("--out");
  const std::string data = (fs::path(out) / "data").string();
  // The demo's data: a built-in simulated world with camera, Wi-Fi, compass and odometry.
  auto world = sim::BuiltInWorld(DemoWorldName());
  if (!world.ok()) {
    std::cerr << MessagePrefix() << world.status().message() << "\n";
    return kExitError;
  }
  dataset::Dataset simulated;
  Status s = SimulateWorld(*world, 1, data, args->quiet, &simulated);
  if (!s.ok()) {
    std::cerr << MessagePrefix() << s.message() << "\n";
    return kExitError;
  }
  ReplayRequest request;
  request.session.pipeline = DemoPipelineOptions();
  request.session.config_path = "(built-in demo configuration, as configs/demo.toml)";
  request.session.data = {data};
  request.session.provenance = args->Provenance();
  request.out = out;
  request.quiet = args->quiet;
  request.json = args->values.count("--json") > 0;
  request.render = true;
  return RunReplay(request);
}

int PrintConfigCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  const bool locate = args->positional == std::vector<std::string>{"locate"};
  if (locate) {  // the configuration of wifi-map and locate
    phone::LocateOptions o;
    if (args->values.count("--config")) {
      StatusOr<phone::LocateOptions> loaded = io::LoadLocateConfigFile(args->values.at("--config"));
      if (!loaded.ok()) {
        std::cerr << MessagePrefix() << loaded.status().message() << "\n";
        return kExitError;
      }
      o = *loaded;
    }
    std::cout << io::PrintLocateConfig(o);
    return kExitOk;
  }
  std::string path;
  auto options = LoadOptions(*args, &path);
  if (!options) return kExitError;
  std::cout << io::PrintConfig(*options);
  return kExitOk;
}

int ImportOpenRatslamCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  StatusOr<io::ImportedConfig> imported = io::ImportOpenRatslamIni(args->positional[0]);
  if (!imported.ok()) {
    std::cerr << MessagePrefix() << imported.status().message() << "\n";
    return kExitError;
  }
  std::cout << "# Imported from " << args->positional[0] << ".\n";
  for (const std::string& note : imported->notes) {
    std::cout << "# " << note << "\n";
    std::cerr << MessagePrefix() << note << "\n";
  }
  std::cout << io::PrintConfig(imported->options);
  return kExitOk;
}

int ImportCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  std::string config_path;
  auto options = LoadOptions(*args, &config_path);
  if (!options) return kExitError;
  dataset::PhoneLogOptions phone;
  phone.lenient = args->lenient;
  phone.pdr = options->pdr;
  StatusOr<dataset::Dataset> d =
      dataset::LoadSessions(args->all.at("--data"), phone, 1.0, options->bag, options->video);
  if (!d.ok()) {
    std::cerr << MessagePrefix() << d.status().message() << "\n";
    return kExitError;
  }
  const std::string out = args->values.at("--out");
  Status copied = dataset::CopyImagesInto(&d.value(), out, [&](size_t done, size_t total) {
    if (!args->quiet) {
      std::cerr << MessagePrefix() << "images " << done << " / " << total << "\n";
    }
  });
  if (!copied.ok()) {
    std::cerr << MessagePrefix() << copied.message() << "\n";
    return kExitError;
  }
  Status written = dataset::WriteDataset(d.value(), out);
  if (!written.ok()) {
    std::cerr << MessagePrefix() << written.message() << "\n";
    return kExitError;
  }
  std::cerr << MessagePrefix() << "wrote '" << d->name << "' (" << d->odometry.size()
            << " odometry rows, " << d->images.size() << " images, " << d->wifi.size()
            << " Wi-Fi scans, " << d->compass.size() << " compass rows, " << d->ground_truth.size()
            << " ground-truth rows) to " << args->Shown(out) << "\n";
  return kExitOk;
}

int SynthesizeCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  dataset::SyntheticOptions options = DemoSyntheticOptions();
  if (args->Has("--seed")) options.seed = static_cast<uint64_t>(args->Whole("--seed"));
  if (args->Has("--laps")) options.laps = static_cast<int>(args->Whole("--laps"));
  if (args->Has("--noise-seed")) {
    options.noise_seed = static_cast<uint64_t>(args->Whole("--noise-seed"));
  }
  if (args->Has("--start-m")) options.start_m = args->Number("--start-m");
  return Synthesize(options, args->values.at("--out"), args->Shown(args->values.at("--out")),
                    args->Value("--bag"), args->Value("--video"), args->quiet);
}

}  // namespace ratslam::apps
