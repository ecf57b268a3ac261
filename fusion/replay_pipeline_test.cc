#include "fusion/replay_pipeline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace ratslam {
namespace {

// Two laps of a 20 m square at 1 m/s: odometry at 10 Hz, a Wi-Fi scan every 2 s from four access
// points whose RSSI falls with distance (so the second lap re-matches the first lap's places),
// and a camera image every second that the Wi-Fi-only front end must skip.
Dataset SquareLoop() {
  Dataset d;
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
  const Dataset data = SquareLoop();
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
  const Dataset data = SquareLoop();
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
  const Dataset data = SquareLoop();
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
  const Dataset data = SquareLoop();
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

TEST(ReplayPipelineTest, RestoreRefusesStatesThatDoNotFit) {
  const Dataset data = SquareLoop();
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

}  // namespace
}  // namespace ratslam
