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
#include "apps/wifi_sequence_images.h"
#include "common/file_util.h"
#include "common/output_folder.h"
#include "common/provenance.h"
#include "common/version.h"
#include "fusion/io/config.h"
#include "fusion/io/map_file.h"
#include "fusion/io/run_outputs.h"
#include "fusion/replay_pipeline.h"
#include "render/renderer.h"
#include "sensors/dataset/dataset.h"
#include "sensors/dataset/dataset_loader.h"
#include "sensors/dataset/image_loader.h"
#include "sensors/dataset/synthetic_dataset.h"
#include "sensors/dataset/visual_odometry_source.h"
#include "session/replay_session.h"
#include "sim/world.h"
#include "viewer/animation.h"
#include "viewer/figures.h"
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
    "      --render also writes experience_map.png, template_graph.png and pose_cells.png\n"
    "      (and with [wifi_sequence] wifi_sequence_similarity.png and wifi_sequence_pairs.png);\n"
    "      --animate N writes an experience-map frame every N events to O/animation/.\n"
    "      --lenient skips and counts malformed lines of phone logs instead of failing.\n"
    "  ratslam import --data D [--data D2 ...] --out F [--config C] [--lenient]\n"
    "      Converts data sets (IPIN logs, ...) to the replay format in folder F.\n"
    "  ratslam demo --out O [--quiet]\n"
    "      Simulates the built-in day_night world (camera, Wi-Fi, compass, odometry) into\n"
    "      O/data, replays it into O with the fused front end and renders the images.\n"
    "  ratslam print-config [locate] [--config C]\n"
    "      Prints the resolved configuration (the defaults when no file is given); with\n"
    "      `locate`, that of wifi-map and locate.\n"
    "  ratslam import-openratslam FILE.ini\n"
    "      Converts an OpenRatSLAM configuration file to ours (TOML on stdout).\n"
    "  ratslam synthesize --out D [--seed S] [--laps N]\n"
    "      Writes the built-in synthetic camera loop into D (configs/synthetic.toml).\n"
    "  ratslam render experience-map --run O [--data D] [--out F] [--size WxH]\n"
    "                 [--color time|session] [--sessions T1,T2,...]\n"
    "  ratslam render template-graph --run O [--out F] [--size WxH] [--spans A-B:label,...]\n"
    "  ratslam render pose-cells --map F --out F [--config C]   (default: the map's own config)\n"
    "  ratslam render similarity --data D [--data D2 ...] [--config C] --out F [--frames N]\n"
    "                 [--sensor camera|wifi]\n"
    "  ratslam render wifi-map --wifi-map W --out F [--ap BSSID] [--floor N]\n"
    "      Images from a run folder, a saved map, or a data set (PNG).\n"
    "  ratslam evaluate [--config C] --map M --query Q --out O [--lenient] [--quiet]\n"
    "      FABMAP localisation benchmark: maps M, localises every node of Q, writes\n"
    "      evaluation.json, queries.csv and localisation.png to O. M and Q may be the same\n"
    "      data set: [evaluation] split and map_fraction then divide it.\n"
    "  ratslam wifi-map --data D [--data D2 ...] --out W [--config C] [--lenient]\n"
    "      Gaussian-process Wi-Fi maps (per AP, mean and variance grids) from data sets with\n"
    "      ground truth into the file W ([wifi_map] in C). With --run RUN_FOLDER (and --data\n"
    "      as that replay had it), positions come from the run's final map instead, in its\n"
    "      frame.\n"
    "  ratslam locate --wifi-map W --data PHONE_LOG --out O [--config C] [--lenient] [--quiet]\n"
    "      Locates a phone in W with a particle filter ([particle_filter], [pdr]): writes\n"
    "      trajectory_tum.txt, errors.csv and cumulative_error.png (with ground truth),\n"
    "      candidates.csv, summary.json.\n"
    "  ratslam call --map RUN_FOLDER|MAP_FILE --wifi-map W --data PHONE_LOG --at T --out O\n"
    "      Locates the phone up to time T and plans the robot's route from its current\n"
    "      experience through every candidate location: call.json, route.csv, call.png.\n"
    "  ratslam simulate --world NAME|FILE --out D [--seed S] [--quiet]\n"
    "      Simulates a world (built in: office, circular, day_night, aliased_floors,\n"
    "      apartment; or a world TOML file) into the replay data set D, with world.toml,\n"
    "      simulation.json and ground_truth.png.\n"
    "  ratslam sweep plan S --out DIR | run DIR [--jobs N] | task DIR [--index I] | collect DIR\n"
    "      Parameter sweeps (configs/README.md, \"Sweeps\"): plan a sweep file into DIR, run its\n"
    "      tasks as separate processes (resumable), run one task of a cluster array, collect.\n";

struct ReplayRequest {
  ReplaySessionOptions session;
  std::string out;
  bool quiet = false;
  bool render = false;         // write experience_map.png, template_graph.png, pose_cells.png
  uint64_t animate_every = 0;  // events between animation frames; 0: no animation
};

// Parses nothing and decides nothing: runs a replay session and reports what it did.
int RunReplay(const ReplayRequest& request) {
  auto fail = [](const Status& s) {
    std::cerr << "ratslam: " << s.message() << "\n";
    return kExitError;
  };
  StatusOr<std::unique_ptr<DiskFolder>> out = DiskFolder::Open(request.out);
  if (!out.ok()) return fail(out.status());
  ProgressPrinter progress(stderr, request.quiet);
  SessionEnvironment environment;
  environment.out = out->get();
  environment.progress = &progress;
  environment.stop_requested = &g_stop_requested;
  ReplaySession session(request.session, environment);
  // Ctrl-C stops the replay cleanly; the handler stays until the outputs and the map are saved,
  // so a second signal during the writes cannot lose them.
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  struct RestoreSignals {
    ~RestoreSignals() {
      std::signal(SIGINT, SIG_DFL);
      std::signal(SIGTERM, SIG_DFL);
    }
  } restore_signals;

  // Animation: a frame of the experience map every `animate_every` events.
  std::unique_ptr<SceneRenderer> animation_renderer;
  std::unique_ptr<AnimationWriter> animation;
  ReplayCheckpoint checkpoint;
  if (request.animate_every > 0) {
    StatusOr<std::unique_ptr<SceneRenderer>> renderer = CreateOsMesaRenderer();
    if (!renderer.ok()) return fail(renderer.status().WithContext("--animate"));
    animation_renderer = std::move(renderer.value());
    animation =
        std::make_unique<AnimationWriter>((fs::path(request.out) / "animation").string(), 10.0);
    checkpoint.every = request.animate_every;
    checkpoint.callback = [&](const ReplayPipeline& p) -> Status {
      ExperienceMapImageOptions options;
      options.width_px = 960;
      options.height_px = 720;
      char title[96];
      std::snprintf(title, sizeof title, "%s  t = %.1f s", session.dataset().name.c_str(),
                    p.state().trajectory.empty() ? 0.0 : p.state().trajectory.back().time_s);
      options.title = title;
      StatusOr<RgbaImage> frame = animation_renderer->Render(
          ExperienceMapScene(ExperienceMapDataOf(p.View(), session.dataset()), options));
      if (!frame.ok()) return frame.status();
      return animation->AddFrame(frame.value());
    };
  }
  if (Status loaded = session.Load(); !loaded.ok()) return fail(loaded);
  if (Status prepared = session.Prepare(); !prepared.ok()) return fail(prepared);
  (void)session.Replay(checkpoint);
  if (animation) {
    const bool video = animation->Close();
    std::cerr << "ratslam: wrote " << animation->frames() << " animation frames"
              << (video ? " and animation.avi" : " (no video writer available)") << " to "
              << (fs::path(request.out) / "animation").string() << "\n";
  }
  (void)session.WriteOutputs();
  (void)session.SaveMap();
  const ReplayResult& result = session.result();

  int exit_code = kExitOk;
  if (result.summary) std::cout << result.summary->json;
  if (!result.outputs.ok()) exit_code = fail(result.outputs);
  if (!result.save.ok()) exit_code = fail(result.save);
  if (request.render && result.outputs.ok()) {
    StatusOr<std::unique_ptr<SceneRenderer>> renderer = CreateOsMesaRenderer();
    Status rendered = renderer.ok() ? WriteRunImages(*renderer.value(), session.pipeline().View(),
                                                     session.dataset(), request.out)
                                    : renderer.status();
    if (rendered.ok() && session.pipeline().wifi_sequence().options().enabled) {
      rendered = WriteWifiSequenceImages(*renderer.value(), session.pipeline(), request.out);
    }
    if (!rendered.ok()) exit_code = fail(rendered.WithContext("images not written"));
  }
  if (!result.replay.ok()) {
    std::cerr << "ratslam: " << result.replay.message() << "\n";
    if (result.outputs.ok()) {
      std::cerr << "ratslam: outputs up to the last complete event are in " << request.out << "\n";
    }
    if (!result.saved_map.empty()) {
      std::cerr << "ratslam: the state is saved in " << result.saved_map << "\n";
    }
    return kExitError;
  }
  if (exit_code != kExitOk) return exit_code;
  if (result.interrupted) {
    std::cerr << "ratslam: interrupted; state saved in " << result.saved_map << "\n";
    return kExitInterrupted;
  }
  if (result.summary && result.summary->frames == 0) {
    std::cerr << "ratslam: the run processed no frame (no view for the front end to judge); "
                 "the outputs in "
              << request.out << " hold dead reckoning only\n";
    return kExitError;
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
  auto options = LoadOptions(*args, &request.session.config_path);
  if (!options) return kExitError;
  request.session.pipeline = *options;
  request.session.data = args->all["--data"];
  request.session.provenance = {ShellCommandLine(argc, argv), UtcNowIso8601()};
  request.session.lenient = args->lenient;
  request.out = args->values["--out"];
  request.session.save_map = args->values.count("--save-map") ? args->values["--save-map"] : "";
  request.session.load_map = args->values.count("--load-map") ? args->values["--load-map"] : "";
  if (args->values.count("--until")) {
    auto until = ParseNumber("--until", args->values["--until"]);
    if (!until) return kExitUsage;
    request.session.until_s = *until;
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
  request.session.pipeline = DemoPipelineOptions();
  request.session.config_path = "(built-in demo configuration, as configs/demo.toml)";
  request.session.data = {data};
  request.session.provenance = {ShellCommandLine(argc, argv), UtcNowIso8601()};
  request.out = out;
  request.quiet = args->quiet;
  request.render = true;
  return RunReplay(request);
}

int PrintConfigCommand(int argc, char** argv) {
  auto args = ParseArguments(argc, argv, 2, {"--config"});
  const bool locate = args && args->positional == std::vector<std::string>{"locate"};
  if (!args || (!args->positional.empty() && !locate)) {
    std::cerr << kUsage;
    return kExitUsage;
  }
  if (locate) {  // the configuration of wifi-map and locate
    LocateOptions o;
    if (args->values.count("--config")) {
      StatusOr<LocateOptions> loaded = LoadLocateConfigFile(args->values.at("--config"));
      if (!loaded.ok()) {
        std::cerr << "ratslam: " << loaded.status().message() << "\n";
        return kExitError;
      }
      o = *loaded;
    }
    std::cout << PrintLocateConfig(o);
    return kExitOk;
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
  if (command == "wifi-map") return WifiMapCommand(argc, argv);
  if (command == "locate") return LocateCommand(argc, argv);
  if (command == "call") return CallCommand(argc, argv);
  if (command == "simulate") return SimulateCommand(argc, argv);
  if (command == "sweep") return SweepCommand(argc, argv);
  if (command == "import") return ImportCommand(argc, argv);
  if (command == "--version" || command == "version") {
    std::cout << "ratslam " << RatslamVersion() << " (commit " << RatslamCommit() << ", "
              << RatslamBuildType() << " build)\n";
    return kExitOk;
  }
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
