// Faults a user meets: the program killed while it saves a map. A map file on disk is always a
// complete map (the old one or the new one), never a torn one; the temporary file a killed save
// leaves behind is removed by the next save.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "apps/demo_config.h"
#include "common/scratch_dir.h"
#include "dataset/synthetic_dataset.h"
#include "io/map_file.h"
#include "tests/run_ratslam.h"
#include "tests/test_paths.h"

extern char** environ;

namespace ratslam {
namespace {
namespace fs = std::filesystem;

using e2e::Slurp;

// Starts `ratslam` with `args` (output to /dev/null); returns its pid.
pid_t Spawn(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  std::string binary = ratslam::test_paths::RatslamBinary();
  argv.push_back(binary.data());
  std::vector<std::string> copy = args;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, binary.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

int Wait(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return status;
}

TEST(FaultInjectionTest, KillDuringSaveNeverLeavesATornMap) {
  ScratchDir dir("ratslam_fault");
  ASSERT_TRUE(
      dataset::WriteSyntheticDataset(apps::DemoSyntheticOptions(), (dir / "data").string()).ok());
  const std::string config =
      std::string(ratslam::test_paths::SourceDir()) + "/configs/synthetic.toml";
  auto replay = [&](double until, const fs::path& map) {
    return std::vector<std::string>{"replay",
                                    "--quiet",
                                    "--overwrite",
                                    "--config",
                                    config,
                                    "--data",
                                    (dir / "data").string(),
                                    "--out",
                                    (dir / "out").string(),
                                    "--until",
                                    std::to_string(until),
                                    "--save-map",
                                    map.string()};
  };
  // The two complete maps a save may leave: the earlier one (t = 100 s) and the new (t = 200 s).
  const fs::path early = dir / "early.map", late = dir / "late.map";
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(WEXITSTATUS(Wait(Spawn(replay(200, late)))), 0);
  const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(WEXITSTATUS(Wait(Spawn(replay(100, early)))), 0);
  const std::string early_bytes = Slurp(early), late_bytes = Slurp(late);
  ASSERT_NE(early_bytes, late_bytes);

  // SIGKILL at seeded random moments: half over the whole run, half near its end, where the
  // outputs and the map are written.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> anywhere(0.0, 1.2 * run_s),
      near_end(0.8 * run_s, 1.1 * run_s);
  const fs::path map = dir / "m.map";
  int killed_mid_run = 0, old_maps = 0, new_maps = 0;
  for (int k = 0; k < 24; ++k) {
    fs::copy_file(early, map, fs::copy_options::overwrite_existing);
    const pid_t pid = Spawn(replay(200, map));
    ASSERT_GT(pid, 0);
    std::this_thread::sleep_for(
        std::chrono::duration<double>(k % 2 ? near_end(random) : anywhere(random)));
    ::kill(pid, SIGKILL);
    const int status = Wait(pid);
    killed_mid_run += WIFSIGNALED(status) ? 1 : 0;
    const std::string bytes = Slurp(map);
    ASSERT_TRUE(bytes == early_bytes || bytes == late_bytes)
        << "kill " << k << " left a map of " << bytes.size() << " bytes that is neither";
    (bytes == early_bytes ? old_maps : new_maps) += 1;
    EXPECT_TRUE(io::LoadMapFile(map.string()).ok());
  }
  EXPECT_GT(killed_mid_run, 0);
  // The next complete save removes whatever temporary files the killed saves left.
  ASSERT_EQ(WEXITSTATUS(Wait(Spawn(replay(200, map)))), 0);
  EXPECT_EQ(Slurp(map), late_bytes);
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().filename().string().find("m.map.tmp"), std::string::npos)
        << entry.path();
  }
  std::printf("kills: %d mid-run; map left old %d times, new %d times\n", killed_mid_run, old_maps,
              new_maps);
}

}  // namespace
}  // namespace ratslam
