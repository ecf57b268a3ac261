#include "io/run_outputs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace ratslam::io {
namespace {

// Truth along a line at 1 m/s; the localised frames are the truth turned by 90 degrees and
// shifted (another frame), one of them 3 m off, one lost.
TEST(LocalisationErrorsTest, RigidFitThenDistanceAndNoFitToAHandful) {
  std::vector<GroundTruthRow> truth;
  for (int i = 0; i <= 20; ++i) truth.push_back({1.0 * i, 1.0 * i, 0.0, 0.0, 0});
  std::vector<LocalisationRecord> records;
  for (int i = 0; i < 20; ++i) {
    LocalisationRecord r;
    r.time_s = i + 0.5;
    r.x_m = 5.0;  // (x, y) -> (-y, x) + (5, 7)
    r.y_m = 7.0 + (i + 0.5);
    r.lost = false;
    records.push_back(r);
  }
  records[4].lost = true;
  records[12].x_m += 3.0;
  std::vector<Point2> true_at;
  const std::vector<double> errors = LocalisationErrors(records, truth, &true_at);
  ASSERT_EQ(errors.size(), records.size());
  EXPECT_TRUE(std::isnan(errors[4]));
  EXPECT_NEAR(true_at[4].x, 4.5, 1e-12);
  // The outlier pulls the least-squares fit a little: 3 m over 19 frames moves the centroid
  // 0.16 m and turns the line slightly, up to about 0.25 m at its ends.
  EXPECT_NEAR(errors[12], 3.0, 0.2);
  for (size_t i = 0; i < errors.size(); ++i) {
    if (i != 4 && i != 12) {
      EXPECT_LT(errors[i], 0.3) << i;
    }
  }
  // Nine localised frames: a fit would match them almost exactly, so no errors at all.
  records.resize(9);
  records[4].lost = false;
  for (double e : LocalisationErrors(records, truth)) EXPECT_TRUE(std::isnan(e));
  // Outside the ground truth: no truth, no error.
  records.resize(20, records[0]);
  for (LocalisationRecord& r : records) r.time_s += 100.0;
  for (double e : LocalisationErrors(records, truth, &true_at)) EXPECT_TRUE(std::isnan(e));
  EXPECT_TRUE(std::isnan(true_at[0].x));
}

}  // namespace
}  // namespace ratslam::io

namespace ratslam::io {
namespace {

// Two sessions photograph places a..e under the same names (the second also z, which the first
// never saw). Second-session frames: a on a's template (0 images apart), b on d's (2 apart), c a
// new template, d on d's (0 apart), z on b's (not scored: no namesake before). Four frames
// scored, three matched, correct within 0 and 1: two; within 2 and 5: three.
TEST(CrossSessionPlacesTest, ScoresByTheNamesakeInTheTemplatesSession) {
  dataset::Dataset d;
  d.session_start_times_s = {0.0, 100.0};
  const std::vector<std::string> names = {"a.png", "b.png", "c.png", "d.png", "e.png"};
  std::vector<FrameRecord> frames;
  for (int i = 0; i < 5; ++i) {
    d.images.push_back({1.0 + i, "/x/summer/" + names[i], i + 2});
    frames.push_back({1.0 + i, static_cast<uint32_t>(i), true, -1, DecisionSource::kNew, false});
  }
  const std::vector<std::pair<std::string, int>> later = {
      {"a.png", 0}, {"b.png", 3}, {"c.png", 5}, {"d.png", 3}, {"z.png", 1}};
  for (size_t i = 0; i < later.size(); ++i) {
    const double t = 101.0 + static_cast<double>(i);
    d.images.push_back({t, "/x/winter/" + later[i].first, static_cast<int>(i) + 2});
    const bool made = later[i].second == 5;
    frames.push_back({t, static_cast<uint32_t>(later[i].second), made, -1,
                      made ? DecisionSource::kNew : DecisionSource::kCamera, false});
  }
  const CrossSessionPlaces p = ScoreCrossSessionPlaces(frames, d);
  EXPECT_EQ(p.frames, 4u);
  EXPECT_EQ(p.matched, 3u);
  EXPECT_EQ(p.correct, (std::vector<size_t>{2, 2, 3, 3}));
  // A later image that gave no view (a blank frame) is a frame, not matched.
  d.images.push_back({110.0, "/x/winter/e.png", 9});
  const CrossSessionPlaces with_blank = ScoreCrossSessionPlaces(frames, d);
  EXPECT_EQ(with_blank.frames, 5u);
  EXPECT_EQ(with_blank.matched, 3u);
  EXPECT_EQ(with_blank.correct, p.correct);
  // One session: nothing to score.
  d.session_start_times_s = {0.0};
  EXPECT_EQ(ScoreCrossSessionPlaces(frames, d).frames, 0u);
}

}  // namespace
}  // namespace ratslam::io
