// The `ratslam` command line: replay a data set, run the demo, print or import configurations,
// and write the built-in synthetic data set.
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
#include "common/file_util.h"
#include "fusion/io/config.h"
#include "fusion/io/map_file.h"
#include "fusion/io/run_outputs.h"
#include "fusion/replay_pipeline.h"
#include "sensors/dataset/dataset.h"
#include "sensors/dataset/dataset_loader.h"
#include "sensors/dataset/image_loader.h"
#include "sensors/dataset/synthetic_dataset.h"
#include "sensors/dataset/visual_odometry_source.h"
#include "sim/world.h"
#include "viewer/animation.h"
#include "viewer/figures.h"
#include "viewer/renderer.h"
#include "viewer/run_images.h"

namespace ratslam {
namespace {

namespace fs = std::filesystem;

std::atomic<bool> g_stop_requested{false};

extern "C" void OnSignal(int) { g_stop_requested.store(true); }

const char kUsage[] =
    "usage:\n"
    "  ratslam replay --data D [--data D2 ...] --out O [--config C] [--save-map F]\n"
    "                 [--load-map F] [--until T] [--render] [--animate N] [--lenient] [--quiet]\n"
    "      Replays data set D (a replay-format folder or an IPIN log; several --data make one\n"
    "      multi-session run) and writes the map, trajectory and summary into O. --until T stops "
    "after data time T seconds; --save-map F saves the\n"
    "      whole state to F; --load-map F resumes from F. Ctrl-C stops cleanly and saves.\n"
    "      --render also writes experience_map.png, template_graph.png and pose_cells.png;\n"
    "      --animate N writes an experience-map frame every N events to O/animation/.\n"
    "      --lenient skips and counts malformed lines of phone logs instead of failing.\n"
    "  ratslam import --data D [--data D2 ...] --out F [--config C] [--lenient]\n"
    "      Converts data sets (IPIN logs, ...) to the replay format in folder F.\n"
    "  ratslam demo --out O [--quiet]\n"
    "      Simulates the built-in day_night world (camera, Wi-Fi, compass, odometry) into\n"
    "      O/data, replays it into O with the fused front end and renders the images.\n"
    "  ratslam print-config [--config C]\n"
    "      Prints the resolved configuration (the defaults when no file is given).\n"
    "  ratslam import-openratslam FILE.ini\n"
    "      Converts an OpenRatSLAM configuration file to ours (TOML on stdout).\n"
    "  ratslam synthesize --out D [--seed S] [--laps N]\n"
    "      Writes the built-in synthetic camera loop into D (configs/synthetic.toml).\n"
    "  ratslam render experience-map --run O [--data D] [--out F] [--size WxH]\n"
    "                 [--color time|session] [--sessions T1,T2,...]\n"
    "  ratslam render template-graph --run O [--out F] [--size WxH] [--spans A-B:label,...]\n"
    "  ratslam render pose-cells --map F [--config C] --out F\n"
    "  ratslam render similarity --data D [--data D2 ...] [--config C] --out F [--frames N]\n"
    "                 [--sensor camera|wifi]\n"
    "      Images from a run folder, a saved map, or a data set (PNG).\n"
    "  ratslam evaluate [--config C] --map M --query Q --out O [--quiet]\n"
    "      FABMAP localisation benchmark: maps M, localises every node of Q, writes\n"
    "      evaluation.json, queries.csv and localisation.png to O. M and Q may be the same\n"
    "      data set: [evaluation] split and map_fraction then divide it.\n"
    "  ratslam simulate --world NAME|FILE --out D [--seed S] [--quiet]\n"
    "      Simulates a world (built in: office, circular, day_night, aliased_floors,\n"
    "      apartment; or a world TOML file) into the replay data set D, with world.toml,\n"
    "      simulation.json and ground_truth.png.\n";

struct ReplayRequest {
  PipelineOptions options;
  std::string config_path;        // empty: built-in
  std::vector<std::string> data;  // one data set, or several sessions
  bool lenient = false;           // skip malformed lines of phone logs
  std::string out;
  std::string save_map;
  std::string load_map;
  double until_s = std::numeric_limits<double>::infinity();
  bool quiet = false;
  bool render = false;         // write experience_map.png, template_graph.png, pose_cells.png
  uint64_t animate_every = 0;  // events between animation frames; 0: no animation
};

int RunReplay(const ReplayRequest& request) {
  PhoneLogOptions phone;
  phone.lenient = request.lenient;
  phone.pdr = request.options.pdr;
  StatusOr<Dataset> dataset = LoadSessions(request.data, phone);
  if (!dataset.ok()) {
    std::cerr << "ratslam: " << dataset.status().message() << "\n";
    return kExitError;
  }
  FileImageLoader images;
  if (request.options.visual_odometry.enabled) {
    Status replaced =
        ReplaceOdometryWithVisual(&dataset.value(), &images, request.options.visual_odometry);
    if (!replaced.ok()) {
      std::cerr << "ratslam: visual odometry: " << replaced.message() << "\n";
      return kExitError;
    }
  }
  std::error_code ec;
  fs::create_directories(request.out, ec);
  if (ec) {
    std::cerr << "ratslam: " << request.out << ": cannot create: " << ec.message() << "\n";
    return kExitError;
  }
  const std::string resolved =
      "# Resolved configuration of this run (ratslam print-config format).\n" +
      PrintConfig(request.options);
  Status written = WriteFileAtomically((fs::path(request.out) / "config.toml").string(), resolved);
  if (!written.ok()) {
    std::cerr << "ratslam: " << written.message() << "\n";
    return kExitError;
  }

  std::shared_ptr<const FabmapResources> fabmap;
  if (request.options.sensors.front_end.kind == FrontEndKind::kFabmap) {
    auto prepared = PrepareFabmapResources(request.options.sensors, dataset.value(), images);
    if (!prepared.ok()) {
      std::cerr << "ratslam: FABMAP front end: " << prepared.status().message() << "\n";
      return kExitError;
    }
    fabmap = *prepared;
  }
  ReplayPipeline pipeline(request.options, dataset.value(), &images, fabmap);
  const uint64_t fingerprint = ConfigFingerprint(request.options);
  if (!request.load_map.empty()) {
    StatusOr<MapFile> map = LoadMapFile(request.load_map);
    if (!map.ok()) {
      std::cerr << "ratslam: " << map.status().message() << "\n";
      return kExitError;
    }
    if (map->config_fingerprint != fingerprint) {
      std::cerr << "ratslam: " << request.load_map
                << ": the map was made with a different configuration\n";
      return kExitError;
    }
    if (map->dataset_name != dataset->name) {
      std::cerr << "ratslam: " << request.load_map << ": the map was made from data set '"
                << map->dataset_name << "', not '" << dataset->name << "'\n";
      return kExitError;
    }
    Status restored = pipeline.Restore(map->state);
    if (!restored.ok()) {
      std::cerr << "ratslam: " << request.load_map << ": " << restored.message() << "\n";
      return kExitError;
    }
  }

  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  ProgressPrinter progress(stderr, request.quiet);
  ReplayControl control;
  control.until_time_s = request.until_s;
  control.stop_requested = &g_stop_requested;
  control.progress = [&progress](const ReplayProgress& p) { progress.Update(p); };
  // Animation: a frame of the experience map every `animate_every` events.
  std::unique_ptr<SceneRenderer> animation_renderer;
  std::unique_ptr<AnimationWriter> animation;
  if (request.animate_every > 0) {
    StatusOr<std::unique_ptr<SceneRenderer>> renderer = CreateOsMesaRenderer();
    if (!renderer.ok()) {
      std::cerr << "ratslam: --animate: " << renderer.status().message() << "\n";
      return kExitError;
    }
    animation_renderer = std::move(renderer.value());
    animation =
        std::make_unique<AnimationWriter>((fs::path(request.out) / "animation").string(), 10.0);
    control.checkpoint_every = request.animate_every;
    control.checkpoint = [&](const ReplayPipeline& p) -> Status {
      ExperienceMapImageOptions options;
      options.width_px = 960;
      options.height_px = 720;
      char title[96];
      std::snprintf(title, sizeof title, "%s  t = %.1f s", dataset->name.c_str(),
                    p.state().trajectory.empty() ? 0.0 : p.state().trajectory.back().time_s);
      options.title = title;
      StatusOr<RgbaImage> frame = animation_renderer->Render(
          ExperienceMapScene(ExperienceMapDataOf(p, dataset.value()), options));
      if (!frame.ok()) return frame.status();
      return animation->AddFrame(frame.value());
    };
  }
  const uint64_t frames_before = pipeline.state().frames.size();
  const auto start = std::chrono::steady_clock::now();
  const Status run = pipeline.Run(control);
  const double wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  progress.Finish();
  if (animation) {
    const bool video = animation->Close();
    std::cerr << "ratslam: wrote " << animation->frames() << " animation frames"
              << (video ? " and animation.avi" : " (no video writer available)") << " to "
              << (fs::path(request.out) / "animation").string() << "\n";
  }
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  const bool interrupted = g_stop_requested.load();

  // Whatever happened, write what exists.
  RunInfo info;
  info.wall_seconds = wall_seconds;
  info.frames_this_run = pipeline.state().frames.size() - frames_before;
  info.interrupted = interrupted;
  info.config_path = request.config_path;
  info.config_fingerprint = fingerprint;
  info.resumed_from = request.load_map;
  StatusOr<RunSummary> summary = WriteRunOutputs(request.out, pipeline, dataset.value(), info);
  if (!summary.ok()) {
    std::cerr << "ratslam: " << summary.status().message() << "\n";
    return kExitError;
  }
  std::string save_path = request.save_map;
  if (save_path.empty() && (interrupted || !run.ok())) {
    save_path = (fs::path(request.out) / "interrupted.map").string();
  }
  if (!save_path.empty()) {
    MapFile map{fingerprint, dataset->name, pipeline.Snapshot()};
    Status saved = SaveMapFile(map, save_path);
    if (!saved.ok()) {
      std::cerr << "ratslam: " << saved.message() << "\n";
      return kExitError;
    }
  }
  std::cout << summary->json;
  if (request.render) {
    StatusOr<std::unique_ptr<SceneRenderer>> renderer = CreateOsMesaRenderer();
    Status rendered =
        renderer.ok() ? WriteRunImages(*renderer.value(), pipeline, dataset.value(), request.out)
                      : renderer.status();
    if (!rendered.ok()) {
      std::cerr << "ratslam: images not written: " << rendered.message() << "\n";
      return kExitError;
    }
  }
  if (!run.ok()) {
    std::cerr << "ratslam: " << run.message() << "\n"
              << "ratslam: outputs up to the last complete event are in " << request.out
              << "; the state is saved in " << save_path << "\n";
    return kExitError;
  }
  if (interrupted) {
    std::cerr << "ratslam: interrupted; state saved in " << save_path << "\n";
    return kExitInterrupted;
  }
  return kExitOk;
}

int Replay(int argc, char** argv) {
  auto args = ParseArguments(
      argc, argv, 2,
      {"--config", "--data", "--out", "--save-map", "--load-map", "--until", "--animate"});
  if (!args || !args->positional.empty() || !args->values.count("--data") ||
      !args->values.count("--out")) {
    std::cerr << kUsage;
    return kExitUsage;
  }
  ReplayRequest request;
  auto options = LoadOptions(*args, &request.config_path);
  if (!options) return kExitError;
  request.options = *options;
  request.data = args->all["--data"];
  request.lenient = args->lenient;
  request.out = args->values["--out"];
  request.save_map = args->values.count("--save-map") ? args->values["--save-map"] : "";
  request.load_map = args->values.count("--load-map") ? args->values["--load-map"] : "";
  if (args->values.count("--until")) {
    auto until = ParseNumber("--until", args->values["--until"]);
    if (!until) return kExitUsage;
    request.until_s = *until;
  }
  if (args->values.count("--animate")) {
    auto every = ParseInteger("--animate", args->values["--animate"], 1, int64_t{1} << 53);
    if (!every) return kExitUsage;
    request.animate_every = static_cast<uint64_t>(*every);
  }
  request.quiet = args->quiet;
  request.render = args->render;
  return RunReplay(request);
}

int Synthesize(const SyntheticOptions& options, const std::string& folder) {
  StatusOr<Dataset> d = WriteSyntheticDataset(options, folder);
  if (!d.ok()) {
    std::cerr << "ratslam: " << d.status().message() << "\n";
    return kExitError;
  }
  std::cerr << "ratslam: wrote " << d->images.size() << " frames of '" << d->name << "' to "
            << folder << "\n";
  return kExitOk;
}

int Demo(int argc, char** argv) {
  auto args = ParseArguments(argc, argv, 2, {"--out"});
  if (!args || !args->positional.empty() || !args->values.count("--out")) {
    std::cerr << kUsage;
    return kExitUsage;
  }
  const std::string out = args->values["--out"];
  const std::string data = (fs::path(out) / "data").string();
  // The demo's data: a built-in simulated world with camera, Wi-Fi, compass and odometry.
  auto world = sim::BuiltInWorld(DemoWorldName());
  if (!world.ok()) {
    std::cerr << "ratslam: " << world.status().message() << "\n";
    return kExitError;
  }
  Dataset simulated;
  Status s = SimulateWorld(*world, 1, data, args->quiet, &simulated);
  if (!s.ok()) {
    std::cerr << "ratslam: " << s.message() << "\n";
    return kExitError;
  }
  ReplayRequest request;
  request.options = DemoPipelineOptions();
  request.config_path = "(built-in demo configuration, as configs/demo.toml)";
  request.data = {data};
  request.out = out;
  request.quiet = args->quiet;
  request.render = true;
  return RunReplay(request);
}

int PrintConfigCommand(int argc, char** argv) {
  auto args = ParseArguments(argc, argv, 2, {"--config"});
  if (!args || !args->positional.empty()) {
    std::cerr << kUsage;
    return kExitUsage;
  }
  std::string path;
  auto options = LoadOptions(*args, &path);
  if (!options) return kExitError;
  std::cout << PrintConfig(*options);
  return kExitOk;
}

int ImportOpenRatslam(int argc, char** argv) {
  auto args = ParseArguments(argc, argv, 2, {});
  if (!args || args->positional.size() != 1) {
    std::cerr << kUsage;
    return kExitUsage;
  }
  StatusOr<ImportedConfig> imported = ImportOpenRatslamIni(args->positional[0]);
  if (!imported.ok()) {
    std::cerr << "ratslam: " << imported.status().message() << "\n";
    return kExitError;
  }
  std::cout << "# Imported from " << args->positional[0] << ".\n";
  for (const std::string& note : imported->notes) {
    std::cout << "# " << note << "\n";
    std::cerr << "ratslam: " << note << "\n";
  }
  std::cout << PrintConfig(imported->options);
  return kExitOk;
}

int ImportCommand(int argc, char** argv) {
  auto args = ParseArguments(argc, argv, 2, {"--data", "--out", "--config"});
  if (!args || !args->positional.empty() || !args->values.count("--data") ||
      !args->values.count("--out")) {
    std::cerr << kUsage;
    return kExitUsage;
  }
  std::string config_path;
  auto options = LoadOptions(*args, &config_path);
  if (!options) return kExitError;
  PhoneLogOptions phone;
  phone.lenient = args->lenient;
  phone.pdr = options->pdr;
  StatusOr<Dataset> d = LoadSessions(args->all["--data"], phone);
  if (!d.ok()) {
    std::cerr << "ratslam: " << d.status().message() << "\n";
    return kExitError;
  }
  if (!d->images.empty()) {
    std::cerr << "ratslam: import copies no images; convert image data sets by hand\n";
    return kExitError;
  }
  Status written = WriteDataset(d.value(), args->values["--out"]);
  if (!written.ok()) {
    std::cerr << "ratslam: " << written.message() << "\n";
    return kExitError;
  }
  std::cerr << "ratslam: wrote '" << d->name << "' (" << d->odometry.size() << " odometry rows, "
            << d->wifi.size() << " Wi-Fi scans, " << d->compass.size() << " compass rows, "
            << d->ground_truth.size() << " ground-truth rows) to " << args->values["--out"] << "\n";
  return kExitOk;
}

int SynthesizeCommand(int argc, char** argv) {
  auto args = ParseArguments(argc, argv, 2, {"--out", "--seed", "--laps"});
  if (!args || !args->positional.empty() || !args->values.count("--out")) {
    std::cerr << kUsage;
    return kExitUsage;
  }
  SyntheticOptions options = DemoSyntheticOptions();
  if (args->values.count("--seed")) {
    auto seed = ParseInteger("--seed", args->values["--seed"], 0, int64_t{1} << 53);
    if (!seed) return kExitUsage;
    options.seed = static_cast<uint64_t>(*seed);
  }
  if (args->values.count("--laps")) {
    auto laps = ParseInteger("--laps", args->values["--laps"], 1, 1000);
    if (!laps) return kExitUsage;
    options.laps = static_cast<int>(*laps);
  }
  return Synthesize(options, args->values["--out"]);
}

}  // namespace
}  // namespace ratslam

namespace {

int Dispatch(int argc, char** argv) {
  using namespace ratslam;
  if (argc < 2) {
    std::cerr << kUsage;
    return kExitUsage;
  }
  const std::string command = argv[1];
  if (command == "replay") return Replay(argc, argv);
  if (command == "demo") return Demo(argc, argv);
  if (command == "print-config") return PrintConfigCommand(argc, argv);
  if (command == "import-openratslam") return ImportOpenRatslam(argc, argv);
  if (command == "synthesize") return SynthesizeCommand(argc, argv);
  if (command == "render") return RenderCommand(argc, argv);
  if (command == "evaluate") return EvaluateCommand(argc, argv);
  if (command == "simulate") return SimulateCommand(argc, argv);
  if (command == "import") return ImportCommand(argc, argv);
  if (command == "--help" || command == "help" || command == "-h") {
    std::cout << kUsage;
    return kExitOk;
  }
  std::cerr << "ratslam: unknown command '" << command << "'\n" << kUsage;
  return kExitUsage;
}

}  // namespace

// Expected failures come back as Status; an exception here is a bug or an exhausted machine
// (std::bad_alloc). Either way the program says so and exits non-zero instead of aborting.
int main(int argc, char** argv) {
  try {
    return Dispatch(argc, argv);
  } catch (const std::bad_alloc&) {
    std::cerr << "ratslam: out of memory\n";
  } catch (const std::exception& e) {
    std::cerr << "ratslam: internal error: " << e.what() << "\n";
  }
  return ratslam::kExitInternal;
}
