#include "viewer/figures.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "render/image.h"
#include "render/renderer.h"
#include "render/vector_figure.h"
#include "viewer/run_images.h"

namespace ratslam::viewer {
namespace {

TEST(NiceStepTest, PicksOneTwoFive) {
  EXPECT_DOUBLE_EQ(NiceStep(100, 10), 10);
  EXPECT_DOUBLE_EQ(NiceStep(37, 8), 5);
  EXPECT_DOUBLE_EQ(NiceStep(0.9, 5), 0.2);
}

// Two walks on floor -2, each starting a minute before its first ground-truth point (a phone's
// calibration): experiences made in those minutes have no measured position but belong to the
// walk's floor, not to a floor 0 the building may not have.
TEST(ExperienceFloorsTest, ExperiencesWithoutTruthTakeTheNearestPointsFloor) {
  dataset::Dataset d;
  d.session_start_times_s = {0.0, 100.0};
  d.ground_truth = {
      {60.0, 0, 0, 0, -2}, {90.0, 5, 0, 0, -2}, {160.0, 0, 0, 0, -1}, {190.0, 5, 0, 0, -1}};
  std::vector<Experience> ex(6);
  const double times[] = {10.0, 70.0, 95.0, 130.0, 170.0, 250.0};
  for (size_t i = 0; i < ex.size(); ++i) ex[i].time_s = times[i];
  const std::vector<int> floors = ExperienceFloors(ex, d);
  EXPECT_EQ(floors, (std::vector<int>{-2, -2, -2, -1, -1, -1}));
  EXPECT_EQ(ExperienceFloors(ex, dataset::Dataset{}), std::vector<int>(6, 0));
}

TEST(SequentialColorTest, LightnessRisesMonotonically) {
  double previous = -1;
  for (int i = 0; i <= 100; ++i) {
    const render::Rgba c = SequentialColor(i / 100.0);
    const double lightness = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
    EXPECT_GE(lightness, previous - 1e-9) << i;
    previous = lightness;
  }
}

Experience At(uint32_t id, double x, double y, double theta = 0.0) {
  Experience e;
  e.id = id;
  e.x_m = x;
  e.y_m = y;
  e.theta_rad = theta;
  e.time_s = id;
  return e;
}

// Three experiences on an L: (0,0), (20,0), (20,10).
ExperienceMapImageData LMap() {
  ExperienceMapImageData data;
  data.experiences = {At(0, 0, 0), At(1, 20, 0), At(2, 20, 10, M_PI / 2)};
  Link a;
  a.id = 0;
  a.from = 0;
  a.to = 1;
  Link b = a;
  b.id = 1;
  b.from = 1;
  b.to = 2;
  data.links = {a, b};
  return data;
}

TEST(ExperienceMapSceneTest, EqualAspectAndYUp) {
  WorldToImage t;
  ExperienceMapScene(LMap(), {}, &t);
  const render::ScenePoint origin = t(0, 0), east = t(20, 0), north = t(20, 10);
  // 20 m along x spans twice the pixels of 10 m along y: equal scale on both axes.
  EXPECT_NEAR(east.x - origin.x, 2.0 * (east.y - north.y), 1e-3);
  EXPECT_GT(east.x, origin.x);
  EXPECT_LT(north.y, east.y) << "larger world y must be higher in the image";
}

TEST(AlignGroundTruthToMapTest, RotatedTruthLandsOnTheMap) {
  const std::vector<Point2> map = {{0, 0}, {10, 0}, {10, 5}};
  std::vector<Point2> truth;
  for (const Point2& p : map) truth.push_back({-p.y + 3, p.x - 1});  // rotated 90 deg, moved
  const std::vector<Point2> aligned = AlignGroundTruthToMap(map, truth, truth);
  ASSERT_EQ(aligned.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(aligned[i].x, map[i].x, 1e-9);
    EXPECT_NEAR(aligned[i].y, map[i].y, 1e-9);
  }
}

// Rendered: nodes appear at the pixels the transform gives, the right way up.
TEST(ExperienceMapSceneTest, RenderedNodesAreWhereTheWorldSays) {
  StatusOr<std::unique_ptr<render::SceneRenderer>> renderer = render::CreateOsMesaRenderer();
  if (!renderer.ok()) GTEST_SKIP() << "OSMesa unavailable: " << renderer.status().message();
  ExperienceMapImageOptions options;
  options.width_px = 400;
  options.height_px = 300;
  WorldToImage t;
  const render::Scene scene = ExperienceMapScene(LMap(), options, &t);
  StatusOr<render::RgbaImage> image = renderer.value()->Render(scene);
  ASSERT_TRUE(image.ok()) << image.status().message();
  auto is_ink = [&](render::ScenePoint p) {
    const render::Rgba c =
        image->At(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)));
    return c.r + c.g + c.b < 600;
  };
  EXPECT_TRUE(is_ink(t(0, 0)));
  EXPECT_TRUE(is_ink(t(20, 0)));
  EXPECT_TRUE(is_ink(t(20, 10)));
  EXPECT_TRUE(is_ink(t(10, 0)));   // on the first link
  EXPECT_FALSE(is_ink(t(5, 8)));   // empty corner of the L
  EXPECT_FALSE(is_ink(t(0, 10)));  // mirrored position of node 2: would be inked if upside down
}

// Two floors: two panels at one scale in the figure's size, under one title, with one legend;
// each shows only its own floor's experiences.
TEST(ExperienceMapByFloorTest, OnePanelPerFloorOneLegend) {
  StatusOr<std::unique_ptr<render::SceneRenderer>> renderer = render::CreateOsMesaRenderer();
  if (!renderer.ok()) GTEST_SKIP() << "OSMesa unavailable: " << renderer.status().message();
  ExperienceMapImageData data = LMap();  // (0,0) and (20,0) on floor 0, (20,10) on floor 1
  data.links[0].loop_closure = true;
  ExperienceMapImageOptions options;
  options.width_px = 800;
  options.height_px = 400;
  options.title = "the run";
  FloorPanels layout;
  const render::Scene scene = ExperienceMapFloorsScene(data, {0, 0, 1}, {}, options, 0, &layout);
  EXPECT_EQ(scene.width(), 800);
  EXPECT_EQ(scene.height(), 400);
  // A 20 m x 10 m map in 800 x 400: side by side draws it larger than stacked.
  ASSERT_EQ(layout.columns, 2);
  EXPECT_EQ(layout.floors, (std::vector<int>{0, 1}));
  auto count = [&](const std::string& text) {
    return std::count_if(scene.texts().begin(), scene.texts().end(),
                         [&](const render::SceneText& t) { return t.text == text; });
  };
  EXPECT_EQ(count("the run"), 1);
  EXPECT_EQ(count("floor 0"), 1);
  EXPECT_EQ(count("floor 1"), 1);
  EXPECT_EQ(count("loop closure"), 1);  // one legend, though floor 1 has no loop closure
  // A tall map stacks its panels.
  FloorPanels tall;
  ExperienceMapImageOptions narrow;
  narrow.width_px = 400;
  narrow.height_px = 800;
  ExperienceMapFloorsScene(data, {0, 0, 1}, {}, narrow, 0, &tall);
  EXPECT_EQ(tall.columns, 1);

  StatusOr<render::RgbaImage> image = renderer.value()->Render(scene);
  ASSERT_TRUE(image.ok()) << image.status().message();
  // Both panels share the full map's view, so a world point maps to the same offset in each.
  ExperienceMapImageOptions panel;
  panel.width_px = layout.panel_width_px;
  panel.height_px = layout.panel_height_px;
  panel.bounds = WorldBounds{0, 0, 20, 10};
  WorldToImage t;
  ExperienceMapScene(data, panel, &t);
  auto ink = [&](render::ScenePoint p, int k) {
    const render::Rgba c = image->At(static_cast<int>(std::lround(p.x)) + layout.panel_width_px * k,
                                     static_cast<int>(std::lround(p.y)) + layout.top_px);
    return c.r + c.g + c.b < 600;
  };
  EXPECT_TRUE(ink(t(0, 0), 0));
  EXPECT_FALSE(ink(t(0, 0), 1));
  EXPECT_TRUE(ink(t(20, 10), 1));
  EXPECT_FALSE(ink(t(20, 10), 0));
}

// A title too long for its width is set smaller, then elided in the middle; a short one is kept.
TEST(FittedTitleTest, ShrinksThenElidesTheMiddle) {
  render::Scene scene(400, 100, {255, 255, 255, 255});
  FittedTitle(scene, {10, 20}, "short", 18, 380);
  const std::string name = "experience map (IPIN2023_T3_TrainingTrial51_repetition02, run 7)";
  FittedTitle(scene, {10, 40}, name, 18, 380);
  ASSERT_EQ(scene.texts().size(), 2u);
  EXPECT_EQ(scene.texts()[0].text, "short");
  EXPECT_EQ(scene.texts()[0].height_px, 18);
  const render::SceneText& t = scene.texts()[1];
  EXPECT_EQ(t.height_px, 13);
  EXPECT_LE(render::TextWidthPx(t.text, t.height_px), 380);
  EXPECT_NE(t.text.find("..."), std::string::npos);
  EXPECT_EQ(t.text.substr(0, 15), "experience map ");  // the start and the end survive
  EXPECT_EQ(t.text.substr(t.text.size() - 6), "run 7)");
}

// With two lines allowed, a title too long for a column breaks at a space into two lines that
// both fit, losing nothing; the figure's content moves down by the second line.
TEST(FittedTitleTest, TwoLinesKeepTheWholeTitle) {
  const std::string name =
      "template graph (IPIN2023_T3_TrainingTrial51_repetition02 +3 sessions, walking)";
  // A column's width (88 mm) as the vector figures lay it out.
  const float width = render::VectorLayoutWidthPx(88.0) - 40.0f;
  const FittedText one = FitTitle(name, 18, width);
  ASSERT_EQ(one.lines.size(), 1u);
  EXPECT_NE(one.lines[0].find("..."), std::string::npos);
  const FittedText two = FitTitle(name, 18, width, 2);
  ASSERT_EQ(two.lines.size(), 2u);
  EXPECT_EQ(two.lines[0] + " " + two.lines[1], name);
  for (const std::string& line : two.lines)
    EXPECT_LE(render::TextWidthPx(line, two.height_px), width);
  EXPECT_GE(two.height_px, one.height_px);
  EXPECT_GT(two.ExtraHeightPx(), 0);
  EXPECT_EQ(FitTitle("short", 18, width, 2).lines.size(), 1u);

  std::vector<TemplateGraphPoint> points = {{0, 0, 0, DecisionSource::kNew},
                                            {30, 1, 1, DecisionSource::kNew}};
  TemplateGraphImageOptions options;
  options.width_px = render::VectorLayoutWidthPx(88.0);
  options.title = name;
  const render::Scene scene = TemplateGraphScene(points, options);
  float title_bottom = 0, legend_top = 1e9;
  std::string drawn;
  for (const render::SceneText& t : scene.texts()) {
    if (name.find(t.text) != std::string::npos && t.text.size() > 10) {
      drawn += (drawn.empty() ? "" : " ") + t.text;
      title_bottom = std::max(title_bottom, t.position.y);
    }
    if (t.text == "new template") legend_top = t.position.y;
  }
  EXPECT_EQ(drawn, name);
  EXPECT_GT(legend_top - 14, title_bottom);  // the legend's text sits below the title's
}

// A template's later matches (rings) start a second after it was made: the dot of the new
// template is drawn over them, where it stays visible, not under them.
TEST(TemplateGraphSceneTest, NewTemplatesAreDrawnOverTheirMatches) {
  std::vector<TemplateGraphPoint> points;
  for (int i = 0; i < 20; ++i) {
    points.push_back({static_cast<double>(i), static_cast<uint32_t>(i / 5), i / 5,
                      i % 5 == 0 ? DecisionSource::kNew : DecisionSource::kWifi});
  }
  const render::Scene scene = TemplateGraphScene(points, {});
  const render::Rgba new_color = {70, 70, 70, 255};
  auto is_new_dot = [&](const render::SceneShape& s) {
    return s.kind == render::SceneShape::Kind::kDisc && s.color.r == new_color.r &&
           s.color.g == new_color.g && s.color.b == new_color.b;
  };
  size_t last_ring = 0, first_dot = scene.shapes().size(), dots = 0;
  for (size_t i = 0; i < scene.shapes().size(); ++i) {
    const render::SceneShape& s = scene.shapes()[i];
    if (s.kind == render::SceneShape::Kind::kRing && s.points[0].y > 100) last_ring = i;
    if (is_new_dot(s) && s.points[0].y > 100) {
      first_dot = std::min(first_dot, i);
      ++dots;
    }
  }
  EXPECT_EQ(dots, 4u);  // one per template (the legend's sits above the plots)
  EXPECT_GT(first_dot, last_ring);
}

// The session legend reads the sessions' names, not their numbers.
TEST(ExperienceMapSceneTest, SessionLegendNamesTheSessions) {
  ExperienceMapImageOptions options;
  options.coloring = MapColoring::kSession;
  options.session_start_times_s = {0.0, 1.5};
  options.session_names = {"day", "night"};
  const render::Scene scene = ExperienceMapScene(LMap(), options);
  std::set<std::string> texts;
  for (const render::SceneText& t : scene.texts()) texts.insert(t.text);
  EXPECT_TRUE(texts.count("day") && texts.count("night"));
  EXPECT_FALSE(texts.count("session 1"));
  options.session_names.clear();
  std::set<std::string> numbered;
  const render::Scene unnamed = ExperienceMapScene(LMap(), options);
  for (const render::SceneText& t : unnamed.texts()) numbered.insert(t.text);
  EXPECT_TRUE(numbered.count("session 1") && numbered.count("session 2"));
}

TEST(TemplateGraphSceneTest, EmptyInputStillGivesAFigure) {
  const render::Scene scene = TemplateGraphScene({}, {});
  EXPECT_EQ(scene.width(), 1600);
  EXPECT_FALSE(scene.texts().empty());
}

// Template ids and experience ids are nearly equal in a camera run; on one axis the experience
// dots hid under the template circles. Now each has its own panel: no dot sits on a circle.
TEST(TemplateGraphSceneTest, ExperienceIdsDoNotHideUnderTemplateIds) {
  std::vector<TemplateGraphPoint> points;
  for (uint32_t i = 0; i < 40; ++i) points.push_back({double(i), i, i, DecisionSource::kCamera});
  const render::Scene scene = TemplateGraphScene(points, {});
  std::vector<render::ScenePoint> circles, dots;
  for (const render::SceneShape& s : scene.shapes()) {
    if (s.kind == render::SceneShape::Kind::kRing && s.radius_px < 10)
      circles.push_back(s.points[0]);
    if (s.kind == render::SceneShape::Kind::kDisc && s.color.r == 230 && s.color.g == 110) {
      dots.push_back(s.points[0]);
    }
  }
  ASSERT_EQ(circles.size(), 40u + 1u);  // and the legend's
  ASSERT_EQ(dots.size(), 40u + 1u);     // and the legend's
  for (const render::ScenePoint& c : circles) {
    for (const render::ScenePoint& d : dots) {
      EXPECT_GT(std::hypot(c.x - d.x, c.y - d.y), 8.0f) << c.x << "," << c.y;
    }
  }
}

// Adjacent spans (sessions, day and night) get different shades, so their border shows.
TEST(TemplateGraphSceneTest, AdjacentSpansHaveDifferentShades) {
  std::vector<TemplateGraphPoint> points = {{0, 0, 0, DecisionSource::kNew},
                                            {30, 1, 1, DecisionSource::kNew}};
  TemplateGraphImageOptions options;
  options.shaded_spans = {{0, 10, "a"}, {10, 20, "b"}, {20, 30, "c"}};
  const render::Scene scene = TemplateGraphScene(points, options);
  std::vector<render::Rgba> shades;  // per panel, in order: a, a, b, b, c, c
  for (const render::SceneShape& s : scene.shapes()) {
    if (s.kind == render::SceneShape::Kind::kRect && s.color.a == 110) shades.push_back(s.color);
  }
  ASSERT_EQ(shades.size(), 6u);
  auto same = [](render::Rgba x, render::Rgba y) { return x.r == y.r && x.g == y.g && x.b == y.b; };
  EXPECT_FALSE(same(shades[0], shades[2]));
  EXPECT_FALSE(same(shades[2], shades[4]));
  EXPECT_TRUE(same(shades[0], shades[1]));  // one span, one shade in both panels

  // Labels wider than their spans lose their middles and never overlap.
  options.width_px = 600;
  options.shaded_spans = {{0, 15, "IPIN2023_T3_TrainingTrial01_repetition01"},
                          {15, 30, "IPIN2023_T3_TrainingTrial01_repetition02"}};
  const render::Scene narrow = TemplateGraphScene(points, options);
  std::vector<const render::SceneText*> labels;
  for (const render::SceneText& t : narrow.texts()) {
    if (t.text.find("...") != std::string::npos) labels.push_back(&t);
  }
  ASSERT_EQ(labels.size(), 2u);
  EXPECT_EQ(labels[0]->text.substr(labels[0]->text.size() - 2), "01");
  EXPECT_EQ(labels[1]->text.substr(labels[1]->text.size() - 2), "02");
  const float right_of_first = labels[0]->position.x + render::TextWidthPx(labels[0]->text, 14) / 2;
  const float left_of_second = labels[1]->position.x - render::TextWidthPx(labels[1]->text, 14) / 2;
  EXPECT_LT(right_of_first, left_of_second);
}

// Session and curve colours never read as the loop-closure red (220, 50, 32): in multi-session
// maps the second session was drawn in a red two units from it.
TEST(CategoryColorTest, NoCategoryLooksLikeTheLoopClosureRed) {
  for (int i = 0; i < 16; ++i) {
    const render::Rgba c = CategoryColor(i);
    const double distance =
        std::sqrt(std::pow(c.r - 220.0, 2) + std::pow(c.g - 50.0, 2) + std::pow(c.b - 32.0, 2));
    EXPECT_GT(distance, 80.0) << "category " << i;  // the old red was 16 away
  }
}

}  // namespace
}  // namespace ratslam::viewer
