#include "apps/command_line.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/version.h"
#include "tests/generated_block.h"

namespace ratslam::apps {
namespace {

struct Outcome {
  std::variant<ParsedCommand, int> result;
  std::string out, err;
  int code() const { return std::holds_alternative<int>(result) ? std::get<int>(result) : -1; }
  const ParsedCommand& command() const { return std::get<ParsedCommand>(result); }
};

// Splits `line` at spaces (no quoting needed here) and parses it as `ratslam line`.
Outcome Parse(const std::string& line) {
  std::vector<std::string> words{"ratslam"};
  std::istringstream in(line);
  for (std::string w; in >> w;) words.push_back(w);
  std::vector<const char*> argv;
  for (const std::string& w : words) argv.push_back(w.c_str());
  std::ostringstream out, err;
  Outcome o{ParseCommandLine(static_cast<int>(argv.size()), argv.data(), out, err), "", ""};
  o.out = out.str();
  o.err = err.str();
  return o;
}

TEST(CommandLineTest, EveryCommandHasHelpWithBothSpellings) {
  for (const std::string& path : CommandPaths()) {
    for (const char* flag : {"--help", "-h"}) {
      const Outcome o = Parse(path + " " + flag);
      EXPECT_EQ(o.code(), kExitOk) << path << " " << flag << ": " << o.err;
      EXPECT_NE(o.out.find("Usage: ratslam " + path), std::string::npos) << path << "\n" << o.out;
      EXPECT_TRUE(o.err.empty()) << o.err;
    }
    const Outcome help = Parse("help " + path);
    EXPECT_EQ(help.code(), kExitOk) << path;
    EXPECT_NE(help.out.find("Usage: ratslam " + path), std::string::npos) << path;
  }
}

// One table names each command's handler: every command that runs has one, no two share one
// (a copied line would run the wrong command), and a parsed command carries its own.
TEST(CommandLineTest, EveryCommandHasItsOwnHandler) {
  std::set<CommandHandler> seen;
  for (const std::string& path : CommandPaths()) {
    const bool group = path == "render" || path == "sweep";
    if (group || path == "completion") {
      EXPECT_EQ(HandlerOf(path), nullptr) << path;
      continue;
    }
    ASSERT_NE(HandlerOf(path), nullptr) << path;
    EXPECT_TRUE(seen.insert(HandlerOf(path)).second) << path << " shares a handler";
  }
  EXPECT_EQ(seen.size(), 22u);
  const Outcome o = Parse("render pose-cells --map m --out o.png");
  ASSERT_EQ(o.code(), -1) << o.err;
  EXPECT_EQ(o.command().handler, HandlerOf("render pose-cells"));
  EXPECT_FALSE(o.command().guard_out);  // an image file
  EXPECT_FALSE(Parse("wifi-map --data d --out w.bin").command().guard_out);
  EXPECT_TRUE(Parse("replay --data d --out o").command().guard_out);
}

TEST(CommandLineTest, HelpIsNotTakenForAFileName) {
  // Before CLI11, `import-openratslam -h` tried to open a file named "-h".
  const Outcome o = Parse("import-openratslam -h");
  EXPECT_EQ(o.code(), kExitOk);
  EXPECT_NE(o.out.find("FILE"), std::string::npos);
}

TEST(CommandLineTest, VersionNamesVersionCommitAndBuildType) {
  for (const char* line : {"--version", "version"}) {
    const Outcome o = Parse(line);
    EXPECT_EQ(o.code(), kExitOk);
    EXPECT_NE(o.out.find("ratslam " + RatslamVersion()), std::string::npos) << o.out;
    EXPECT_NE(o.out.find(RatslamCommit()), std::string::npos) << o.out;
    EXPECT_NE(o.out.find(RatslamBuildType()), std::string::npos) << o.out;
  }
}

TEST(CommandLineTest, NoCommandIsAUsageErrorListingTheCommands) {
  const Outcome o = Parse("");
  EXPECT_EQ(o.code(), kExitUsage);
  EXPECT_NE(o.err.find("one of replay, import"), std::string::npos) << o.err;
}

TEST(CommandLineTest, ValuesBothSpellingsAndRepeatedOptions) {
  const Outcome o = Parse("replay --data=a --data b --out=o --until 12.5 --render --quiet");
  ASSERT_EQ(o.code(), -1) << o.err;
  const ParsedCommand& c = o.command();
  EXPECT_EQ(c.command, "replay");
  EXPECT_EQ(c.args.all.at("--data"), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(c.args.values.at("--out"), "o");
  EXPECT_EQ(c.args.values.at("--until"), "12.5");
  EXPECT_TRUE(c.args.render);
  EXPECT_TRUE(c.args.quiet);
  EXPECT_FALSE(c.args.lenient);
  EXPECT_EQ(c.args.Value("--config"), "");
}

TEST(CommandLineTest, NestedCommandsPositionalsAndOtherFlags) {
  const Outcome o = Parse("sweep submit DIR --slurm --chunk 4 --sbatch-arg=-A --sbatch-arg x");
  ASSERT_EQ(o.code(), -1) << o.err;
  EXPECT_EQ(o.command().command, "sweep submit");
  EXPECT_EQ(o.command().args.positional, std::vector<std::string>{"DIR"});
  EXPECT_EQ(o.command().args.values.count("--slurm"), 1u);
  EXPECT_EQ(o.command().args.values.count("--dry-run"), 0u);
  EXPECT_EQ(o.command().args.all.at("--sbatch-arg"), (std::vector<std::string>{"-A", "x"}));
  // A yes/no flag with an explicit value: true is the flag, false is its absence.
  const Outcome on = Parse("replay --data a --out o --overwrite=true --render=true --quiet=false");
  ASSERT_EQ(on.code(), -1) << on.err;
  EXPECT_EQ(on.command().args.values.count("--overwrite"), 1u);
  EXPECT_TRUE(on.command().args.render);
  EXPECT_FALSE(on.command().args.quiet);
  const Outcome off = Parse("replay --data a --out o --overwrite=false --render=false");
  ASSERT_EQ(off.code(), -1) << off.err;
  EXPECT_EQ(off.command().args.values.count("--overwrite"), 0u);
  EXPECT_FALSE(off.command().args.render);
  const Outcome p = Parse("print-config locate");
  ASSERT_EQ(p.code(), -1) << p.err;
  EXPECT_EQ(p.command().args.positional, std::vector<std::string>{"locate"});
}

// The parser hands commands typed values, read from the text it checked: numbers, whole numbers,
// sizes, points and number lists, each the last one given.
TEST(CommandLineTest, ValuesArriveTyped) {
  const Outcome replay = Parse("replay --data a --out o --until 12.5 --animate 7");
  ASSERT_EQ(replay.code(), -1) << replay.err;
  EXPECT_EQ(replay.command().args.Number("--until"), 12.5);
  EXPECT_EQ(replay.command().args.Whole("--animate"), 7);
  EXPECT_FALSE(replay.command().args.Has("--lost-after"));
  const Outcome seed = Parse("synthesize --out d --seed 9007199254740992 --start-m -2.5e1");
  ASSERT_EQ(seed.code(), -1) << seed.err;
  EXPECT_EQ(seed.command().args.Whole("--seed"), int64_t{1} << 53);
  EXPECT_EQ(seed.command().args.Number("--start-m"), -25.0);
  const Outcome render =
      Parse("render experience-map --run r --size 640x480 --sessions 30,0.5,-1 --width-mm 120");
  ASSERT_EQ(render.code(), -1) << render.err;
  EXPECT_EQ(render.command().args.sizes.at("--size").width, 640);
  EXPECT_EQ(render.command().args.sizes.at("--size").height, 480);
  EXPECT_EQ(render.command().args.number_lists.at("--sessions"),
            (std::vector<double>{30, 0.5, -1}));
  EXPECT_EQ(render.command().args.Number("--width-mm"), 120.0);
  const Outcome route = Parse("route --map m --out o --to-xy -1.5,2e-1");
  ASSERT_EQ(route.code(), -1) << route.err;
  EXPECT_EQ(route.command().args.number_lists.at("--to-xy"), (std::vector<double>{-1.5, 0.2}));
}

// Each bad line, and a piece of the message it must give; all are usage errors (exit 2).
TEST(CommandLineTest, UsageErrorsSayWhatIsWrong) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"synthesize --out d --seed -1", "--seed: expected a whole number in 0..9007199254740992"},
      {"synthesize --out d --seed 1.5", "got '1.5'"},
      {"synthesize --out d --seed 1e3", "got '1e3'"},
      {"synthesize --out d --laps 0", "--laps: expected a whole number in 1..1000"},
      {"synthesize --out d --seed 99999999999999999999", "--seed: expected a whole number"},
      {"replay --data a --out o --until soon", "--until: expected a finite number, got 'soon'"},
      {"replay --data a --out o --until nan", "--until: expected a finite number"},
      {"call --map m --wifi-map w --data d --out o --at inf", "--at: expected a finite number"},
      {"render experience-map --run r --size 100", "--size: expected WIDTHxHEIGHT"},
      {"render experience-map --run r --size 32x32", "--size: expected WIDTHxHEIGHT"},
      {"render experience-map --run r --color sesion", "(did you mean 'session'?)"},
      {"render experience-map --run r --sessions 0,x", "--sessions: expected finite numbers"},
      {"render experience-map --run r --sessions 1,", "--sessions: expected finite numbers"},
      {"route --map m --out o --to-xy 3", "--to-xy: expected X,Y (two finite numbers), got '3'"},
      {"route --map m --out o --to-xy 1,2,3", "--to-xy: expected X,Y"},
      {"route --map m --out o --to-xy 1,inf", "--to-xy: expected X,Y"},
      {"print-config --render", "ratslam print-config: unknown option '--render'"},
      {"print-config --quiet", "unknown option '--quiet'"},
      {"replay --dta x --out y", "unknown option '--dta' (did you mean '--data'?)"},
      {"replay --data x --out y --outt z", "(did you mean '--out'?)"},
      {"replya --data x", "unknown command 'replya' (did you mean 'replay'?)"},
      {"render pose-cell --map m --out o",
       "unknown command 'pose-cell' (did you mean "
       "'pose-cells'?)"},
      {"render", "a command is required: one of experience-map"},
      {"replay --out o", "--data is required"},
      {"replay --data a b --out o", "unexpected argument 'b'"},
      {"replay --data a --out o --out p", "--out: given more than once"},
      {"replay --data a --out", "--out: needs a value"},
      {"print-config other", "'other' is not one of locate"},
      {"sweep run", "DIR is required"},
      {"import-openratslam a.ini b.ini", "unexpected argument 'b.ini'"},
      {"replay --data a --out o --overwrite=no", "takes no value, or true or false; not 'no'"},
      {"replay --data a --out o --render=no", "not 'no'"},
      {"replay --data a --out o --render=banana", "not 'banana'"},
      {"replay --data a --out o --render=1", "not '1'"},
      {"replay --data a --out o --quiet=yes", "not 'yes'"},
  };
  for (const auto& [line, expected] : cases) {
    const Outcome o = Parse(line);
    EXPECT_EQ(o.code(), kExitUsage) << line;
    EXPECT_NE(o.err.find(expected), std::string::npos) << line << "\n" << o.err;
    EXPECT_NE(o.err.find("--help' for the options"), std::string::npos) << line << "\n" << o.err;
    EXPECT_TRUE(o.out.empty()) << line;
  }
}

TEST(CommandLineTest, TheLimitsOfARangeAreAccepted) {
  for (const char* line :
       {"synthesize --out d --seed 0", "synthesize --out d --seed 9007199254740992",
        "synthesize --out d --laps 1000",
        "render similarity --data d --out f "
        "--frames 2",
        "render wifi-map --wifi-map w --out f --floor -1000",
        "render experience-map --run r --size 64x16384"}) {
    const Outcome o = Parse(line);
    EXPECT_EQ(o.code(), -1) << line << "\n" << o.err;
  }
}

// docs/cli.md's command reference is this program's help, so the two cannot drift apart.
TEST(CommandLineTest, ReadmeCarriesTheCurrentCommandReference) {
  e2e::ExpectGeneratedBlock("docs/cli.md", "command reference", CommandReference());
}

// The completion script is valid bash and completes commands, sub-commands and options.
TEST(CommandLineTest, BashCompletionCompletes) {
  const std::filesystem::path script =
      std::filesystem::temp_directory_path() / "ratslam_completion_test.bash";
  {
    std::ofstream out(script);
    out << BashCompletion();
  }
  auto complete = [&](const std::string& words) {
    const std::filesystem::path result = script.string() + ".out";
    const std::string command = "bash -c 'source " + script.string() + " && COMP_WORDS=(" + words +
                                ") && COMP_CWORD=$((${#COMP_WORDS[@]} - 1)) && _ratslam && echo "
                                "\"${COMPREPLY[*]}\"' > " +
                                result.string() + " 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
    std::ifstream in(result);
    std::string line;
    std::getline(in, line);
    return line;
  };
  EXPECT_EQ(complete("ratslam rep"), "replay");
  EXPECT_EQ(complete("ratslam render pose"), "pose-cells");
  EXPECT_EQ(complete("ratslam replay --data x --loa"), "--load-map");
  EXPECT_EQ(complete("ratslam replay --data x --lo"), "--load-map --localise --lost-after");
  EXPECT_EQ(complete("ratslam sweep submit DIR --sl"), "--slurm");
  EXPECT_EQ(complete("ratslam print-config --"), "--help --config");
  std::filesystem::remove(script);
}

}  // namespace
}  // namespace ratslam::apps
