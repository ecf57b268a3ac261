// Helpers for the end-to-end tests, which run the `ratslam` program (test_paths::RatslamBinary())
// as a user would and read what it wrote.
#ifndef RATSLAM_TESTS_RUN_RATSLAM_H_
#define RATSLAM_TESTS_RUN_RATSLAM_H_

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/test_paths.h"

namespace ratslam::e2e {

// The file's bytes; empty when it cannot be read.
inline std::string Slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// `toml` with `lines` added right after its "[section]" header line; empty when there is none.
inline std::string WithLinesInSection(std::string toml, const std::string& section,
                                      const std::string& lines) {
  const std::string header = "[" + section + "]\n";
  const size_t at = toml.find(header);
  if (at == std::string::npos) return {};
  return toml.insert(at + header.size(), lines);
}

struct Result {
  int exit_code;
  std::string err;  // what it printed on stderr
  std::string out;  // what it printed on stdout
};

// Runs `ratslam arguments` with stdout and stderr in files of `scratch`. With `limit_s`, the
// program is killed after that many seconds (exit code 124, as timeout(1) reports it): for tests
// of inputs that once made it wait for ever.
inline Result RunRatslam(const std::string& arguments, const std::filesystem::path& scratch,
                         int limit_s = 0) {
  const std::filesystem::path err = scratch / "stderr.txt", out = scratch / "stdout.txt";
  const std::string command =
      (limit_s > 0 ? "timeout -s KILL " + std::to_string(limit_s) + " " : std::string()) +
      std::string(ratslam::test_paths::RatslamBinary()) + " " + arguments + " > " + out.string() +
      " 2> " + err.string();
  const int status = std::system(command.c_str());
  return {WEXITSTATUS(status), Slurp(err), Slurp(out)};
}

}  // namespace ratslam::e2e

#endif  // RATSLAM_TESTS_RUN_RATSLAM_H_
