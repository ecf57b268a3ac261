// Small helpers shared by the `ratslam` sub-commands.
#ifndef RATSLAM_APPS_CLI_H_
#define RATSLAM_APPS_CLI_H_

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/provenance.h"
#include "io/config.h"
#include "ratslam/experience_map.h"
#include "render/renderer.h"
#include "sim/world.h"
#include "viewer/figure_output.h"

namespace ratslam::apps {

inline constexpr int kExitOk = 0;
inline constexpr int kExitError = 1;
inline constexpr int kExitUsage = 2;
inline constexpr int kExitInternal = 70;  // a bug or an exhausted machine (EX_SOFTWARE)
inline constexpr int kExitInterrupted = 130;

// An image size from --size.
struct ImageSize {
  int width = 0, height = 0;
};

// A command's options after parsing (apps/command_line.h): "--flag value" pairs and bare flags,
// and the typed value of each option that is not text, read once by the parser that checked it.
struct Arguments {
  std::map<std::string, std::string> values;                // the last value of each flag
  std::map<std::string, std::vector<std::string>> all;      // every value, for repeatable flags
  std::map<std::string, double> numbers;                    // number options
  std::map<std::string, int64_t> wholes;                    // whole-number options, within range
  std::map<std::string, ImageSize> sizes;                   // WIDTHxHEIGHT options
  std::map<std::string, std::vector<double>> number_lists;  // X,Y points and number lists
  std::vector<std::string> positional;
  bool quiet = false;
  bool render = false;
  bool lenient = false;
  std::string command_line;  // as typed, for provenance
  // Under an OutputGuard, --out is the guard's staging folder and this is the folder the user
  // named, where the outputs appear at the end (see Shown).
  std::string output_folder;

  bool Has(const std::string& flag) const { return values.count(flag) > 0; }
  // Typed values of options given (see Has; the option's kind must match).
  double Number(const std::string& flag) const { return numbers.at(flag); }
  int64_t Whole(const std::string& flag) const { return wholes.at(flag); }
  // The value of `flag`, or "" when it was not given.
  std::string Value(const std::string& flag) const {
    auto it = values.find(flag);
    return it == values.end() ? std::string() : it->second;
  }
  // `path` as the user knows it: a path below the staging folder is named below --out's folder.
  std::string Shown(const std::string& path) const { return Provenance().Recorded(path); }
  // The command line and start time, and where the run writes, for the outputs' `run` block.
  RunProvenance Provenance() const {
    RunProvenance p;
    p.command_line = command_line;
    p.started_utc = UtcNowIso8601();
    if (!output_folder.empty()) {
      p.staging_folder = Value("--out");
      p.output_folder = output_folder;
    }
    return p;
  }
};

// SIGINT and SIGTERM while a command that writes into --out runs (ratslam_main.cc installs the
// handler with StopOnSignalsGuarded, stop_signals.cc). A command that stops cleanly calls
// StopCooperatively() and then polls StopFlag(); any other command ends at once with exit 130, and
// its output folder is as it was (its files were only staged).
std::atomic<bool>& StopFlag();
void StopCooperatively();

// "ratslam CMD: ", the one prefix of every message a command prints (main sets it once the
// command is known; usage errors use the same form).
inline std::string& MessagePrefix() {
  static std::string prefix = "ratslam: ";
  return prefix;
}

inline std::optional<double> ParseNumber(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(value)) {
    std::cerr << MessagePrefix() << flag << ": not a number: '" << text << "'\n";
    return std::nullopt;
  }
  return value;
}

// A whole number in [min, max] (written as digits, no fraction, no exponent overflow); prints why
// not and returns nullopt otherwise. Casting a double instead overflowed silently.
inline std::optional<int64_t> ParseInteger(const std::string& flag, const std::string& text,
                                           int64_t min, int64_t max) {
  const std::optional<double> value = ParseNumber(flag, text);
  if (!value) return std::nullopt;
  if (*value != std::floor(*value) || *value < static_cast<double>(min) ||
      *value > static_cast<double>(max)) {
    std::cerr << MessagePrefix() << flag << ": expected a whole number in " << min << ".." << max
              << ", got '" << text << "'\n";
    return std::nullopt;
  }
  return static_cast<int64_t>(*value);
}

// The options of --config, or the defaults; prints the error and returns nullopt on a bad file.
// `path` (optional) receives the file name.
inline std::optional<fusion::PipelineOptions> LoadOptions(const Arguments& args,
                                                          std::string* path = nullptr) {
  auto it = args.values.find("--config");
  if (it == args.values.end()) return fusion::PipelineOptions();
  if (path) *path = it->second;
  StatusOr<fusion::PipelineOptions> options = io::LoadConfigFile(it->second);
  if (!options.ok()) {
    std::cerr << MessagePrefix() << options.status().message() << "\n";
    return std::nullopt;
  }
  return options.value();
}

// --format and --width-mm of the figure commands: the formats asked for (none: the one the
// output's extension names) and the page width of vector figures.
struct FigureOptions {
  std::optional<std::vector<viewer::FigureFormat>> formats;
  double width_mm = render::kOneColumnMm;
};
inline StatusOr<FigureOptions> FigureOptionsOf(const Arguments& args) {
  FigureOptions o;
  if (auto it = args.values.find("--format"); it != args.values.end()) {
    StatusOr<std::vector<viewer::FigureFormat>> formats = viewer::ParseFigureFormats(it->second);
    if (!formats.ok()) return formats.status().WithContext("--format");
    o.formats = *formats;
  }
  if (args.Has("--width-mm")) o.width_mm = args.Number("--width-mm");
  return o;
}

// Where a command's figure goes: `path` and, with --format, the same stem in each format asked
// for; the vector page width (--width-mm, else `default_width_mm`: two-panel figures need two
// columns); a PNG renderer when a target is a PNG.
struct CommandFigure {
  std::vector<viewer::FigureTarget> targets;
  double width_mm = render::kOneColumnMm;
  std::unique_ptr<render::SceneRenderer> renderer;
};
inline StatusOr<CommandFigure> CommandFigureOf(const Arguments& args, const std::string& path,
                                               double default_width_mm) {
  StatusOr<FigureOptions> figure = FigureOptionsOf(args);
  if (!figure.ok()) return figure.status();
  CommandFigure c;
  c.width_mm = args.values.count("--width-mm") ? figure->width_mm : default_width_mm;
  c.targets = viewer::FigureTargets(path, figure->formats ? &*figure->formats : nullptr);
  StatusOr<std::unique_ptr<render::SceneRenderer>> renderer = viewer::RendererFor(c.targets);
  if (!renderer.ok()) return renderer.status();
  c.renderer = std::move(renderer.value());
  return c;
}

// Writes a command's figure (natural size, see WriteNaturalFigure) to CommandFigureOf's targets.
inline Status WriteCommandFigure(const Arguments& args, const std::string& png_path,
                                 const std::function<render::Scene(int width_px)>& build,
                                 double default_width_mm = render::kOneColumnMm) {
  StatusOr<CommandFigure> figure = CommandFigureOf(args, png_path, default_width_mm);
  if (!figure.ok()) return figure.status();
  return viewer::WriteNaturalFigure(figure->renderer.get(), build, figure->targets,
                                    figure->width_mm);
}

// Installs the handlers of SIGINT and SIGTERM: StopOnSignals sets StopFlag (a command that
// stops cleanly); StopOnSignalsGuarded, for a command under an OutputGuard, also ends one that
// does not poll it at once (exit 130), and any command at a second signal.
void StopOnSignals();
void StopOnSignalsGuarded();

// The commands: each runs with its parsed arguments and returns the exit code. The command
// table (command_line.cc) names each one's handler beside its options.
using CommandHandler = int (*)(const Arguments&);
int ReplayCommand(const Arguments& args);  // replay_command.cc
int DemoCommand(const Arguments& args);
int PrintConfigCommand(const Arguments& args);
int ImportOpenRatslamCommand(const Arguments& args);
int ImportCommand(const Arguments& args);
int SynthesizeCommand(const Arguments& args);
int EvaluateCommand(const Arguments& args);  // evaluate_command.cc
int WifiMapCommand(const Arguments& args);   // locate_command.cc
int LocateCommand(const Arguments& args);
int CallCommand(const Arguments& args);
int RouteCommand(const Arguments& args);                // route_command.cc
int SimulateCommand(const Arguments& args);             // simulate_command.cc
int RenderExperienceMapCommand(const Arguments& args);  // render_command.cc
int RenderTemplateGraphCommand(const Arguments& args);
int RenderPoseCellsCommand(const Arguments& args);
int RenderSimilarityCommand(const Arguments& args);
int RenderWifiMapCommand(const Arguments& args);
int SweepPlanCommand(const Arguments& args);  // sweep_command.cc
int SweepRunCommand(const Arguments& args);
int SweepTaskCommand(const Arguments& args);
int SweepCollectCommand(const Arguments& args);
int SweepSubmitCommand(const Arguments& args);
// Simulates `world` into the replay data set `out` (with world.toml, simulation.json and
// ground_truth.png); `dataset` receives it.
Status SimulateWorld(const sim::World& world, uint64_t seed, const std::string& out, bool quiet,
                     dataset::Dataset* dataset);

}  // namespace ratslam::apps

#endif  // RATSLAM_APPS_CLI_H_
