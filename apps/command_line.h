// The `ratslam` command line: every sub-command, its options and their types, parsed with CLI11.
// One table describes the commands; the parser, `--help`, docs/cli.md's command reference and
// the bash completion all come from it, so they cannot disagree.
#ifndef RATSLAM_APPS_COMMAND_LINE_H_
#define RATSLAM_APPS_COMMAND_LINE_H_

#include <ostream>
#include <string>
#include <variant>
#include <vector>

#include "apps/cli.h"

namespace ratslam::apps {

// A parsed command line: the command's path ("replay", "render pose-cells", "sweep run") and
// its arguments, already checked (required options present, numbers whole and in range, values
// among the allowed choices).
struct ParsedCommand {
  std::string command;
  Arguments args;
  CommandHandler handler = nullptr;  // the command's own (never null for a parsed command)
  bool guard_out = true;             // a given --out is a folder to write under an OutputGuard
};

// Parses `argv`. Returns the command, or an exit code once the parser has answered by itself:
// help and the version go to `out` (exit 0); a usage error goes to `err` with a "did you mean"
// for misspelt commands and options and the command's `--help` line (exit 2, kExitUsage).
std::variant<ParsedCommand, int> ParseCommandLine(int argc, const char* const* argv,
                                                  std::ostream& out, std::ostream& err);

// Every command path, in the order of the reference.
std::vector<std::string> CommandPaths();

// The handler the table names for `path`: null for a group ("render", "sweep") and for
// `completion`, which the parser answers itself.
CommandHandler HandlerOf(const std::string& path);

// docs/cli.md's command reference: each command's `--help`, in Markdown.
std::string CommandReference();

// A bash completion script for `ratslam` (commands and options): `source <(ratslam
// completion)`.
std::string BashCompletion();

}  // namespace ratslam::apps

#endif  // RATSLAM_APPS_COMMAND_LINE_H_
