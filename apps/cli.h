// Small helpers shared by the `ratslam` sub-commands.
#ifndef RATSLAM_APPS_CLI_H_
#define RATSLAM_APPS_CLI_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fusion/io/config.h"

namespace ratslam {

inline constexpr int kExitOk = 0;
inline constexpr int kExitError = 1;
inline constexpr int kExitUsage = 2;
inline constexpr int kExitInternal = 70;  // a bug or an exhausted machine (EX_SOFTWARE)
inline constexpr int kExitInterrupted = 130;

// Parsed "--flag value" pairs and bare flags.
struct Arguments {
  std::map<std::string, std::string> values;            // the last value of each flag
  std::map<std::string, std::vector<std::string>> all;  // every value, for repeatable flags
  std::vector<std::string> positional;
  bool quiet = false;
  bool render = false;
  bool lenient = false;
};

inline std::optional<Arguments> ParseArguments(int argc, char** argv, int first,
                                               const std::vector<std::string>& flags_with_values) {
  Arguments args;
  for (int i = first; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quiet") {
      args.quiet = true;
    } else if (a == "--render") {
      args.render = true;
    } else if (a == "--lenient") {
      args.lenient = true;
    } else if (a.rfind("--", 0) == 0) {
      if (std::find(flags_with_values.begin(), flags_with_values.end(), a) ==
          flags_with_values.end()) {
        std::cerr << "ratslam: unknown option " << a << "\n";
        return std::nullopt;
      }
      if (i + 1 >= argc) {
        std::cerr << "ratslam: " << a << " needs a value\n";
        return std::nullopt;
      }
      args.values[a] = argv[++i];
      args.all[a].push_back(args.values[a]);
    } else {
      args.positional.push_back(a);
    }
  }
  return args;
}

inline std::optional<double> ParseNumber(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(value)) {
    std::cerr << "ratslam: " << flag << ": not a number: '" << text << "'\n";
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
    std::cerr << "ratslam: " << flag << ": expected a whole number in " << min << ".." << max
              << ", got '" << text << "'\n";
    return std::nullopt;
  }
  return static_cast<int64_t>(*value);
}

// The options of --config, or the defaults; prints the error and returns nullopt on a bad file.
// `path` (optional) receives the file name.
inline std::optional<PipelineOptions> LoadOptions(const Arguments& args,
                                                  std::string* path = nullptr) {
  auto it = args.values.find("--config");
  if (it == args.values.end()) return PipelineOptions();
  if (path) *path = it->second;
  StatusOr<PipelineOptions> options = LoadConfigFile(it->second);
  if (!options.ok()) {
    std::cerr << "ratslam: " << options.status().message() << "\n";
    return std::nullopt;
  }
  return options.value();
}

// `ratslam render ...` (render_command.cc).
int RenderCommand(int argc, char** argv);
int EvaluateCommand(int argc, char** argv);
int WifiMapCommand(int argc, char** argv);
int LocateCommand(int argc, char** argv);
int CallCommand(int argc, char** argv);
int SimulateCommand(int argc, char** argv);
int SweepCommand(int argc, char** argv);
// Simulates `world` into the replay data set `out` (with world.toml, simulation.json and
// ground_truth.png); `dataset` receives it.
namespace sim {
struct World;
}
Status SimulateWorld(const sim::World& world, uint64_t seed, const std::string& out, bool quiet,
                     Dataset* dataset);

}  // namespace ratslam

#endif  // RATSLAM_APPS_CLI_H_
