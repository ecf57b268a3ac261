#include "fusion/replay_pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace ratslam::fusion {
namespace {

// Two laps of a 20 m square at 1 m/s: odometry at 10 Hz, a Wi-Fi scan every 2 s from four access
// points whose RSSI falls with distance (so the second lap re-matches the first lap's places),
// and a camera image every second that the Wi-Fi-only front end must skip.
dataset::Dataset SquareLoop() {
  dataset::Dataset d;
  d.name = "square";
  const double side_m = 20.0, speed = 1.0, rate_hz = 10.0;
  const double lap_s = 4 * side_m / speed;
  const double corners[4][2] = {{0, 0}, {20, 0}, {20, 20}, {0, 20}};
  auto position = [&](double t, double* x, double* y) {
    const double along = std::fmod(t * speed, 4 * side_m);
    const int leg = static_cast<int>(along / side_m);
    const double f = (along - leg * side_m) / side_m;
    const double* a = corners[leg];
    const double* b = corners[(leg + 1) % 4];
    *x = a[0] + f * (b[0] - a[0]);
    *y = a[1] + f * (b[1] - a[1]);
  };
  for (int i = 0; i <= static_cast<int>(2 * lap_s * rate_hz); ++i) {
    const double t = i / rate_hz;
    const double along = std::fmod(t * speed, side_m);
    // Turn 90 degrees in the last 0.1 s of each leg.
    const bool turning = i > 0 && along > side_m - speed / rate_hz - 1e-9;
    d.odometry.push_back({t, speed, turning ? std::numbers::pi / 2 * rate_hz : 0.0});
  }
  const char* aps[4] = {"aa", "bb", "cc", "dd"};
  for (double t = 1.0; t < 2 * lap_s; t += 2.0) {
    double x = 0, y = 0;
    position(t, &x, &y);
    WifiScan scan{t, {}};
    for (int k = 0; k < 4; ++k) {
      const double dist = std::hypot(x - corners[k][0], y - corners[k][1]);
      scan.readings.push_back({aps[k], -40.0 - 20.0 * std::log10(1.0 + dist)});
    }
    d.wifi.push_back(scan);
  }
  for (int t = 0; t < 2 * lap_s; ++t) d.images.push_back({t + 0.5, "f.png", t + 2});
  return d;
}

PipelineOptions WifiOptions() {
  PipelineOptions o;
  o.sensors.front_end.kind = FrontEndKind::kFused;
  o.sensors.fused.use_wifi = true;
  o.sensors.fused.use_camera = false;
  o.sensors.fused.recency_s = 20.0;
  return o;
}

class NoImages : public ImageLoader {
 public:
  StatusOr<GrayImage> Load(const std::string& path) override {
    ++loads;
    return Status::Error(path + ": cannot read image");
  }
  int loads = 0;
};

TEST(ReplayPipelineTest, SkipsImagesTheFrontEndDoesNotUseAndReportsProgress) {
  const dataset::Dataset data = SquareLoop();
  NoImages images;
  ReplayPipeline pipeline(WifiOptions(), data, &images);
  std::vector<ReplayProgress> reports;
  ReplayControl control;
  control.progress_every = 100;
  control.progress = [&](const ReplayProgress& p) { reports.push_back(p); };
  ASSERT_TRUE(pipeline.Run(control).ok());
  EXPECT_TRUE(pipeline.finished());
  EXPECT_EQ(images.loads, 0);
  EXPECT_EQ(pipeline.state().images_skipped, data.images.size());
  EXPECT_EQ(pipeline.state().wifi_scans_seen, data.wifi.size());
  EXPECT_EQ(pipeline.state().trajectory.size(), data.odometry.size());
  // Wi-Fi scans are the frames; the second lap re-matches the first lap's places.
  EXPECT_EQ(pipeline.state().frames.size(), data.wifi.size());
  EXPECT_GT(pipeline.slam().counters().loop_closures, 0u);
  const uint64_t total = data.odometry.size() + data.wifi.size() + data.images.size();
  ASSERT_EQ(reports.size(), total / 100 + (total % 100 ? 1 : 0));
  for (size_t i = 0; i + 1 < reports.size(); ++i) {
    EXPECT_EQ(reports[i].events_done, (i + 1) * 100);
    EXPECT_LE(reports[i].data_time_s, reports[i + 1].data_time_s);
  }
  EXPECT_EQ(reports.back().events_done, total);
  EXPECT_EQ(reports.back().events_total, total);
}

TEST(ReplayPipelineTest, ImageErrorsNameTheRowAndKeepTheStateSoFar) {
  const dataset::Dataset data = SquareLoop();
  NoImages images;
  PipelineOptions options;  // the classic camera wants every image
  ReplayPipeline pipeline(options, data, &images);
  const Status status = pipeline.Run({});
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("images.csv:2"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("f.png"), std::string::npos) << status.message();
  // Stopped at the first image (t = 0.5 s): the odometry before it was processed.
  EXPECT_EQ(pipeline.state().trajectory.size(), 5u);
  EXPECT_FALSE(pipeline.finished());
}

TEST(ReplayPipelineTest, CheckpointsRunAtTheirPeriodAndAnErrorStopsTheReplay) {
  const dataset::Dataset data = SquareLoop();
  NoImages images;
  ReplayPipeline pipeline(WifiOptions(), data, &images);
  std::vector<uint64_t> at;
  ReplayControl control;
  control.checkpoint_every = 250;
  control.checkpoint = [&](const ReplayPipeline& p) {
    at.push_back(p.state().next_event);
    return at.size() == 3 ? Status::Error("disk full") : Status::Ok();
  };
  const Status status = pipeline.Run(control);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(), "disk full");
  EXPECT_EQ(at, (std::vector<uint64_t>{250, 500, 750}));
  EXPECT_EQ(pipeline.state().next_event, 750u);
}

TEST(ReplayPipelineTest, StopAndResumeEqualsOneRunForTheFusedFrontEnd) {
  const dataset::Dataset data = SquareLoop();
  NoImages images;
  ReplayPipeline whole(WifiOptions(), data, &images);
  ASSERT_TRUE(whole.Run({}).ok());

  ReplayPipeline first(WifiOptions(), data, &images);
  ReplayControl half;
  half.until_time_s = 110.0;  // in the second lap, after some matches
  ASSERT_TRUE(first.Run(half).ok());
  ASSERT_FALSE(first.finished());
  ReplayPipeline second(WifiOptions(), data, &images);
  ASSERT_TRUE(second.Restore(first.Snapshot()).ok());
  ASSERT_TRUE(second.Run({}).ok());

  const auto& a = whole.slam().experience_map().experiences();
  const auto& b = second.slam().experience_map().experiences();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].x_m, b[i].x_m);
    EXPECT_EQ(a[i].y_m, b[i].y_m);
  }
  EXPECT_EQ(whole.state().frames.size(), second.state().frames.size());
  EXPECT_EQ(whole.Snapshot().front_end, second.Snapshot().front_end);
}

TEST(ReplayPipelineTest, StageTimesSplitTheRunAndChangeNothing) {
  const dataset::Dataset data = SquareLoop();
  NoImages images;
  ReplayPipeline untimed(WifiOptions(), data, &images);
  ASSERT_TRUE(untimed.Run({}).ok());

  // Timed for the first half (through a restore, which makes a new spine), then not.
  StageTimes times;
  ReplayPipeline first(WifiOptions(), data, &images);
  first.AttachStageTimes(&times);
  ReplayControl half;
  half.until_time_s = 60.0;
  ASSERT_TRUE(first.Run(half).ok());
  const StageTimes first_half = times;
  ReplayPipeline timed(WifiOptions(), data, &images);
  timed.AttachStageTimes(&times);
  ASSERT_TRUE(timed.Restore(first.Snapshot()).ok());
  half.until_time_s = 110.0;
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(timed.Run(half).ok());
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const StageTimes after_half = times;
  // The stages ran on both sides of the restore, and the second run's stages fit in its wall
  // time.
  auto sum = [](const StageTimes& t) {
    return t.front_end_s + t.pose_cells_s + t.experience_map_s;
  };
  EXPECT_GT(first_half.front_end_s, 0.0);
  EXPECT_GT(first_half.pose_cells_s, 0.0);
  EXPECT_GT(first_half.experience_map_s, 0.0);
  EXPECT_GT(after_half.front_end_s, first_half.front_end_s);
  EXPECT_GT(after_half.pose_cells_s, first_half.pose_cells_s);
  EXPECT_GT(after_half.experience_map_s, first_half.experience_map_s);
  EXPECT_LE(sum(after_half) - sum(first_half), wall_s);
  timed.AttachStageTimes(nullptr);
  ASSERT_TRUE(timed.Run({}).ok());
  EXPECT_EQ(times.front_end_s, after_half.front_end_s);
  EXPECT_EQ(times.pose_cells_s, after_half.pose_cells_s);
  EXPECT_EQ(times.experience_map_s, after_half.experience_map_s);

  // Timing a frame changes none of it.
  const auto& a = untimed.slam().experience_map().experiences();
  const auto& b = timed.slam().experience_map().experiences();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].x_m, b[i].x_m);
    EXPECT_EQ(a[i].y_m, b[i].y_m);
    EXPECT_EQ(a[i].theta_rad, b[i].theta_rad);
  }
  EXPECT_EQ(untimed.Snapshot().front_end, timed.Snapshot().front_end);
  EXPECT_EQ(untimed.state().frames.size(), timed.state().frames.size());
}

// A front end that notes what the pipeline says about walking before each scan (and, given a
// list, the verified revisits it hears of).
class WalkingNotes : public FrontEnd {
 public:
  explicit WalkingNotes(std::vector<std::pair<double, bool>>* notes,
                        std::vector<std::pair<double, double>>* revisits = nullptr)
      : notes_(notes), revisits_(revisits) {}
  StatusOr<std::optional<FrameDecision>> OnImage(double, const GrayImage&) override {
    return std::optional<FrameDecision>();
  }
  void OnWalking(bool walking) override { walking_ = walking; }
  void OnVerifiedRevisit(double now_s, double then_s) override {
    if (revisits_) revisits_->emplace_back(now_s, then_s);
  }
  StatusOr<std::optional<FrameDecision>> OnWifi(const WifiScan& scan) override {
    notes_->emplace_back(scan.time_s, walking_);
    return std::optional<FrameDecision>();
  }
  bool WantsImages() const override { return false; }
  uint32_t size() const override { return 0; }
  std::string EncodeState() const override { return {}; }
  Status DecodeState(const std::string&) override { return Status::Ok(); }

 private:
  std::vector<std::pair<double, bool>>* notes_;
  std::vector<std::pair<double, double>>* revisits_;
  bool walking_ = false;
};

// Walking before a scan: the newest odometry step moved, within the PDR's longest step interval
// (2 s) of the scan. Standing still with odometry rows of zero speed (0-10 s), walking (10-20 s),
// then no rows at all (a phone's PDR writes none while its walker stands).
TEST(ReplayPipelineTest, TellsTheFrontEndWhetherTheWalkerMovedBeforeEachScan) {
  dataset::Dataset data;
  data.name = "stand-walk-stand";
  for (int i = 0; i <= 200; ++i) data.odometry.push_back({0.1 * i, i > 100 ? 1.0 : 0.0, 0.0});
  for (int t = 0; t < 30; ++t) data.wifi.push_back({t + 0.5, {{"aa", -50.0}}});
  std::vector<std::pair<double, bool>> notes;
  PipelineOptions options;
  options.sensors.front_end.kind = FrontEndKind::kCustom;
  FrontEndResources resources;
  resources.custom = [&notes] { return std::make_unique<WalkingNotes>(&notes); };
  NoImages images;
  ReplayPipeline pipeline(options, data, &images, resources);
  ASSERT_TRUE(pipeline.Run({}).ok());
  ASSERT_EQ(notes.size(), 30u);
  for (const auto& [time_s, walking] : notes) {
    const bool expected = time_s > 10.0 && time_s < 20.0 + 2.0;
    EXPECT_EQ(walking, expected) << "scan at " << time_s << " s";
  }
}

// Sequence recognition ([sequence] recognise_views) wraps the front end that decides; what the
// pipeline tells a front end about walking and verified revisits still reaches it (it did not:
// a fused front end's rssi_offset_walking_only then took every scan as walking).
TEST(ReplayPipelineTest, SequenceRecognitionPassesWalkingAndRevisitsOn) {
  std::vector<std::pair<double, bool>> notes;
  std::vector<std::pair<double, double>> revisits;
  FrontEndSettings settings;
  settings.front_end.kind = FrontEndKind::kCustom;
  settings.sequence.recognise_views = true;
  FrontEndResources resources;
  resources.custom = [&] { return std::make_unique<WalkingNotes>(&notes, &revisits); };
  std::unique_ptr<FrontEnd> f = CreateFrontEnd(settings, resources);
  ASSERT_TRUE(f->WantsImages());  // the wrapper
  f->OnWalking(false);
  ASSERT_TRUE(f->OnWifi({1.0, {{"aa", -50.0}}}).ok());
  f->OnWalking(true);
  ASSERT_TRUE(f->OnWifi({2.0, {{"aa", -50.0}}}).ok());
  f->OnVerifiedRevisit(2.0, 1.0);
  const std::vector<std::pair<double, bool>> want_notes = {{1.0, false}, {2.0, true}};
  EXPECT_EQ(notes, want_notes);
  const std::vector<std::pair<double, double>> want_revisits = {{2.0, 1.0}};
  EXPECT_EQ(revisits, want_revisits);
}

TEST(ReplayPipelineTest, RestoreRefusesStatesThatDoNotFit) {
  const dataset::Dataset data = SquareLoop();
  NoImages images;
  ReplayPipeline pipeline(WifiOptions(), data, &images);
  ReplayControl half;
  half.until_time_s = 110.0;
  ASSERT_TRUE(pipeline.Run(half).ok());
  const ReplayPipeline::State good = pipeline.Snapshot();
  ASSERT_FALSE(good.frames.empty());

  auto refused = [&](ReplayPipeline::State s, const std::string& expected) {
    ReplayPipeline other(WifiOptions(), data, &images);
    const Status status = other.Restore(s);
    EXPECT_FALSE(status.ok()) << expected;
    EXPECT_NE(status.message().find(expected), std::string::npos) << status.message();
    EXPECT_EQ(other.state().next_event, 0u);  // nothing taken over
  };
  ReplayPipeline::State s = good;
  s.events_total += 1;
  refused(s, "events");
  s = good;
  s.next_event = good.events_total + 1;
  refused(s, "past the data set");
  s = good;
  s.trajectory.back().experience_id = 1'000'000;  // crashed RecordPose in the outputs
  refused(s, "trajectory record");
  s = good;
  s.frames.back().template_id = 1'000'000;  // crashed Summarise in the outputs
  refused(s, "frame record");
  s = good;
  s.odometry_x_m = std::numeric_limits<double>::quiet_NaN();
  refused(s, "not finite");
  s = good;
  s.front_end.resize(s.front_end.size() / 2);
  refused(s, "fused front-end state");
  s = good;
  s.ratslam.local_view.templates.pop_back();  // the front end has one template more
  for (auto& e : s.ratslam.experience_map.experiences) {
    if (e.template_id == s.ratslam.local_view.templates.size()) e.template_id = 0;
  }
  ReplayPipeline other(WifiOptions(), data, &images);
  EXPECT_FALSE(other.Restore(s).ok());

  // A state from another configuration's front end is refused too.
  PipelineOptions camera;
  ReplayPipeline classic(camera, data, &images);
  EXPECT_FALSE(classic.Restore(good).ok());
}

// Two laps of the same 20 m square with 20 access points along it, each heard within 7 m: every
// stretch of the loop has its own set of APs, which FABMAP's presence words can tell apart.
dataset::Dataset ApLoop() {
  dataset::Dataset d = SquareLoop();
  const double side = 20.0, lap = 80.0;
  auto position = [&](double along, double* x, double* y) {
    along = std::fmod(along, lap);
    const int leg = static_cast<int>(along / side);
    const double f = along - leg * side;
    const double c[5][2] = {{0, 0}, {side, 0}, {side, side}, {0, side}, {0, 0}};
    *x = c[leg][0] + (c[leg + 1][0] - c[leg][0]) * f / side;
    *y = c[leg][1] + (c[leg + 1][1] - c[leg][1]) * f / side;
  };
  for (WifiScan& scan : d.wifi) {
    double x, y;
    position(scan.time_s, &x, &y);
    scan.readings.clear();
    for (int k = 0; k < 20; ++k) {
      double ax, ay;
      position(4.0 * k, &ax, &ay);
      const double dist = std::hypot(x - ax, y - ay);
      if (dist < 7.0) {
        scan.readings.push_back({"ap" + std::to_string(k), -40.0 - 20.0 * std::log10(1.0 + dist)});
      }
    }
  }
  return d;
}

PipelineOptions FabmapWifiOptions(WifiLearning learning) {
  PipelineOptions o;
  o.sensors.front_end.kind = FrontEndKind::kFabmap;
  o.sensors.fabmap.localiser.localiser.mode = fabmap::FabmapMode::kWifi;
  o.sensors.fabmap.front_end.recency_s = 20.0;
  o.sensors.fabmap.front_end.wifi_learning = learning;
  o.sensors.fabmap.front_end.online_first_scans = 10;
  return o;
}

// Replays `data` with the FABMAP Wi-Fi front end; returns the frames' decisions.
std::vector<FrameRecord> FabmapFrames(const dataset::Dataset& data, WifiLearning learning,
                                      std::optional<FabmapLearningReport>* report = nullptr) {
  NoImages images;
  const PipelineOptions options = FabmapWifiOptions(learning);
  auto resources = PrepareFabmapResources(options.sensors, data, std::nullopt);
  EXPECT_TRUE(resources.ok()) << resources.status().message();
  ReplayPipeline pipeline(options, data, &images, *resources);
  EXPECT_TRUE(pipeline.Run({}).ok());
  if (report) *report = pipeline.fabmap_learning();
  return pipeline.state().frames;
}

bool SameDecisions(const std::vector<FrameRecord>& a, const std::vector<FrameRecord>& b,
                   size_t count) {
  for (size_t i = 0; i < count; ++i) {
    if (a[i].template_id != b[i].template_id || a[i].is_new != b[i].is_new ||
        a[i].recent != b[i].recent) {
      return false;
    }
  }
  return true;
}

// Online learning is causal: the decisions up to time T are the same whether the data set ends
// at T or goes on. Whole-data-set learning sees the future, and its early decisions change when
// later scans are added (the test checks that too, so that it can fail).
TEST(ReplayPipelineTest, OnlineFabmapLearningNeverUsesFutureScans) {
  dataset::Dataset whole = ApLoop();
  dataset::Dataset first_lap = whole;
  // In the second lap the building changed: six new access points are heard everywhere and two
  // old ones are gone. A model that saw those scans differs from one that did not.
  for (WifiScan& scan : whole.wifi) {
    if (scan.time_s < 80.0) continue;
    std::erase_if(scan.readings,
                  [](const WifiReading& r) { return r.bssid == "ap3" || r.bssid == "ap9"; });
    for (int k = 0; k < 6; ++k) scan.readings.push_back({"new" + std::to_string(k), -70.0 + k});
  }
  const double cut_s = 70.0;
  std::erase_if(first_lap.wifi, [&](const WifiScan& s) { return s.time_s > cut_s; });
  std::erase_if(first_lap.odometry, [&](const OdometryRow& r) { return r.time_s > cut_s; });
  first_lap.images.clear();

  std::optional<FabmapLearningReport> report;
  const auto online_whole = FabmapFrames(whole, WifiLearning::kOnline, &report);

  const auto online_cut = FabmapFrames(first_lap, WifiLearning::kOnline);
  ASSERT_EQ(online_cut.size(), first_lap.wifi.size());
  EXPECT_TRUE(SameDecisions(online_whole, online_cut, online_cut.size()));
  ASSERT_TRUE(report.has_value());
  EXPECT_EQ(report->wifi_learning, WifiLearning::kOnline);
  // 80 scans: models after 10, 20, 40 and 80 scans.
  EXPECT_EQ(report->wifi_learned_from_scans, 80u);
  EXPECT_EQ(report->wifi_relearnt, 4u);
  // The second lap re-matches places of the first.
  EXPECT_TRUE(std::any_of(online_whole.begin() + online_cut.size(), online_whole.end(),
                          [](const FrameRecord& f) { return !f.is_new && !f.recent; }));

  const auto batch_whole = FabmapFrames(whole, WifiLearning::kWholeDataSet, &report);
  const auto batch_cut = FabmapFrames(first_lap, WifiLearning::kWholeDataSet);
  EXPECT_FALSE(SameDecisions(batch_whole, batch_cut, batch_cut.size()))
      << "whole-data-set learning should depend on later scans here";
  EXPECT_EQ(report->wifi_learned_from_scans, whole.wifi.size());
}

TEST(ReplayPipelineTest, StopAndResumeEqualsOneRunForOnlineFabmapLearning) {
  const dataset::Dataset data = ApLoop();
  NoImages images;
  const PipelineOptions options = FabmapWifiOptions(WifiLearning::kOnline);
  auto resources = PrepareFabmapResources(options.sensors, data, std::nullopt);
  ASSERT_TRUE(resources.ok());
  ReplayPipeline whole(options, data, &images, *resources);
  ASSERT_TRUE(whole.Run({}).ok());
  ReplayPipeline first(options, data, &images, *resources);
  ReplayControl half;
  half.until_time_s = 100.0;  // after the model of 40 scans, before the one of 80
  ASSERT_TRUE(first.Run(half).ok());
  ReplayPipeline second(options, data, &images, *resources);
  ASSERT_TRUE(second.Restore(first.Snapshot()).ok());
  ASSERT_TRUE(second.Run({}).ok());
  EXPECT_TRUE(
      SameDecisions(whole.state().frames, second.state().frames, whole.state().frames.size()));
  EXPECT_EQ(whole.Snapshot().front_end, second.Snapshot().front_end);
  EXPECT_EQ(second.fabmap_learning()->wifi_relearnt, whole.fabmap_learning()->wifi_relearnt);
}

}  // namespace
}  // namespace ratslam::fusion

namespace ratslam::fusion {
namespace {

PipelineOptions SequenceOptions(FrontEndKind kind) {
  PipelineOptions o = WifiOptions();
  o.sensors.front_end.kind = kind;
  o.wifi_sequence.enabled = true;
  return o;
}

TEST(ReplayPipelineWifiSequenceTest, SequenceLoopClosureAloneLinksTheSecondLapToTheFirst) {
  const dataset::Dataset data = SquareLoop();
  NoImages images;
  ReplayPipeline pipeline(SequenceOptions(FrontEndKind::kNone), data, &images);
  ASSERT_TRUE(pipeline.Run({}).ok());
  EXPECT_EQ(pipeline.slam().counters().loop_closures, 0u);  // nothing by appearance
  EXPECT_EQ(pipeline.wifi_sequence().size(), data.wifi.size());
  size_t sequence_links = 0;
  for (const Link& l : pipeline.slam().experience_map().links()) {
    if (!l.wifi_sequence) continue;
    ++sequence_links;
    // A link joins places one lap (80 s) apart, give or take two scans (a DP pair may be a scan
    // off, and a scan's experience is the one made before it).
    const auto& e = pipeline.slam().experience_map().experiences();
    EXPECT_NEAR(std::abs(e[l.to].time_s - e[l.from].time_s), 80.0, 4.5);
    EXPECT_TRUE(l.loop_closure);
    // Odometry is exact here, so whatever the pair, the link must put `to` where it truly is
    // seen from `from` (the fit's relative pose, not "the same place").
    const Experience& from = e[l.from];
    const double x = from.x_m + l.distance_m * std::cos(from.theta_rad + l.heading_rad);
    const double y = from.y_m + l.distance_m * std::sin(from.theta_rad + l.heading_rad);
    EXPECT_NEAR(x, e[l.to].x_m, 0.3);
    EXPECT_NEAR(y, e[l.to].y_m, 0.3);
  }
  EXPECT_GE(sequence_links, 5u);
}

TEST(ReplayPipelineWifiSequenceTest, StopAndResumeEqualsOneRun) {
  const dataset::Dataset data = SquareLoop();
  NoImages images;
  const PipelineOptions options = SequenceOptions(FrontEndKind::kFused);
  ReplayPipeline whole(options, data, &images);
  ASSERT_TRUE(whole.Run({}).ok());
  for (double cut_s : {60.0, 110.0, 150.0}) {
    ReplayPipeline first(options, data, &images);
    ReplayControl half;
    half.until_time_s = cut_s;
    ASSERT_TRUE(first.Run(half).ok());
    ReplayPipeline second(options, data, &images);
    ASSERT_TRUE(second.Restore(first.Snapshot()).ok());
    ASSERT_TRUE(second.Run({}).ok());
    const auto& a = whole.slam().experience_map();
    const auto& b = second.slam().experience_map();
    ASSERT_EQ(a.num_links(), b.num_links()) << "cut at " << cut_s;
    for (size_t i = 0; i < a.num_experiences(); ++i) {
      EXPECT_EQ(a.experiences()[i].x_m, b.experiences()[i].x_m);
      EXPECT_EQ(a.experiences()[i].y_m, b.experiences()[i].y_m);
    }
    ASSERT_EQ(whole.wifi_sequence().loops().size(), second.wifi_sequence().loops().size());
    for (size_t l = 0; l < whole.wifi_sequence().loops().size(); ++l) {
      EXPECT_EQ(whole.wifi_sequence().loops()[l].dp_cost,
                second.wifi_sequence().loops()[l].dp_cost);
    }
  }
}

TEST(ReplayPipelineWifiSequenceTest, RestoreRefusesAPoseAnchoredToAMissingExperience) {
  const dataset::Dataset data = SquareLoop();
  NoImages images;
  const PipelineOptions options = SequenceOptions(FrontEndKind::kNone);
  ReplayPipeline pipeline(options, data, &images);
  ReplayControl half;
  half.until_time_s = 60.0;
  ASSERT_TRUE(pipeline.Run(half).ok());
  ReplayPipeline::State s = pipeline.Snapshot();
  ASSERT_FALSE(s.wifi_sequence.poses.empty());
  s.wifi_sequence.poses.back().anchor = 100000;
  ReplayPipeline other(options, data, &images);
  EXPECT_FALSE(other.Restore(s).ok());
}

}  // namespace
}  // namespace ratslam::fusion

namespace ratslam::fusion {
namespace {

TEST(ReplayPipelineWifiSequenceTest, RunsBesideTheFabmapFrontEnd) {
  const dataset::Dataset data = SquareLoop();
  NoImages images;
  PipelineOptions options = FabmapWifiOptions(WifiLearning::kOnline);
  options.wifi_sequence.enabled = true;
  auto resources = PrepareFabmapResources(options.sensors, data, std::nullopt);
  ASSERT_TRUE(resources.ok()) << resources.status().message();
  ReplayPipeline pipeline(options, data, &images, *resources);
  ASSERT_TRUE(pipeline.Run({}).ok());
  // Every scan is a pose of the loop closer whatever the front end decides, and the second lap
  // is matched against the first.
  EXPECT_EQ(pipeline.wifi_sequence().size(), data.wifi.size());
  EXPECT_GE(pipeline.wifi_sequence().loops().size(), 1u);
  for (const wifi_sequence::SequencePose& p : pipeline.wifi_sequence().state().poses) {
    EXPECT_LT(p.anchor, static_cast<int64_t>(pipeline.slam().experience_map().num_experiences()));
  }
}

}  // namespace
}  // namespace ratslam::fusion

namespace ratslam::fusion {
namespace {

// Sequence recognition needs a front end that takes camera frames.
TEST(PipelineOptionsTest, SequenceRecognitionNeedsACameraFrontEnd) {
  PipelineOptions o;
  o.sensors.sequence.recognise_views = true;
  std::string error;
  EXPECT_TRUE(o.IsValid(&error)) << error;  // classic camera
  o.sensors.front_end.kind = FrontEndKind::kFused;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("sequence.recognise_views"), std::string::npos) << error;
  o.sensors.fused.use_camera = true;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  o.sensors.front_end.kind = FrontEndKind::kFabmap;
  EXPECT_FALSE(o.IsValid(&error));
}

}  // namespace
}  // namespace ratslam::fusion
