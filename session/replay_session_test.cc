#include "session/replay_session.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "common/scratch_dir.h"
#include "dataset/synthetic_dataset.h"
#include "io/config.h"
#include "io/map_file.h"
#include "tests/test_paths.h"

namespace ratslam::session {
namespace {
namespace fs = std::filesystem;

// Files in memory; can refuse writes of chosen names (a full disk) and counts attempts.
class MemoryFolder : public OutputFolder {
 public:
  explicit MemoryFolder(std::string root) : root_(std::move(root)) {}
  std::string Path(const std::string& name) const override { return root_ + "/" + name; }
  using OutputFolder::Write;
  Status Write(const std::vector<std::pair<std::string, std::string>>& files) override {
    for (const auto& [name, contents] : files) {
      if (refuse.count(name)) return Status::Error(Path(name) + ": write failed: No space left");
    }
    for (const auto& [name, contents] : files) written[name] = contents;
    return Status::Ok();
  }
  std::set<std::string> refuse;
  std::map<std::string, std::string> written;

 private:
  std::string root_;
};

// Each call advances by a second: wall times become known numbers.
class FakeClock : public Clock {
 public:
  double Seconds() const override { return now_ += 1.0; }

 private:
  mutable double now_ = 100.0;
};

class RecordingProgress : public ProgressSink {
 public:
  void Update(const ProgressUpdate& u) override { updates.push_back(u); }
  void Finish() override { ++finishes; }
  std::vector<ProgressUpdate> updates;
  int finishes = 0;
};

class ReplaySessionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir("ratslam_session");
    dataset::SyntheticOptions small;
    small.laps = 1;
    ASSERT_TRUE(dataset::WriteSyntheticDataset(small, (dir_->path() / "data").string()).ok());
  }
  static void TearDownTestSuite() { delete dir_; }
  static ReplaySessionOptions Options() {
    ReplaySessionOptions o;
    o.data = {(dir_->path() / "data").string()};
    o.pipeline.sensors.classic_camera.match_threshold = 0.06;
    return o;
  }
  static ScratchDir* dir_;
};
ScratchDir* ReplaySessionTest::dir_ = nullptr;

TEST_F(ReplaySessionTest, RunsEveryStageAndReportsThroughTheEnvironment) {
  MemoryFolder out("mem");
  FakeClock clock;
  RecordingProgress progress;
  ReplaySession session(Options(), {&out, &clock, &progress, nullptr, nullptr, {}});
  StatusOr<ReplayResult> result = session.Run();
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_TRUE(result->ok());
  EXPECT_TRUE(result->finished);
  EXPECT_EQ(result->wall_seconds, 1.0);  // two clock readings a second apart
  for (const char* name :
       {"config.toml", "experiences.csv", "links.csv", "trajectory_tum.txt", "odometry_tum.txt",
        "experience_map.g2o", "frames.csv", "summary.json"}) {
    EXPECT_TRUE(out.written.count(name)) << name;
  }
  EXPECT_FALSE(out.written.count("interrupted.map"));
  EXPECT_TRUE(result->saved_map.empty());
  const auto summary = nlohmann::json::parse(out.written["summary.json"]);
  EXPECT_EQ(summary["wall_seconds"], 1.0);
  EXPECT_EQ(summary["frames"].get<uint64_t>(), session.pipeline().state().frames.size());
  EXPECT_EQ(summary["finished"], true);
  ASSERT_FALSE(progress.updates.empty());
  EXPECT_EQ(progress.updates.back().phase, "replay");
  EXPECT_EQ(progress.updates.back().done, progress.updates.back().total);
  EXPECT_EQ(progress.finishes, 1);
}

// A full disk when the outputs are written: the error names the file, the map is still saved
// where the user asked (another disk), and nothing of the outputs is half-written.
TEST_F(ReplaySessionTest, OutputFailureStillSavesTheMap) {
  MemoryFolder out("mem");
  out.refuse = {"frames.csv"};
  ReplaySessionOptions options = Options();
  options.until_s = 30.0;
  options.save_map = (dir_->path() / "elsewhere.map").string();
  ReplaySession session(options, {&out, nullptr, nullptr, nullptr, nullptr, {}});
  StatusOr<ReplayResult> result = session.Run();
  ASSERT_TRUE(result.ok());
  EXPECT_TRUE(result->replay.ok());
  ASSERT_FALSE(result->outputs.ok());
  EXPECT_NE(result->outputs.message().find("mem/frames.csv"), std::string::npos);
  EXPECT_FALSE(out.written.count("summary.json"));
  EXPECT_FALSE(out.written.count("experiences.csv"));  // all or nothing
  EXPECT_TRUE(result->save.ok()) << result->save.message();
  EXPECT_EQ(result->saved_map, options.save_map);
  EXPECT_TRUE(io::LoadMapFile(options.save_map).ok());
}

// Without --save-map, a failure to write the outputs saves interrupted.map beside them so that
// the replay's work can be resumed.
TEST_F(ReplaySessionTest, OutputFailureWithoutSaveMapSavesInterruptedMap) {
  MemoryFolder out((dir_->path() / "run").string());
  fs::create_directories(dir_->path() / "run");
  out.refuse = {"summary.json"};
  ReplaySessionOptions options = Options();
  options.until_s = 20.0;
  ReplaySession session(options, {&out, nullptr, nullptr, nullptr, nullptr, {}});
  StatusOr<ReplayResult> result = session.Run();
  ASSERT_TRUE(result.ok());
  EXPECT_FALSE(result->outputs.ok());
  EXPECT_EQ(result->saved_map, (dir_->path() / "run" / "interrupted.map").string());
  EXPECT_TRUE(fs::exists(dir_->path() / "run" / "interrupted.map"));
}

TEST_F(ReplaySessionTest, StopRequestInterruptsAndSavesState) {
  MemoryFolder out((dir_->path() / "stopped").string());
  fs::create_directories(dir_->path() / "stopped");
  std::atomic<bool> stop{false};
  ReplaySession session(Options(), {&out, nullptr, nullptr, nullptr, &stop, {}});
  ReplayCheckpoint checkpoint;
  checkpoint.every = 100;
  checkpoint.callback = [&stop](const fusion::ReplayPipeline&) {
    stop.store(true);  // as a signal handler would, after the first 100 events
    return Status::Ok();
  };
  StatusOr<ReplayResult> result = session.Run(checkpoint);
  ASSERT_TRUE(result.ok());
  EXPECT_TRUE(result->interrupted);
  EXPECT_FALSE(result->finished);
  EXPECT_EQ(session.pipeline().state().next_event, 100u);
  EXPECT_EQ(nlohmann::json::parse(out.written["summary.json"])["interrupted"], true);
  StatusOr<io::MapFile> map = io::LoadMapFile(result->saved_map);
  ASSERT_TRUE(map.ok()) << map.status().message();
  EXPECT_EQ(map->state.next_event, 100u);
}

TEST_F(ReplaySessionTest, LoadAndPrepareErrorsAreReturnedBeforeAnythingRuns) {
  MemoryFolder out("mem");
  ReplaySessionOptions missing = Options();
  missing.data = {(dir_->path() / "no-such-data").string()};
  ReplaySession a(missing, {&out, nullptr, nullptr, nullptr, nullptr, {}});
  EXPECT_FALSE(a.Run().ok());
  EXPECT_TRUE(out.written.empty());

  ReplaySessionOptions wrong_map = Options();
  wrong_map.load_map = (dir_->path() / "no-such.map").string();
  ReplaySession b(wrong_map, {&out, nullptr, nullptr, nullptr, nullptr, {}});
  const StatusOr<ReplayResult> result = b.Run();
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("no-such.map"), std::string::npos);
  EXPECT_FALSE(out.written.count("summary.json"));
}

// A map from another configuration is refused, naming the file.
TEST_F(ReplaySessionTest, ResumeChecksConfigurationAndDataSet) {
  MemoryFolder out("mem");
  ReplaySessionOptions first = Options();
  first.until_s = 10.0;
  first.save_map = (dir_->path() / "first.map").string();
  ReplaySession a(first, {&out, nullptr, nullptr, nullptr, nullptr, {}});
  ASSERT_TRUE(a.Run().ok());
  ReplaySessionOptions other = Options();
  other.pipeline.sensors.classic_camera.match_threshold = 0.07;
  other.load_map = first.save_map;
  ReplaySession b(other, {&out, nullptr, nullptr, nullptr, nullptr, {}});
  const StatusOr<ReplayResult> refused = b.Run();
  ASSERT_FALSE(refused.ok());
  // The map carries its configuration (format 3): the error names the key and both values.
  EXPECT_NE(refused.status().message().find("different configuration"), std::string::npos);
  EXPECT_NE(refused.status().message().find("camera.match_threshold: 0.06 -> 0.07"),
            std::string::npos)
      << refused.status().message();
}

// [fabmap_front_end] calibrate_earlier_session_log_odds on the four walks of IPIN route 21: the
// calibration pass reports its own progress phase and learns before the main pass; a stop during
// it stops the run before any frame (nothing calibrated, the state saved at event 0), and the
// run resumed from that map calibrates afresh and ends as an uninterrupted run does. A map saved
// after the first event keeps its threshold: resuming it makes no calibration pass.
TEST_F(ReplaySessionTest, CalibrationPassRunsFirstAndAStopDuringItLosesNothing) {
  ReplaySessionOptions options;
  for (const char* rep : {"01", "02", "03", "04"}) {
    const fs::path log = fs::path(test_paths::SharedDataDir()) / "ipin2023-t3" /
                         (std::string("IPIN2023_T3_TrainingTrial21_repetition") + rep + ".txt");
    if (!fs::exists(log)) GTEST_SKIP() << "missing " << log;
    options.data.push_back(log.string());
  }
  StatusOr<fusion::PipelineOptions> config = io::LoadConfigFile(
      std::string(test_paths::SourceDir()) + "/configs/ipin2023-fabmap-wifi.toml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  ASSERT_TRUE(config->sensors.fabmap.front_end.calibrate_earlier_session_log_odds);
  options.pipeline = *config;

  MemoryFolder whole_out("mem");
  RecordingProgress progress;
  ReplaySession whole(options, {&whole_out, nullptr, &progress, nullptr, nullptr, {}});
  StatusOr<ReplayResult> uninterrupted = whole.Run();
  ASSERT_TRUE(uninterrupted.ok() && uninterrupted->ok());
  ASSERT_TRUE(uninterrupted->calibration.has_value());
  ASSERT_TRUE(uninterrupted->calibration->earlier_session_log_odds.has_value());
  EXPECT_GE(uninterrupted->calibration->verified_revisits, 10u);
  ASSERT_FALSE(progress.updates.empty());
  EXPECT_EQ(progress.updates.front().phase, "calibrate");
  EXPECT_EQ(progress.updates.back().phase, "replay");
  EXPECT_EQ(progress.finishes, 2);
  const auto summary = nlohmann::json::parse(whole_out.written["summary.json"]);
  EXPECT_EQ(summary["fabmap_calibrated"], true);
  EXPECT_EQ(summary["fabmap_earlier_session_log_odds"].get<double>(),
            *uninterrupted->calibration->earlier_session_log_odds);

  // Stopped half way through the calibration pass (as a signal would).
  fs::create_directories(dir_->path() / "calibrating");
  MemoryFolder out((dir_->path() / "calibrating").string());
  std::atomic<bool> stop{false};
  struct StopHalfWay : RecordingProgress {
    std::atomic<bool>* stop = nullptr;
    void Update(const ProgressUpdate& u) override {
      if (u.phase == "calibrate" && 2 * u.done >= u.total) stop->store(true);
    }
  } stopper;
  stopper.stop = &stop;
  ReplaySession stopped(options, {&out, nullptr, &stopper, nullptr, &stop, {}});
  StatusOr<ReplayResult> result = stopped.Run();
  ASSERT_TRUE(result.ok());
  EXPECT_TRUE(result->interrupted);
  EXPECT_FALSE(result->calibration.has_value());
  EXPECT_EQ(result->frames_this_run, 0u);
  EXPECT_EQ(nlohmann::json::parse(out.written["summary.json"])["fabmap_calibrated"], false);
  StatusOr<io::MapFile> map = io::LoadMapFile(result->saved_map);
  ASSERT_TRUE(map.ok()) << map.status().message();
  EXPECT_EQ(map->state.next_event, 0u);

  ReplaySessionOptions resume = options;
  resume.load_map = result->saved_map;
  resume.save_map = (dir_->path() / "calibrated.map").string();
  MemoryFolder resumed_out("mem");
  ReplaySession resumed(resume, {&resumed_out, nullptr, nullptr, nullptr, nullptr, {}});
  StatusOr<ReplayResult> resumed_result = resumed.Run();
  ASSERT_TRUE(resumed_result.ok() && resumed_result->ok());
  ASSERT_TRUE(resumed_result->calibration.has_value());
  EXPECT_EQ(resumed_result->calibration->earlier_session_log_odds,
            uninterrupted->calibration->earlier_session_log_odds);
  for (const char* file : {"experiences.csv", "links.csv", "frames.csv"}) {
    EXPECT_EQ(resumed_out.written[file], whole_out.written[file]) << file;
  }

  // A map made past its first event: resumed (here with nothing left to replay), no second
  // calibration pass, and the threshold it was saved with.
  ReplaySessionOptions again = options;
  again.load_map = resume.save_map;
  MemoryFolder again_out("mem");
  ReplaySession kept(again, {&again_out, nullptr, nullptr, nullptr, nullptr, {}});
  StatusOr<ReplayResult> kept_result = kept.Run();
  ASSERT_TRUE(kept_result.ok() && kept_result->ok());
  EXPECT_FALSE(kept_result->calibration.has_value());
  const auto kept_summary = nlohmann::json::parse(again_out.written["summary.json"]);
  EXPECT_EQ(kept_summary["fabmap_calibrated"], true);
  EXPECT_EQ(kept_summary["fabmap_earlier_session_log_odds"],
            summary["fabmap_earlier_session_log_odds"]);
}

// A front end of the caller's own: every image a new place (the smallest valid front end; a
// useful one is in fusion/custom_front_end_test.cc).
class EveryImageNew : public fusion::FrontEnd {
 public:
  StatusOr<std::optional<fusion::FrameDecision>> OnImage(double time_s, const GrayImage&) override {
    fusion::FrameDecision d;
    d.view.time_s = time_s;
    d.view.template_id = count_++;
    d.view.is_new = true;
    return std::optional<fusion::FrameDecision>(d);
  }
  bool WantsImages() const override { return true; }
  uint32_t size() const override { return count_; }
  std::string EncodeState() const override { return std::to_string(count_); }
  Status DecodeState(const std::string& bytes) override {
    count_ = static_cast<uint32_t>(std::stoul(bytes));
    return Status::Ok();
  }

 private:
  uint32_t count_ = 0;
};

// kind = "custom" runs the session's factory; without one the session says how to give it.
TEST_F(ReplaySessionTest, CustomFrontEndComesFromTheEnvironment) {
  MemoryFolder out("mem");
  ReplaySessionOptions options = Options();
  options.pipeline.sensors.front_end.kind = fusion::FrontEndKind::kCustom;
  options.until_s = 10.0;
  ReplaySession without(options, {&out, nullptr, nullptr, nullptr, nullptr, {}});
  const StatusOr<ReplayResult> refused = without.Run();
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("SessionEnvironment::custom_front_end"),
            std::string::npos)
      << refused.status().message();
  int made = 0;
  fusion::FrontEndFactory factory = [&made] {
    ++made;
    return std::make_unique<EveryImageNew>();
  };
  ReplaySession with(options, {&out, nullptr, nullptr, nullptr, nullptr, factory});
  const StatusOr<ReplayResult> result = with.Run();
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_EQ(made, 1);
  const nlohmann::json s = nlohmann::json::parse(out.written.at("summary.json"));
  EXPECT_GT(s["frames"].get<int>(), 50);
  EXPECT_EQ(s["templates"].get<int>(), s["frames"].get<int>());
  EXPECT_EQ(s["loop_closures"].get<int>(), 0);
}

}  // namespace
}  // namespace ratslam::session
