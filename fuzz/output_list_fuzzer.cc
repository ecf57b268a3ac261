// ratslam_outputs.txt, the list of files an earlier run wrote, which --overwrite removes: a
// hostile list never makes OutputGuard touch a file outside the output folder, nor one of the
// run's inputs; a refusal names the list's file and line.
#include <filesystem>
#include <fstream>
#include <string>

#include "common/output_guard.h"
#include "fuzz/fuzz_support.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  return {"# list\nsummary.json\nexperience_map.png\nanimation/frame_000000.png\n",
          "summary.json\n../outside.txt\n", "/etc/passwd\n", "input.map\nsub/../summary.json\n"};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace fs = std::filesystem;
  using namespace ratslam;
  const fs::path root = fuzz::Scratch().path() / "output_list";
  const fs::path folder = root / "out";
  fs::remove_all(root);
  fs::create_directories(folder / "animation");
  fs::create_directories(folder / "sub");
  for (const fs::path& p : {root / "outside.txt", folder / "summary.json", folder / "input.map",
                            folder / "experience_map.png", folder / "animation/frame_000000.png"}) {
    std::ofstream(p) << "x";
  }
  {
    std::ofstream list(folder / OutputGuard::kListName, std::ios::binary);
    list.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  StatusOr<OutputGuard> guard =
      OutputGuard::Begin(folder.string(), /*overwrite=*/true, {(folder / "input.map").string()});
  if (!guard.ok()) {
    if (guard.status().message().find(OutputGuard::kListName) == std::string::npos) {
      fuzz::InvariantFailed("refusal does not name the list: " + guard.status().message());
    }
  } else {
    // The run rewrites one file.
    std::ofstream(fs::path(guard->staging()) / "summary.json") << "the new run's";
    StatusOr<OutputGuard::Report> removed = guard->Finish(OutputGuard::Outcome::kSucceeded);
    if (!removed.ok()) fuzz::InvariantFailed("Finish failed: " + removed.status().message());
  }
  if (!fs::exists(root / "outside.txt")) fuzz::InvariantFailed("removed a file outside the folder");
  if (!fs::exists(folder / "input.map")) fuzz::InvariantFailed("removed an input");
  if (!fs::exists(folder / "summary.json")) fuzz::InvariantFailed("removed the new run's output");
  return 0;
}
