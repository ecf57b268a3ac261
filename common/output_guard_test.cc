#include "common/output_guard.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "common/file_util.h"
#include "common/scratch_dir.h"

namespace ratslam {
namespace {

namespace fs = std::filesystem;

void Put(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

std::string Read(const fs::path& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::set<std::string> Files(const fs::path& folder) {
  std::set<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    if (e.path().filename() == OutputGuard::kLockName) continue;
    if (e.is_regular_file()) files.insert(e.path().lexically_relative(folder).generic_string());
  }
  return files;
}

class OutputGuardTest : public ::testing::Test {
 protected:
  ScratchDir scratch_{"output_guard"};
  fs::path out_ = scratch_.path() / "out";

  // A "run" that writes `names` (through OutputGuard) and reports `ok`; returns the files
  // removed.
  StatusOr<std::vector<std::string>> Run(const std::vector<std::string>& names, bool overwrite,
                                         bool ok = true,
                                         const std::vector<std::string>& inputs = {}) {
    StatusOr<OutputGuard> guard = OutputGuard::Begin(out_.string(), overwrite, inputs);
    if (!guard.ok()) return guard.status();
    for (const std::string& n : names) Put(fs::path(guard->staging()) / n, "new " + n);
    StatusOr<OutputGuard::Report> report =
        guard->Finish(ok ? OutputGuard::Outcome::kSucceeded : OutputGuard::Outcome::kFailed);
    if (!report.ok()) return report.status();
    return report->removed;
  }
};

TEST_F(OutputGuardTest, AFreshOrForeignFolderIsUsedAndTheListNamesWhatTheRunWrote) {
  Put(out_ / "notes.txt", "the user's own file");
  ASSERT_TRUE(Run({"summary.json", "a.csv", "animation/f1.png"}, false).ok());
  EXPECT_EQ(Read(out_ / "notes.txt"), "the user's own file");
  const std::string list = Read(out_ / OutputGuard::kListName);
  EXPECT_NE(list.find("\nsummary.json\n"), std::string::npos) << list;
  EXPECT_NE(list.find("\nanimation/f1.png\n"), std::string::npos) << list;
  EXPECT_EQ(list.find("notes.txt"), std::string::npos) << list;
}

TEST_F(OutputGuardTest, AnEarlierRunIsRefusedWithoutOverwrite) {
  ASSERT_TRUE(Run({"summary.json", "a.csv"}, false).ok());
  StatusOr<std::vector<std::string>> again = Run({"summary.json"}, false);
  ASSERT_FALSE(again.ok());
  EXPECT_NE(again.status().message().find("holds the outputs of an earlier run"),
            std::string::npos);
  EXPECT_NE(again.status().message().find("--overwrite"), std::string::npos);
  // A folder from before the list existed is recognised by the files only runs write.
  fs::remove(out_ / OutputGuard::kListName);
  again = Run({"x"}, false);
  ASSERT_FALSE(again.ok());
  EXPECT_NE(again.status().message().find("(summary.json)"), std::string::npos)
      << again.status().message();
}

TEST_F(OutputGuardTest, OverwriteLeavesExactlyTheNewRunsFilesAndTheUsersOwn) {
  Put(out_ / "notes.txt", "mine");
  ASSERT_TRUE(
      Run({"summary.json", "a.csv", "old.png", "animation/f1.png", "animation/f2.png"}, false)
          .ok());
  StatusOr<std::vector<std::string>> removed = Run({"summary.json", "a.csv"}, true);
  ASSERT_TRUE(removed.ok()) << removed.status().message();
  EXPECT_EQ(std::set<std::string>(removed->begin(), removed->end()),
            (std::set<std::string>{"old.png", "animation/f1.png", "animation/f2.png"}));
  EXPECT_EQ(Files(out_),
            (std::set<std::string>{"summary.json", "a.csv", "notes.txt", OutputGuard::kListName}));
  EXPECT_FALSE(fs::exists(out_ / "animation"));  // emptied by the removal
  EXPECT_EQ(Read(out_ / "a.csv"), "new a.csv");
}

TEST_F(OutputGuardTest, AFailedRunChangesNothingAndKeepsItsFilesAside) {
  ASSERT_TRUE(Run({"summary.json", "old.png", "config.toml"}, false).ok());
  ASSERT_TRUE(Run({"summary.json", "config.toml"}, true, /*ok=*/false).ok());
  // The earlier run's files are all as they were, the failed run's beside them.
  EXPECT_EQ(Read(out_ / "summary.json"), "new summary.json");
  EXPECT_EQ(Read(out_ / "config.toml"), "new config.toml");
  EXPECT_TRUE(fs::exists(out_ / "old.png"));
  EXPECT_TRUE(fs::exists(out_ / OutputGuard::kIncompleteName / "config.toml"));
  // A retry is not blocked by the failed run, and its success clears the aside folder.
  Put(out_ / "summary.json", "still the first run's");
  ASSERT_TRUE(Run({"summary.json"}, true).ok());
  EXPECT_FALSE(fs::exists(out_ / "old.png"));
  EXPECT_FALSE(fs::exists(out_ / OutputGuard::kIncompleteName));
  EXPECT_EQ(Read(out_ / "summary.json"), "new summary.json");
}

TEST_F(OutputGuardTest, TheRunWritesOnlyIntoItsStagingFolderUntilItEnds) {
  ASSERT_TRUE(Run({"summary.json", "a.csv"}, false).ok());
  StatusOr<OutputGuard> guard = OutputGuard::Begin(out_.string(), true, {});
  ASSERT_TRUE(guard.ok()) << guard.status().message();
  Put(fs::path(guard->staging()) / "summary.json", "second");
  // Before Finish the folder still holds the first run's outputs only.
  EXPECT_EQ(Read(out_ / "summary.json"), "new summary.json");
  EXPECT_TRUE(fs::exists(out_ / "a.csv"));
  ASSERT_TRUE(guard->Finish(OutputGuard::Outcome::kSucceeded).ok());
  EXPECT_EQ(Read(out_ / "summary.json"), "second");
  EXPECT_FALSE(fs::exists(out_ / "a.csv"));
  EXPECT_FALSE(fs::exists(out_ / OutputGuard::kStagingName));
  EXPECT_FALSE(fs::exists(out_ / OutputGuard::kJournalName));
}

TEST_F(OutputGuardTest, ASecondRunIntoALockedFolderFailsAtOnceNamingTheFirst) {
  StatusOr<OutputGuard> first = OutputGuard::Begin(out_.string(), false, {}, "ratslam replay A");
  ASSERT_TRUE(first.ok()) << first.status().message();
  // flock locks belong to the open file: another process is refused, as a second run would be.
  const pid_t child = ::fork();
  if (child == 0) {
    StatusOr<OutputGuard> second = OutputGuard::Begin(out_.string(), true, {}, "B");
    const bool named =
        !second.ok() &&
        second.status().message().find("in use by another ratslam run") != std::string::npos &&
        second.status().message().find("ratslam replay A") != std::string::npos &&
        second.status().message().find("pid ") != std::string::npos;
    ::_exit(named ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  Put(fs::path(first->staging()) / "summary.json", "A");
  ASSERT_TRUE(first->Finish(OutputGuard::Outcome::kSucceeded).ok());
  // Released at Finish: the next run (with --overwrite) gets the folder.
  EXPECT_TRUE(Run({"summary.json"}, true).ok());
}

TEST_F(OutputGuardTest, ACommitStoppedHalfWayIsCompletedByTheNextGuardAndByReaders) {
  ASSERT_TRUE(Run({"summary.json", "a.csv", "old.png"}, false).ok());
  // What a run killed between two of its moves leaves: the journal, one file moved, one not.
  const fs::path staging = out_ / OutputGuard::kStagingName;
  Put(staging / "a.csv", "second a.csv");
  Put(out_ / "summary.json", "second summary.json");
  Put(out_ / OutputGuard::kJournalName,
      "# journal\nmove summary.json\nmove a.csv\nremove old.png\n");
  ASSERT_TRUE(RecoverOutputFolder(out_.string()).ok());
  EXPECT_EQ(Read(out_ / "a.csv"), "second a.csv");
  EXPECT_EQ(Read(out_ / "summary.json"), "second summary.json");
  EXPECT_FALSE(fs::exists(out_ / "old.png"));
  EXPECT_FALSE(fs::exists(staging));
  EXPECT_FALSE(fs::exists(out_ / OutputGuard::kJournalName));
  // A journal that points outside the folder is refused, and nothing is touched.
  Put(scratch_.path() / "precious.txt", "keep");
  Put(out_ / OutputGuard::kJournalName, "remove ../precious.txt\n");
  const Status refused = RecoverOutputFolder(out_.string());
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find(std::string(OutputGuard::kJournalName) + ":1:"),
            std::string::npos)
      << refused.message();
  EXPECT_FALSE(OutputGuard::Begin(out_.string(), true, {}).ok());
  EXPECT_EQ(Read(scratch_.path() / "precious.txt"), "keep");
}

TEST_F(OutputGuardTest, AKilledRunsStagingFolderIsDroppedAndTheEarlierOutputsStay) {
  ASSERT_TRUE(Run({"summary.json"}, false).ok());
  Put(out_ / OutputGuard::kStagingName / "summary.json", "half");
  StatusOr<OutputGuard> guard = OutputGuard::Begin(out_.string(), true, {});
  ASSERT_TRUE(guard.ok());
  EXPECT_FALSE(fs::exists(fs::path(guard->staging()) / "summary.json"));
  EXPECT_EQ(Read(out_ / "summary.json"), "new summary.json");
}

TEST_F(OutputGuardTest, AnOutputNamedByItsOwnFlagIsNotReplacedWithoutOverwrite) {
  Put(scratch_.path() / "map.bin", "the user's map");
  const std::string map = (scratch_.path() / "map.bin").string();
  const Status refused = CheckReplaceable(map, false, "--save-map");
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("--save-map " + map + ": the file exists"), std::string::npos)
      << refused.message();
  EXPECT_TRUE(CheckReplaceable(map, true, "--save-map").ok());
  EXPECT_TRUE(CheckReplaceable((scratch_.path() / "new.bin").string(), false, "--save-map").ok());
  EXPECT_TRUE(CheckReplaceable("", false, "--save-map").ok());
}

TEST_F(OutputGuardTest, OutputsInsideTheFolderNamedByTheirOwnFlagGoToStagingToo) {
  StatusOr<OutputGuard> guard = OutputGuard::Begin(out_.string(), false, {});
  ASSERT_TRUE(guard.ok());
  EXPECT_EQ(guard->Staged((out_ / "maps/run.map").string()),
            (fs::path(guard->staging()) / "maps/run.map").string());
  EXPECT_EQ(guard->Staged((scratch_.path() / "x.map").string()),
            (scratch_.path() / "x.map").string());
}

TEST_F(OutputGuardTest, AnEmptyFolderNameIsRefused) {
  const StatusOr<OutputGuard> guard = OutputGuard::Begin("", false, {});
  ASSERT_FALSE(guard.ok());
  EXPECT_NE(guard.status().message().find("empty"), std::string::npos);
}

TEST_F(OutputGuardTest, ARunThatWroteNothingIntoANewFolderLeavesNoFolder) {
  ASSERT_TRUE(Run({}, false, /*ok=*/false).ok());
  EXPECT_FALSE(fs::exists(out_));
}

TEST_F(OutputGuardTest, InputsInsideTheFolderAreNeverRemoved) {
  ASSERT_TRUE(Run({"summary.json", "interrupted.map"}, false).ok());
  ASSERT_TRUE(Run({"summary.json"}, true, true, {(out_ / "interrupted.map").string()}).ok());
  EXPECT_TRUE(fs::exists(out_ / "interrupted.map"));
}

TEST_F(OutputGuardTest, AListPointingOutsideTheFolderIsRefusedAndNothingIsRemoved) {
  Put(scratch_.path() / "precious.txt", "keep");
  Put(out_ / "summary.json", "{}");
  Put(out_ / OutputGuard::kListName, "# list\nsummary.json\n../precious.txt\n");
  StatusOr<std::vector<std::string>> r = Run({"summary.json"}, true);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("ratslam_outputs.txt:3: '../precious.txt'"),
            std::string::npos)
      << r.status().message();
  Put(out_ / OutputGuard::kListName, "/etc/passwd\n");
  EXPECT_FALSE(Run({"summary.json"}, true).ok());
  EXPECT_EQ(Read(scratch_.path() / "precious.txt"), "keep");
}

TEST_F(OutputGuardTest, ARunThatWroteNothingLeavesNoListAndDoesNotBlockTheNext) {
  fs::create_directories(out_);
  ASSERT_TRUE(Run({}, false, /*ok=*/true).ok());
  EXPECT_FALSE(fs::exists(out_ / OutputGuard::kListName));
  ASSERT_TRUE(Run({}, false, /*ok=*/false).ok());
  EXPECT_FALSE(fs::exists(out_ / OutputGuard::kListName));
  EXPECT_TRUE(Run({"summary.json"}, false).ok());
}

TEST_F(OutputGuardTest, AFileWhereTheFolderShouldBeIsAnError) {
  Put(out_, "not a folder");
  EXPECT_FALSE(Run({}, false).ok());
}

}  // namespace
}  // namespace ratslam
