#include "viewer/sweep_figures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "render/image.h"

namespace ratslam::viewer {
namespace {

bool HasText(const render::Scene& scene, const std::string& text) {
  return std::any_of(scene.texts().begin(), scene.texts().end(),
                     [&](const render::SceneText& t) { return t.text == text; });
}

// Two parameters of two values each, and a third that the heat map takes the best over.
SweepFigureData Example() {
  SweepFigureData d;
  d.title = "t";
  d.objective = "ate";
  d.keys = {"a", "b", "c"};
  d.points = {{{"1", "x", "0"}, 4.0, 1.0},
              {{"1", "x", "1"}, 3.0, 2.0},
              {{"2", "x", "0"}, 2.5, 1.0},
              {{"1", "y", "0"}, 7.0, 1.0},
              {{"2", "y", "0"}, std::nullopt, 1.0}};
  d.best = 2;
  return d;
}

// The colour bar is the rectangles furthest right: bright (the cells' colour for good values) at
// the better end, higher values up, labelled at the sweep's worst and best values beside it.
TEST(SweepFiguresTest, HeatmapHasAColourBarBrightAtTheBetterEnd) {
  for (bool minimize : {true, false}) {
    SweepFigureData data = Example();
    data.minimize = minimize;
    const render::Scene scene = SweepHeatmapScene(data, 0, 1);
    float bar_left = 0;
    for (const render::SceneShape& s : scene.shapes()) {
      if (s.kind == render::SceneShape::Kind::kRect) bar_left = std::max(bar_left, s.points[0].x);
    }
    std::vector<const render::SceneShape*> bar;
    for (const render::SceneShape& s : scene.shapes()) {
      if (s.kind == render::SceneShape::Kind::kRect && s.points[0].x == bar_left) bar.push_back(&s);
    }
    ASSERT_GE(bar.size(), 16u);
    std::sort(bar.begin(), bar.end(),
              [](auto* a, auto* b) { return a->points[0].y < b->points[0].y; });
    auto brightness = [](const render::Rgba& c) { return c.r + c.g + c.b; };
    const int top = brightness(bar.front()->color), bottom = brightness(bar.back()->color);
    if (minimize) {
      EXPECT_GT(bottom, top) << "lower values are better: bright at the bottom";
    } else {
      EXPECT_GT(top, bottom) << "higher values are better: bright at the top";
    }
    // Labels at the worst and best values (2.5 and 7), right of the bar, 7 above 2.5.
    std::optional<float> y_low, y_high;
    for (const render::SceneText& t : scene.texts()) {
      if (t.position.x <= bar_left) continue;
      if (t.text == "2.5") y_low = t.position.y;
      if (t.text == "7") y_high = t.position.y;
    }
    ASSERT_TRUE(y_low && y_high);
    EXPECT_LT(*y_high, *y_low);
  }
}

TEST(SweepFiguresTest, HeatmapCellsHoldTheBestOverTheOtherParameters) {
  const render::Scene scene = SweepHeatmapScene(Example(), 0, 1);
  EXPECT_TRUE(HasText(scene, "3"));    // a=1, b=x: min(4, 3)
  EXPECT_TRUE(HasText(scene, "2.5"));  // a=2, b=x
  EXPECT_TRUE(HasText(scene, "7"));    // a=1, b=y
  EXPECT_FALSE(HasText(scene, "4"));   // beaten in its cell
  SweepFigureData maximise = Example();
  maximise.minimize = false;
  EXPECT_TRUE(HasText(SweepHeatmapScene(maximise, 0, 1), "4"));
}

TEST(SweepFiguresTest, EveryParameterGetsAPanelWithItsValues) {
  const render::Scene scene = SweepParameterScene(Example());
  for (const char* text : {"a", "b", "c", "x", "y"}) EXPECT_TRUE(HasText(scene, text)) << text;
  EXPECT_GT(scene.triangles().size(), 0u);
}

// The value axis is titled with the objective and the unit its name ends in (the plots had no
// y-axis label).
TEST(SweepFiguresTest, TheValueAxisNamesTheObjectiveAndItsUnit) {
  SweepFigureData d = Example();
  d.objective = "map_ate_m";
  EXPECT_TRUE(HasText(SweepParameterScene(d), "map_ate_m (m)"));
  EXPECT_TRUE(HasText(SweepParetoScene(d), "map_ate_m (m)"));
  d.objective = "mean map_ate_m";
  EXPECT_TRUE(HasText(SweepParameterScene(d), "mean map_ate_m (m)"));
  d.objective = "match_rate_within_m.5";
  EXPECT_TRUE(HasText(SweepParameterScene(d), "match_rate_within_m.5"));
  d.objective = "map_ate_m + 0.05 * templates";
  EXPECT_TRUE(HasText(SweepParetoScene(d), "map_ate_m + 0.05 * templates"));
}

// Parameter values close together on a numeric axis (a log-odds grid from -40 to 5) get a tick
// each but labels that never overlap: the labels once ran together into "-10.0-5.0-2.00.0".
TEST(SweepFiguresTest, ParameterLabelsNeverOverlap) {
  SweepFigureData d;
  d.title = "t";
  d.objective = "ate";
  d.keys = {"threshold"};
  const std::vector<std::string> values = {"-40.0", "-20.0", "-10.0", "-5.0",
                                           "-2.0",  "0.0",   "2.0",   "5.0"};
  for (size_t i = 0; i < values.size(); ++i) {
    d.points.push_back({{values[i]}, 10.0 - static_cast<double>(i), 1.0});
  }
  d.best = 0;
  const render::Scene scene = SweepParameterScene(d);
  std::vector<std::pair<float, float>> spans;  // the drawn value labels, left to right
  for (const render::SceneText& t : scene.texts()) {
    if (std::find(values.begin(), values.end(), t.text) == values.end()) continue;
    const float half = render::TextWidthPx(t.text, t.height_px) / 2;
    spans.emplace_back(t.position.x - half, t.position.x + half);
  }
  std::sort(spans.begin(), spans.end());
  ASSERT_GE(spans.size(), 4u);  // the sparse end keeps its labels
  for (size_t i = 1; i < spans.size(); ++i) {
    EXPECT_LT(spans[i - 1].second, spans[i].first) << "labels " << i - 1 << " and " << i;
  }
  EXPECT_TRUE(HasText(scene, "-40.0"));
  EXPECT_TRUE(HasText(scene, "-20.0"));
  // Every value keeps its tick: the short vertical lines below the panel.
  size_t ticks = 0;
  for (const render::SceneShape& shape : scene.shapes()) {
    if (shape.kind == render::SceneShape::Kind::kLine && shape.points.size() == 2 &&
        shape.points[0].x == shape.points[1].x && shape.points[1].y - shape.points[0].y == 5.0f) {
      ++ticks;
    }
  }
  EXPECT_EQ(ticks, values.size());
}

// A tick at zero reads "0", never "-0" (a sum of steps landing a hair below zero).
TEST(SweepFiguresTest, NoTickReadsMinusZero) {
  SweepFigureData d = Example();
  for (SweepFigurePoint& p : d.points) {
    if (p.objective) *p.objective -= 2.2;  // -0.2 .. 4.8: ticks step through zero
  }
  const render::Scene scene = SweepParameterScene(d);
  EXPECT_FALSE(HasText(scene, "-0"));
  EXPECT_TRUE(HasText(scene, "0"));
}

}  // namespace
}  // namespace ratslam::viewer
