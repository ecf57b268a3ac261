#include "apps/output_guard.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

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
    if (e.is_regular_file()) files.insert(e.path().lexically_relative(folder).generic_string());
  }
  return files;
}

class OutputGuardTest : public ::testing::Test {
 protected:
  ScratchDir scratch_{"output_guard"};
  fs::path out_ = scratch_.path() / "out";

  // A "run" that writes `names` (through OutputGuard) and reports `ok`.
  StatusOr<std::vector<std::string>> Run(const std::vector<std::string>& names, bool overwrite,
                                         bool ok = true,
                                         const std::vector<std::string>& inputs = {}) {
    StatusOr<OutputGuard> guard = OutputGuard::Begin(out_.string(), overwrite, inputs);
    if (!guard.ok()) return guard.status();
    for (const std::string& n : names) Put(out_ / n, "new " + n);
    return guard->Finish(ok);
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

TEST_F(OutputGuardTest, AFailedRunKeepsTheEarlierFilesAndListsThemForTheNextOverwrite) {
  ASSERT_TRUE(Run({"summary.json", "old.png"}, false).ok());
  ASSERT_TRUE(Run({"summary.json"}, true, /*ok=*/false).ok());
  EXPECT_TRUE(fs::exists(out_ / "old.png"));
  EXPECT_NE(Read(out_ / OutputGuard::kListName).find("old.png"), std::string::npos);
  ASSERT_TRUE(Run({"summary.json"}, true).ok());
  EXPECT_FALSE(fs::exists(out_ / "old.png"));
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
