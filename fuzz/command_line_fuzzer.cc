// The `ratslam` command line (apps/command_line.h): the input is argv after the program name,
// words separated by NUL bytes. Whatever the words, parsing answers with a command the table
// knows (and its handler), or with exit 0 and text on `out` (help, version, completion), or with
// a usage error (exit 2) that says something on `err`; never a crash, and the same words give the
// same answer.
#include <algorithm>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "apps/cli.h"
#include "apps/command_line.h"
#include "fuzz/fuzz_support.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  auto words = [](std::vector<std::string> w) {
    std::string s;
    for (size_t i = 0; i < w.size(); ++i) s += (i ? std::string(1, '\0') : "") + w[i];
    return s;
  };
  return {words({"replay", "--data", "a", "--out", "o", "--until", "12.5", "--animate", "7"}),
          words({"synthesize", "--out", "d", "--seed", "9007199254740992", "--start-m", "-2.5e1"}),
          words({"render", "experience-map", "--run", "r", "--size", "640x480", "--sessions",
                 "30,0.5,-1", "--width-mm", "120"}),
          words({"route", "--map", "m", "--out", "o", "--to-xy", "-1.5,2e-1"}),
          words({"sweep", "run", "s", "--jobs", "2"}),
          words({"evaluate", "--config", "c.toml", "--map", "m", "--query", "q",
                 "--frame-tolerance", "1", "--format", "png,pdf"}),
          words({"replay", "--help"}),
          words({"--version"})};
}

}  // namespace ratslam::fuzz

namespace {

struct Answer {
  std::string command;  // empty unless parsed
  int code = -1;
  std::string out, err;
};

Answer Parse(const std::vector<std::string>& words) {
  std::vector<const char*> argv{"ratslam"};
  for (const std::string& w : words) argv.push_back(w.c_str());
  std::ostringstream out, err;
  const auto result =
      ratslam::apps::ParseCommandLine(static_cast<int>(argv.size()), argv.data(), out, err);
  Answer a;
  if (const auto* parsed = std::get_if<ratslam::apps::ParsedCommand>(&result)) {
    a.command = parsed->command;
    if (!parsed->handler) ratslam::fuzz::InvariantFailed("parsed command without a handler");
  } else {
    a.code = std::get<int>(result);
  }
  a.out = out.str();
  a.err = err.str();
  return a;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using ratslam::fuzz::InvariantFailed;
  if (size > 4096) return 0;  // a command line, not a file
  std::vector<std::string> words(1);
  for (size_t i = 0; i < size; ++i) {
    if (data[i] == 0) {
      words.emplace_back();
    } else {
      words.back().push_back(static_cast<char>(data[i]));
    }
  }
  if (size == 0) words.clear();
  const Answer a = Parse(words);
  if (!a.command.empty()) {
    const std::vector<std::string> paths = ratslam::apps::CommandPaths();
    if (std::find(paths.begin(), paths.end(), a.command) == paths.end()) {
      InvariantFailed("parsed a command the table does not have: " + a.command);
    }
  } else if (a.code == 0) {
    if (a.out.empty()) InvariantFailed("exit 0 without output");
  } else if (a.code == ratslam::apps::kExitUsage) {
    if (a.err.empty()) InvariantFailed("usage error without a message");
  } else {
    InvariantFailed("unexpected exit code " + std::to_string(a.code));
  }
  const Answer again = Parse(words);
  if (again.command != a.command || again.code != a.code || again.out != a.out ||
      again.err != a.err) {
    InvariantFailed("the same words gave another answer");
  }
  return 0;
}
