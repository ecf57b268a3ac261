#include "apps/command_line.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "common/toml_binder.h"
#include "common/version.h"

namespace ratslam::apps {
namespace {

// What an option's value must be.
enum class Kind {
  kText,     // any text (paths, names)
  kNumber,   // a finite decimal number
  kWhole,    // a whole number in [min, max]
  kSize,     // WIDTHxHEIGHT in pixels
  kPoint,    // X,Y: two finite numbers
  kNumbers,  // finite numbers, comma-separated
  kFlag,     // no value
};

struct OptionSpec {
  std::string name;        // "--out", or a positional's name ("FILE")
  std::string value_name;  // "O", shown in the usage
  std::string help;
  bool required = false;
  bool repeatable = false;  // may be given several times (--data D --data D2)
  Kind kind = Kind::kText;
  int64_t min = 0, max = 0;          // kWhole
  std::vector<std::string> choices;  // kText: the allowed values, when fixed
  bool list = false;                 // a comma-separated list of choices
};

struct CommandSpec {
  std::string path;  // "render pose-cells"
  std::string summary;
  std::string description;  // more than the summary, for --help; may be empty
  std::vector<OptionSpec> options;
  std::vector<OptionSpec> positionals;
  CommandHandler handler = nullptr;  // none for a group ("render") and for completion
  // --out is a folder written under an OutputGuard (common/output_guard.h); false: the command
  // writes --out itself (an image, a Wi-Fi map file, a sweep folder).
  bool guard_out = true;
};

constexpr int64_t kSeedMax = int64_t{1} << 53;  // exact in a double, as the map files keep it

OptionSpec Option(std::string name, std::string value_name, std::string help, Kind kind) {
  OptionSpec o;
  o.name = std::move(name);
  o.value_name = std::move(value_name);
  o.help = std::move(help);
  o.kind = kind;
  return o;
}
OptionSpec Flag(std::string name, std::string help) {
  return Option(std::move(name), "", std::move(help), Kind::kFlag);
}
OptionSpec Text(std::string name, std::string value_name, std::string help, bool required = false,
                bool repeatable = false) {
  OptionSpec o = Option(std::move(name), std::move(value_name), std::move(help), Kind::kText);
  o.required = required;
  o.repeatable = repeatable;
  return o;
}
OptionSpec Whole(std::string name, std::string value_name, std::string help, int64_t min,
                 int64_t max) {
  OptionSpec o = Option(std::move(name), std::move(value_name), std::move(help), Kind::kWhole);
  o.min = min;
  o.max = max;
  return o;
}
OptionSpec Number(std::string name, std::string value_name, std::string help,
                  bool required = false) {
  OptionSpec o = Option(std::move(name), std::move(value_name), std::move(help), Kind::kNumber);
  o.required = required;
  return o;
}
OptionSpec Choice(std::string name, std::string value_name, std::string help,
                  std::vector<std::string> choices) {
  OptionSpec o = Option(std::move(name), std::move(value_name), std::move(help), Kind::kText);
  o.choices = std::move(choices);
  return o;
}
OptionSpec Formats(std::string help =
                       "figure formats, comma-separated: png, pdf, svg "
                       "(default: the one --out's extension names)") {
  OptionSpec o = Option("--format", "LIST", std::move(help), Kind::kText);
  o.choices = {"png", "pdf", "svg"};
  o.repeatable = false;
  o.list = true;
  return o;
}
OptionSpec WidthMm(std::string help = "page width of PDF and SVG figures (default 88)") {
  OptionSpec o = Option("--width-mm", "MM", std::move(help), Kind::kNumber);
  o.min = 20;
  o.max = 2000;
  return o;
}
OptionSpec Point(std::string name, std::string help) {
  return Option(std::move(name), "X,Y", std::move(help), Kind::kPoint);
}
OptionSpec Numbers(std::string name, std::string value_name, std::string help) {
  return Option(std::move(name), std::move(value_name), std::move(help), Kind::kNumbers);
}
OptionSpec Size() {
  return Option("--size", "WxH", "image size in pixels (e.g. 1600x1200)", Kind::kSize);
}

const OptionSpec kQuiet = Flag("--quiet", "no progress on stderr and no summary on stdout");
const OptionSpec kJson = Flag("--json",
                              "print the JSON summary on stdout even on a terminal (the default "
                              "when stdout is not one; --quiet silences only the default)");
const OptionSpec kLenient =
    Flag("--lenient", "skip and count malformed lines of phone logs instead of failing");
const OptionSpec kOverwrite = Flag(
    "--overwrite", "replace an earlier run's outputs in the output folder (refused without it)");
const OptionSpec kConfig = Text("--config", "C", "configuration file (TOML); default: built in");

// The one table of commands.
const std::vector<CommandSpec>& Commands() {
  static const std::vector<CommandSpec> commands = {
      {"replay",
       "replay data sets into a map, a trajectory and a summary",
       "Replays data set D (a replay-format folder or a phone log; several --data make one "
       "multi-session run) and writes the map, trajectory and summary into O. Ctrl-C stops "
       "cleanly and saves the state.",
       {Text("--data", "D", "data set to replay; repeat for a multi-session run", true, true),
        Text("--out", "O", "output folder", true), kOverwrite, kConfig,
        Text("--save-map", "F", "save the whole state to F at the end"),
        Text("--load-map", "F", "resume from the state saved in F"),
        Flag("--localise",
             "localise on the map of --load-map without changing it (any data set; writes "
             "localisation.csv)"),
        Number("--lost-after", "M",
               "with --localise: lost when dead reckoning is M metres from the last recognised "
               "place (default 5)"),
        Number("--until", "T", "stop after data time T seconds"),
        Flag("--render", "also write the run's images (experience map, template graph, ...)"),
        Whole("--animate", "N", "write an experience-map frame every N events to O/animation/", 1,
              kSeedMax),
        Formats("formats of the --render images: png, pdf, svg, comma-separated (default png)"),
        WidthMm(), kLenient, kQuiet, kJson},
       {},
       ReplayCommand},
      {"import",
       "convert data sets (ROS bags, phone logs, ...) to the replay format",
       "Converts data sets to the replay format in folder F (one multi-session data set when "
       "--data is repeated), images included: a bag's images are stored as it holds them "
       "(JPEG stays JPEG; raw images become grey PNG). A bag's topics come from [bag] in the "
       "configuration.",
       {Text("--data", "D", "data set to convert; repeat to join sessions", true, true),
        Text("--out", "F", "output folder", true), kOverwrite, kConfig, kLenient, kQuiet},
       {},
       ImportCommand},
      {"demo",
       "simulate the built-in day_night world and replay it",
       "Simulates the built-in day_night world (camera, Wi-Fi, compass, odometry) into O/data, "
       "replays it into O with the fused front end and renders the images.",
       {Text("--out", "O", "output folder", true), kOverwrite, kQuiet, kJson},
       {},
       DemoCommand},
      {"print-config",
       "print the resolved configuration",
       "Prints the resolved configuration (the defaults when no file is given); with `locate`, "
       "that of wifi-map and locate.",
       {kConfig},
       {Choice("WHICH", "WHICH", "`locate` for the configuration of wifi-map and locate",
               {"locate"})},
       PrintConfigCommand},
      {"import-openratslam",
       "convert an OpenRatSLAM configuration file to ours",
       "Converts an OpenRatSLAM configuration file (INI) to ours; the TOML goes to stdout.",
       {},
       {Text("FILE", "FILE", "the OpenRatSLAM .ini or config.txt", true)},
       ImportOpenRatslamCommand},
      {"synthesize",
       "write the built-in synthetic camera loop",
       "Writes the built-in synthetic camera loop into D (replay it with "
       "configs/synthetic.toml).",
       {Text("--out", "D", "output folder", true), kOverwrite,
        Whole("--seed", "S", "random seed", 0, kSeedMax),
        Whole("--laps", "N", "laps of the loop", 1, 1000), kQuiet,
        Whole("--noise-seed", "S",
              "seed of the sensor noise alone (default: from --seed): another session of the "
              "same world",
              1, kSeedMax),
        Number("--start-m", "M", "start M metres along the loop (default 0)"),
        Text("--bag", "F",
             "also write the loop as a ROS 1 bag F (/synthetic/camera/image/compressed, "
             "/synthetic/odom, /synthetic/ground_truth)"),
        Text("--video", "F",
             "also write the loop as a Motion-JPEG video F (.avi) with OpenRatSLAM's odometry "
             "log beside it (F's name with .txt)")},
       {},
       SynthesizeCommand},
      {"render", "images from a run folder, a saved map, a data set or a Wi-Fi map", "", {}, {}},
      {"render experience-map",
       "the experience map of a run",
       "",
       {Text("--run", "O", "run folder (written by replay)", true),
        Text("--data", "D",
             "the run's data set for ground truth, repeated per session; default: the ones it "
             "read",
             false, true),
        Text("--out", "F", "image file; default: O/experience_map.png"), Size(),
        Choice("--color", "BY", "colour the experiences by time or by session",
               {"time", "session"}),
        Numbers("--sessions", "T1,T2,...", "session start times in seconds, comma-separated"),
        Formats(), WidthMm()},
       {},
       RenderExperienceMapCommand,
       false},
      {"render template-graph",
       "template ids over time, with labelled spans",
       "",
       {Text("--run", "O", "run folder (written by replay)", true),
        Text("--out", "F", "image file; default: O/template_graph.png"), Size(),
        Text("--spans", "A-B:label,...", "time spans to shade and label, comma-separated"),
        Formats(), WidthMm()},
       {},
       RenderTemplateGraphCommand,
       false},
      {"render pose-cells",
       "the pose-cell activity of a saved map",
       "Draws the pose-cell network of a saved map with the map's own configuration (maps of "
       "format 2 carry none and need --config).",
       {Text("--map", "F", "saved map (replay --save-map)", true),
        Text("--out", "F", "image file", true), kConfig, Formats(), WidthMm()},
       {},
       RenderPoseCellsCommand,
       false},
      {"render similarity",
       "the frame-by-frame similarity matrix of a data set",
       "",
       {Text("--data", "D", "data set; repeat for several sessions", true, true),
        Text("--out", "F", "image file", true), kConfig,
        Whole("--frames", "N", "frames to compare (evenly spaced)", 2, 5000),
        Choice("--sensor", "S", "the sensor to compare", {"camera", "wifi"}), Formats(), WidthMm()},
       {},
       RenderSimilarityCommand,
       false},
      {"render wifi-map",
       "one access point's Gaussian-process Wi-Fi map",
       "",
       {Text("--wifi-map", "W", "Wi-Fi map file (ratslam wifi-map)", true),
        Text("--out", "F", "image file", true),
        Text("--ap", "BSSID", "access point; default: the one with the largest grid"),
        Whole("--floor", "N", "floor; default: the AP's first", -1000, 1000), Formats(),
        WidthMm("page width of PDF and SVG figures (default 180: two panels)")},
       {},
       RenderWifiMapCommand,
       false},
      {"evaluate",
       "FABMAP localisation benchmark",
       "Maps M, localises every node of Q and writes evaluation.json, queries.csv, "
       "pr_curve.csv, localisation.png and pr_curve.png to O. M and Q may be the same data set: "
       "[evaluation] split and map_fraction then divide it. A data set is a replay folder, a "
       "phone log or a folder of them, a UJIIndoorLoc CSV, a long-term UJI library set (any of "
       "its files, e.g. db/01/trn01rss.csv) or an image folder. With --frame-tolerance, M and Q "
       "are image folders of two traverses of one route (e.g. summer and winter): every frame "
       "of Q is placed on M by the sequence matcher ([sequence]) and by single frames, right "
       "within N frames of its true place (same file name, else same position, else "
       "--ground-truth): evaluation.json, queries.csv, pr_curve.csv, pr_curve.png, "
       "difference_matrix.png. --map-descriptors and --query-descriptors add descriptors "
       "computed elsewhere, matched the same two ways beside the images; --fabmap adds visual "
       "FABMAP on single frames.",
       {kConfig, Text("--map", "M", "data set to map", true),
        Text("--query", "Q", "data set to localise", true),
        Whole("--frame-tolerance", "N",
              "image-sequence place recognition: right within N reference frames", 0, 1000000),
        Text("--ground-truth", "CSV",
             "with --frame-tolerance: query,reference file-name pairs (default: by name)"),
        Text("--map-descriptors", "F",
             "with --frame-tolerance: place descriptors of M's images (.npy or .csv, a row per "
             "image in file-name order), matched too; needs --query-descriptors"),
        Text("--query-descriptors", "F", "with --map-descriptors: those of Q's images"),
        Flag("--fabmap",
             "with --frame-tolerance: also place single frames by visual FABMAP ([visual_model], "
             "[visual_words], [vocabulary]; trained on M's images unless a model or training "
             "images are given)"),
        Text("--out", "O", "output folder", true), kOverwrite, kLenient, kQuiet, kJson,
        Formats("formats of the figures: png, pdf, svg, comma-separated (default png)"),
        WidthMm("page width of PDF and SVG figures (default 180: two panels)")},
       {},
       EvaluateCommand},
      {"wifi-map",
       "fit Gaussian-process Wi-Fi maps",
       "Fits a Gaussian process per access point (mean and variance grids, [wifi_map] in C) from "
       "data sets with ground truth into the file W. With --run, positions come from that run's "
       "final map instead (give --data as the replay had it).",
       {Text("--data", "D", "data set; repeat for several", true, true),
        Text("--out", "W", "Wi-Fi map file to write", true),
        Flag("--overwrite", "replace the file W if it exists (refused without it)"), kConfig,
        Text("--run", "RUN_FOLDER", "take positions from this run's map"), kLenient, kQuiet, kJson},
       {},
       WifiMapCommand,
       false},
      {"locate",
       "locate a phone in a Wi-Fi map with a particle filter",
       "Locates a phone in W with a particle filter ([particle_filter], [pdr]): writes "
       "trajectory_tum.txt, errors.csv and cumulative_error.png (with ground truth), "
       "candidates.csv and summary.json.",
       {Text("--wifi-map", "W", "Wi-Fi map file", true),
        Text("--data", "PHONE_LOG", "the phone's log", true),
        Text("--out", "O", "output folder", true), kOverwrite, kConfig, kLenient, kQuiet, kJson,
        Formats("formats of the figures: png, pdf, svg, comma-separated (default png)"),
        WidthMm("page width of PDF and SVG figures (default 180: two panels)")},
       {},
       LocateCommand},
      {"call",
       "locate a phone and plan the robot's route to it",
       "Locates the phone up to time T and plans the robot's route from its current experience "
       "through every candidate location: call.json, route.csv, call.png.",
       {Text("--map", "RUN", "run folder or saved map", true),
        Text("--wifi-map", "W", "Wi-Fi map file", true),
        Text("--data", "PHONE_LOG", "the phone's log", true),
        Number("--at", "T", "the time of the call, seconds of the phone's log", true),
        Text("--out", "O", "output folder", true), kOverwrite, kConfig, kLenient, kQuiet, kJson,
        Formats("formats of call's figure: png, pdf, svg, comma-separated (default png)"),
        WidthMm("page width of PDF and SVG figures (default 180: a two-column map)")},
       {},
       CallCommand},
      {"route",
       "the shortest path between two experiences of a map",
       "Prints the shortest path over the experience graph of RUN from experience --from (default: "
       "the map's current one) to --to, or to the reachable experience nearest the point --to-xy, "
       "with its length in metres; with --out also route.json, route.csv and route.png.",
       {Text("--map", "RUN", "run folder or saved map", true),
        Whole("--from", "E", "start experience (default: the map's current experience)", 0,
              int64_t{1} << 32),
        Whole("--to", "E", "end experience", 0, int64_t{1} << 32),
        Point("--to-xy", "end at the reachable experience nearest this point (metres)"),
        Text("--out", "O", "output folder"), kOverwrite, kQuiet, kJson,
        Formats("formats of route's figure: png, pdf, svg, comma-separated (default png)"),
        WidthMm()},
       {},
       RouteCommand},
      {"simulate",
       "simulate a world into a replay data set",
       "Simulates a world (built in: office, circular, day_night, aliased_floors, apartment; or "
       "a world TOML file) into the replay data set D, with world.toml, simulation.json and "
       "ground_truth.png.",
       {Text("--world", "NAME|FILE", "built-in world name or world file", true),
        Text("--out", "D", "output folder", true), kOverwrite,
        Whole("--seed", "S", "random seed", 0, kSeedMax), kQuiet},
       {},
       SimulateCommand},
      {"sweep", "parameter sweeps (configs/README.md, \"Sweeps\")", "", {}, {}},
      {"sweep plan",
       "expand a sweep file into a folder's task table",
       "",
       {Text("--out", "DIR", "sweep folder to create", true)},
       {Text("SWEEP", "SWEEP.toml", "sweep file", true)},
       SweepPlanCommand,
       false},
      {"sweep run",
       "run every pending task, N at a time (resumable)",
       "",
       {Whole("--jobs", "N", "tasks at a time", 1, 1024), kQuiet},
       {Text("DIR", "DIR", "sweep folder", true)},
       SweepRunCommand,
       false},
      {"sweep task",
       "run one task of a cluster array",
       "Runs one task (or a chunk of them). The index comes from --index, else from "
       "SLURM_ARRAY_TASK_ID, PBS_ARRAY_INDEX or SGE_TASK_ID.",
       {Whole("--index", "I", "array index", 0, int64_t{1} << 30),
        Whole("--chunk", "C", "tasks per array index", 1, int64_t{1} << 20)},
       {Text("DIR", "DIR", "sweep folder", true)},
       SweepTaskCommand,
       false},
      {"sweep collect",
       "collect results.csv/json, points.csv, best.toml and the plots",
       "",
       {Formats("formats of the plots: png, pdf, svg, comma-separated (default png)"), WidthMm()},
       {Text("DIR", "DIR", "sweep folder", true)},
       SweepCollectCommand,
       false},
      {"sweep submit",
       "submit a Slurm job array over the pending tasks",
       "Writes and submits a Slurm job array over the pending tasks (C tasks per element) and a "
       "collect job after it (afterany).",
       {Flag("--slurm", "submit to Slurm (the only scheduler supported)"),
        Text("--partition", "P", "Slurm partition"),
        Text("--time", "T", "time limit per array element"),
        Text("--mem", "M", "memory per array element"),
        Whole("--max-parallel", "K", "array elements at a time", 1, int64_t{1} << 20),
        Whole("--chunk", "C", "tasks per array element", 1, int64_t{1} << 20),
        Text("--sbatch-arg", "A", "extra sbatch argument; repeatable", false, true),
        Flag("--dry-run", "write and print the scripts without submitting")},
       {Text("DIR", "DIR", "sweep folder", true)},
       SweepSubmitCommand,
       false},
      {"completion",
       "print a bash completion script",
       "Prints a bash completion script for ratslam: `source <(ratslam completion)`.",
       {},
       {}},
  };
  return commands;
}

// `text` broken into lines of at most `width` characters at spaces.
std::string Wrap(const std::string& text, size_t width) {
  std::istringstream in(text);
  std::string word, line, out;
  while (in >> word) {
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      out += line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  return out + line;
}

CLI::Validator WholeValidator(int64_t min, int64_t max) {
  return CLI::Validator(
      [min, max](std::string& text) -> std::string {
        const std::string want =
            "expected a whole number in " + std::to_string(min) + ".." + std::to_string(max);
        char* end = nullptr;
        errno = 0;
        const long long value = std::strtoll(text.c_str(), &end, 10);
        if (text.empty() || *end != '\0' || errno == ERANGE || value < min || value > max) {
          return want + ", got '" + text + "'";
        }
        return "";
      },
      "");
}

// A finite number; within [min, max] unless min == max.
CLI::Validator NumberValidator(int64_t min, int64_t max) {
  return CLI::Validator(
      [min, max](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (text.empty() || *end != '\0' || !std::isfinite(value)) {
          return "expected a finite number, got '" + text + "'";
        }
        if (min != max && (value < static_cast<double>(min) || value > static_cast<double>(max))) {
          return "expected a number in " + std::to_string(min) + ".." + std::to_string(max) +
                 ", got '" + text + "'";
        }
        return "";
      },
      "");
}

CLI::Validator SizeValidator() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        int w = 0, h = 0;
        char x = 0;
        std::istringstream in(text);
        if (!(in >> w >> x >> h) || x != 'x' || !in.eof() || w < 64 || h < 64 || w > 16384 ||
            h > 16384) {
          return "expected WIDTHxHEIGHT with each side in 64..16384, got '" + text + "'";
        }
        return "";
      },
      "");
}

// `text` as finite numbers separated by commas: exactly `count` of them when count > 0, at least
// one otherwise; nothing when an item is not a finite number.
std::optional<std::vector<double>> FiniteNumbers(const std::string& text, size_t count) {
  std::vector<double> numbers;
  std::istringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(value)) return std::nullopt;
    numbers.push_back(value);
  }
  if (text.empty() || text.back() == ',' || numbers.empty() ||
      (count > 0 && numbers.size() != count)) {
    return std::nullopt;
  }
  return numbers;
}

CLI::Validator NumbersValidator(size_t count) {
  return CLI::Validator(
      [count](std::string& text) -> std::string {
        if (FiniteNumbers(text, count)) return "";
        return std::string(count == 2 ? "expected X,Y (two finite numbers)"
                                      : "expected finite numbers separated by commas") +
               ", got '" + text + "'";
      },
      "");
}

// One of `choices`, or with `list` a comma-separated list of distinct ones.
CLI::Validator ChoiceValidator(std::vector<std::string> choices, bool list) {
  return CLI::Validator(
      [choices, list](std::string& text) -> std::string {
        std::vector<std::string> items;
        if (list) {
          std::istringstream in(text);
          for (std::string item; std::getline(in, item, ',');) items.push_back(item);
          if (items.empty() || text.back() == ',') items.push_back("");
        } else {
          items.push_back(text);
        }
        std::set<std::string> seen;
        for (const std::string& item : items) {
          if (!seen.insert(item).second) return "'" + item + "' given twice";
          if (std::find(choices.begin(), choices.end(), item) != choices.end()) continue;
          std::string names;
          for (const std::string& c : choices) names += (names.empty() ? "" : ", ") + c;
          std::set<std::string> known(choices.begin(), choices.end());
          return "'" + item + "' is not one of " + names + schema::DidYouMean(item, known);
        }
        return "";
      },
      "");
}

struct Built {
  std::unique_ptr<CLI::App> app;
  std::map<std::string, CLI::App*> by_path;
};

void AddOption(CLI::App* sub, const OptionSpec& spec) {
  const bool positional = spec.name[0] != '-';
  if (spec.kind == Kind::kFlag) {
    // A yes/no flag takes no value, or exactly true or false: CLI11 alone turned
    // `--overwrite=no` and `--render=banana` on.
    sub->add_flag(spec.name, spec.help)
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
              if (text == "true" || text == "false") return "";
              return "takes no value, or true or false; not '" + text + "'";
            },
            ""));
    return;
  }
  CLI::Option* option = nullptr;
  if (spec.repeatable) {
    option = sub->add_option(spec.name, spec.help)
                 ->expected(1)
                 ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  } else {
    option = sub->add_option(spec.name, spec.help)->expected(1);
  }
  option->type_name(spec.value_name);
  if (spec.required) option->required();
  if (positional) option->type_name("");
  switch (spec.kind) {
    case Kind::kWhole:
      option->check(WholeValidator(spec.min, spec.max));
      break;
    case Kind::kNumber:
      option->check(NumberValidator(spec.min, spec.max));
      break;
    case Kind::kSize:
      option->check(SizeValidator());
      break;
    case Kind::kPoint:
      option->check(NumbersValidator(2));
      break;
    case Kind::kNumbers:
      option->check(NumbersValidator(0));
      break;
    default:
      if (!spec.choices.empty()) option->check(ChoiceValidator(spec.choices, spec.list));
      break;
  }
}

Built Build() {
  Built built;
  built.app = std::make_unique<CLI::App>(
      "Multi-sensor RatSLAM: replay data sets, render experience maps, sweep parameters.",
      "ratslam");
  CLI::App* app = built.app.get();
  app->require_subcommand(1);
  app->set_version_flag("--version", "ratslam " + RatslamVersion() + " (commit " + RatslamCommit() +
                                         ", " + RatslamBuildType() + " build)");
  for (const CommandSpec& c : Commands()) {
    CLI::App* parent = app;
    std::string leaf = c.path;
    if (const size_t space = c.path.rfind(' '); space != std::string::npos) {
      parent = built.by_path.at(c.path.substr(0, space));
      leaf = c.path.substr(space + 1);
    }
    CLI::App* sub = parent->add_subcommand(leaf, c.summary);
    if (!c.description.empty()) sub->footer(Wrap(c.description, 96));
    for (const OptionSpec& o : c.options) AddOption(sub, o);
    for (const OptionSpec& o : c.positionals) AddOption(sub, o);
    built.by_path[c.path] = sub;
  }
  for (auto& [path, sub] : built.by_path) {
    if (!sub->get_subcommands({}).empty()) sub->require_subcommand(1);
  }
  return built;
}

const CommandSpec& SpecOf(const std::string& path) {
  for (const CommandSpec& c : Commands()) {
    if (c.path == path) return c;
  }
  static const CommandSpec none;
  return none;
}

// The deepest sub-command that the parser entered (the top-level app when none).
std::pair<CLI::App*, std::string> Deepest(CLI::App* app) {
  CLI::App* at = app;
  std::string path;
  for (;;) {
    std::vector<CLI::App*> parsed = at->get_subcommands();
    if (parsed.empty()) break;
    at = parsed.front();
    path += (path.empty() ? "" : " ") + at->get_name();
  }
  return {at, path};
}

// The names a misspelling of `word` could have meant in `at`: its options and sub-commands.
std::string Suggest(const std::string& word, CLI::App* at) {
  std::set<std::string> known;
  if (word.rfind("-", 0) == 0) {
    for (const CLI::Option* o : at->get_options()) {
      for (const std::string& n : o->get_lnames()) known.insert("--" + n);
    }
  } else {
    for (const CLI::App* s : at->get_subcommands({})) known.insert(s->get_name());
  }
  const std::string bare = word.substr(0, word.find('='));
  return schema::DidYouMean(bare, known);
}

ParsedCommand Collect(CLI::App* at, const std::string& path) {
  ParsedCommand parsed;
  parsed.command = path;
  const CommandSpec& spec = SpecOf(path);
  parsed.handler = spec.handler;
  parsed.guard_out = spec.guard_out;
  for (const OptionSpec& o : spec.options) {
    const CLI::Option* option = at->get_option(o.name);
    if (option->count() == 0) continue;
    if (o.kind == Kind::kFlag) {
      if (option->results().back() == "false") continue;  // --flag=false: as if not given
      if (o.name == "--quiet") {
        parsed.args.quiet = true;
      } else if (o.name == "--render") {
        parsed.args.render = true;
      } else if (o.name == "--lenient") {
        parsed.args.lenient = true;
      } else {
        parsed.args.values[o.name] = "true";
      }
      continue;
    }
    for (const std::string& value : option->results()) {
      parsed.args.values[o.name] = value;
      parsed.args.all[o.name].push_back(value);
    }
    // The typed value, from the text the validators accepted (the last one given).
    const std::string& text = parsed.args.values[o.name];
    switch (o.kind) {
      case Kind::kNumber:
        parsed.args.numbers[o.name] = std::strtod(text.c_str(), nullptr);
        break;
      case Kind::kWhole:
        parsed.args.wholes[o.name] = std::strtoll(text.c_str(), nullptr, 10);
        break;
      case Kind::kSize: {
        ImageSize size;
        char x = 0;
        std::istringstream(text) >> size.width >> x >> size.height;
        parsed.args.sizes[o.name] = size;
        break;
      }
      case Kind::kPoint:
      case Kind::kNumbers:
        parsed.args.number_lists[o.name] =
            FiniteNumbers(text, o.kind == Kind::kPoint ? 2 : 0).value();
        break;
      default:
        break;
    }
  }
  for (const OptionSpec& o : spec.positionals) {
    const CLI::Option* option = at->get_option(o.name);
    for (const std::string& value : option->results()) parsed.args.positional.push_back(value);
  }
  return parsed;
}

std::string HelpOf(const Built& built, const std::string& path) {
  const size_t space = path.rfind(' ');
  const std::string parents = space == std::string::npos ? "" : " " + path.substr(0, space);
  return built.by_path.at(path)->help("ratslam" + parents);
}

}  // namespace

std::variant<ParsedCommand, int> ParseCommandLine(int argc, const char* const* argv,
                                                  std::ostream& out, std::ostream& err) {
  // `ratslam help [CMD ...]` is `ratslam [CMD ...] --help`.
  std::vector<std::string> words;
  for (int i = 1; i < argc; ++i) words.emplace_back(argv[i]);
  if (!words.empty() && words.front() == "help") {
    words.erase(words.begin());
    words.emplace_back("--help");
  }
  if (!words.empty() && words.front() == "version") words.front() = "--version";
  Built built = Build();
  CLI::App* app = built.app.get();
  try {
    std::vector<std::string> reversed(words.rbegin(), words.rend());
    app->parse(reversed);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) {
      // --help, --help-all, --version: CLI11 writes them.
      return app->exit(e, out, err);
    }
    auto [at, path] = Deepest(app);
    const std::string who = path.empty() ? "ratslam" : "ratslam " + path;
    std::string message = e.what();
    // An unknown word explains the other errors (a misspelt --data makes --data missing), so it
    // is reported first.
    const std::vector<std::string> extras = at->remaining();
    if (!extras.empty()) {
      const std::string& first = extras.front();
      if (first.rfind("-", 0) == 0) {
        message = "unknown option '" + first + "'" + Suggest(first, at);
      } else if (!at->get_subcommands({}).empty()) {
        message = "unknown command '" + first + "'" + Suggest(first, at);
      } else {
        message = "unexpected argument '" + first + "'";
      }
    } else if (dynamic_cast<const CLI::ArgumentMismatch*>(&e) != nullptr &&
               message.find("At Most 1 required") != std::string::npos) {
      message =
          message.substr(0, message.find(':')) + ": given more than once (it takes one value)";
    } else if (dynamic_cast<const CLI::ArgumentMismatch*>(&e) != nullptr &&
               message.find(" missing") != std::string::npos) {
      message = message.substr(0, message.find(':')) + ": needs a value";
    } else if (dynamic_cast<const CLI::RequiredError*>(&e) != nullptr &&
               !at->get_subcommands({}).empty() && at->get_subcommands().empty()) {
      std::string names;
      for (const CLI::App* s : at->get_subcommands({})) {
        names += (names.empty() ? "" : ", ") + s->get_name();
      }
      message = "a command is required: one of " + names;
    }
    err << who << ": " << message << "\n"
        << "Run '" << who << " --help' for the options.\n";
    return kExitUsage;
  }
  auto [at, path] = Deepest(app);
  if (path == "completion") {
    out << BashCompletion();
    return kExitOk;
  }
  return Collect(at, path);
}

CommandHandler HandlerOf(const std::string& path) { return SpecOf(path).handler; }

std::vector<std::string> CommandPaths() {
  std::vector<std::string> paths;
  for (const CommandSpec& c : Commands()) paths.push_back(c.path);
  return paths;
}

std::string CommandReference() {
  Built built = Build();
  std::ostringstream s;
  s << "```text\n" << built.app->help() << "```\n";
  for (const CommandSpec& c : Commands()) {
    if (c.options.empty() && c.positionals.empty() && c.path != "completion") continue;
    s << "\n```text\n" << HelpOf(built, c.path) << "```\n";
  }
  return s.str();
}

std::string BashCompletion() {
  // For each command path, its words: sub-commands, then options.
  std::ostringstream s;
  s << "# bash completion for ratslam (generated by `ratslam completion`)\n"
    << "_ratslam() {\n"
    << "  local cur=\"${COMP_WORDS[COMP_CWORD]}\" path=\"\" w i\n"
    << "  for ((i = 1; i < COMP_CWORD; i++)); do\n"
    << "    w=\"${COMP_WORDS[i]}\"\n"
    << "    case \"$w\" in -*) continue ;; esac\n"
    << "    case \"${path:+$path }$w\" in\n      ";
  std::string alternatives;
  for (const CommandSpec& c : Commands()) {
    alternatives += (alternatives.empty() ? "" : "|") + std::string("\"") + c.path + "\"";
  }
  s << alternatives << ") path=\"${path:+$path }$w\" ;;\n"
    << "    esac\n"
    << "  done\n"
    << "  local words=\"\"\n"
    << "  case \"$path\" in\n";
  std::map<std::string, std::string> words;
  words[""] = "--help --version";
  for (const CommandSpec& c : Commands()) {
    const size_t space = c.path.rfind(' ');
    const std::string parent = space == std::string::npos ? "" : c.path.substr(0, space);
    const std::string leaf = space == std::string::npos ? c.path : c.path.substr(space + 1);
    words[parent] += " " + leaf;
    std::string& mine = words[c.path];
    mine += "--help";
    for (const OptionSpec& o : c.options) mine += " " + o.name;
  }
  for (const auto& [path, list] : words) {
    s << "    \"" << path << "\") words=\"" << list << "\" ;;\n";
  }
  s << "  esac\n"
    << "  COMPREPLY=($(compgen -W \"$words\" -- \"$cur\"))\n"
    << "  case \"$cur\" in -*) ;; *) [[ ${#COMPREPLY[@]} -eq 0 ]] && COMPREPLY=($(compgen -f -- "
       "\"$cur\")) ;; esac\n"
    << "  return 0\n"
    << "}\n"
    << "complete -o filenames -F _ratslam ratslam\n";
  return s.str();
}

}  // namespace ratslam::apps
