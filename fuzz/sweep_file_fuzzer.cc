// Sweep files: errors name the file; a sweep that plans gives every task a valid configuration,
// and planning it again gives the same tasks.
#include <filesystem>
#include <string>

#include "fuzz/fuzz_support.h"
#include "sweep/sweep.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  return {
      "[sweep]\nbase_config = \"base.toml\"\nobjective = \"map_ate_m + 0.1 * templates\"\n"
      "metrics = [\"match_rate_within_m.5\"]\naggregate = \"worst\"\ntimeout_s = 30\n"
      "[[datasets]]\ndata = [\"data/a\", \"data/b\"]\n[[datasets]]\nglob = \"data/*\"\n"
      "[parameters]\n\"wifi.match_threshold\" = {linear = [0.1, 0.5, 3]}\n"
      "\"fused.recency_s\" = [10, 20.5]\n\"local_view.skip_recent_templates\" = {log = [1, 9, "
      "3]}\n",
      "[sweep]\nmethod = \"random\"\nsamples = 5\nseed = 3\nobjective = \"map_ate_m\"\n"
      "goal = \"maximize\"\nsearch = \"halving\"\nhalving_rate = 2\n[[datasets]]\n"
      "data = [\"data/a\"]\n[parameters]\n\"wifi.match_threshold\" = {uniform = [0.1, 0.9]}\n"
      "\"pdr.baseline_s\" = {log_uniform = [1, 4]}\n\"fused.use_compass\" = [true, false]\n",
      "[sweep]\ncommand = \"evaluate\"\nobjective = \"correct_within_m.5\"\n[[datasets]]\n"
      "data = [\"data/a\", \"data/b\"]\n[parameters]\n\"wifi_words.bins\" = [1, 8]\n"};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  namespace fs = std::filesystem;
  static const bool prepared = [] {  // what the seeds refer to, beside the sweep file
    const fs::path root = fuzz::Scratch().path();
    fs::create_directories(root / "data" / "a");
    fs::create_directories(root / "data" / "b");
    const std::string base = "[fused]\nrecency_s = 30.0\n";
    fuzz::WriteScratchFile("base.toml", reinterpret_cast<const uint8_t*>(base.data()), base.size());
    return true;
  }();
  (void)prepared;
  const std::string path = fuzz::WriteScratchFile("sweep.toml", data, size);
  StatusOr<sweep::SweepSpec> spec = sweep::LoadSweepFile(path);
  if (!spec.ok()) {
    if (spec.status().message().rfind(path, 0) != 0) {
      fuzz::InvariantFailed("error does not name the file: " + spec.status().message());
    }
    return 0;
  }
  StatusOr<sweep::Plan> plan = sweep::MakePlan(*spec);
  if (!plan.ok()) {
    if (plan.status().message().rfind(path, 0) != 0) {
      fuzz::InvariantFailed("plan error does not name the file: " + plan.status().message());
    }
    return 0;
  }
  if (plan->tasks.size() > 2000) return 0;  // large plans are valid; checking each is slow
  for (const sweep::Task& task : plan->tasks) {
    StatusOr<fusion::PipelineOptions> config = sweep::TaskConfig(*plan, task);
    std::string error;
    if (!config.ok() || !config->IsValid(&error)) {
      fuzz::InvariantFailed("a planned task has no valid configuration");
    }
  }
  StatusOr<sweep::Plan> again = sweep::MakePlan(*spec);
  if (!again.ok() || again->tasks.size() != plan->tasks.size()) {
    fuzz::InvariantFailed("planning twice differs");
  }
  for (size_t i = 0; i < plan->tasks.size(); ++i) {
    if (again->tasks[i].overrides != plan->tasks[i].overrides) {
      fuzz::InvariantFailed("planning twice gives other tasks");
    }
  }
  return 0;
}
