#include "viewer/figure_output.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "common/scratch_dir.h"
#include "ratslam/pose_cell_network.h"
#include "render/image.h"
#include "viewer/figures.h"
#include "viewer/localisation_figure.h"
#include "viewer/run_images.h"
#include "viewer/sweep_figures.h"

namespace ratslam::viewer {
namespace {

namespace fs = std::filesystem;

TEST(FigureFormatsTest, ParsesListsAndNamesWhatIsWrong) {
  StatusOr<std::vector<FigureFormat>> f = ParseFigureFormats("png,pdf,svg");
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(
      *f, (std::vector<FigureFormat>{FigureFormat::kPng, FigureFormat::kPdf, FigureFormat::kSvg}));
  EXPECT_NE(ParseFigureFormats("png,eps").status().message().find("'eps'"), std::string::npos);
  EXPECT_NE(ParseFigureFormats("pdf,pdf").status().message().find("twice"), std::string::npos);
  EXPECT_FALSE(ParseFigureFormats("").ok());
}

TEST(FigureFormatsTest, TargetsFollowTheExtensionOrTheList) {
  auto paths = [](const std::vector<FigureTarget>& targets) {
    std::vector<std::string> p;
    for (const FigureTarget& t : targets) p.push_back(t.path);
    return p;
  };
  EXPECT_EQ(FigureTargets("a/map.pdf", nullptr).front().format, FigureFormat::kPdf);
  EXPECT_EQ(FigureTargets("a/map.svg", nullptr).front().format, FigureFormat::kSvg);
  EXPECT_EQ(FigureTargets("a/map.png", nullptr).front().format, FigureFormat::kPng);
  EXPECT_EQ(FigureTargets("a/map", nullptr).front().path, "a/map");  // PNG, as named
  const std::vector<FigureFormat> both{FigureFormat::kPng, FigureFormat::kSvg};
  EXPECT_EQ(paths(FigureTargets("a/map.pdf", &both)),
            (std::vector<std::string>{"a/map.png", "a/map.svg"}));
  EXPECT_EQ(paths(FigureTargets("a/map", &both)),
            (std::vector<std::string>{"a/map.png", "a/map.svg"}));
  EXPECT_EQ(paths(FigureTargets("a/v1.2", &both)),  // not an extension of ours: kept
            (std::vector<std::string>{"a/v1.2.png", "a/v1.2.svg"}));
}

TEST(FigureOutputTest, VectorFiguresAreBuiltAtTheLayoutWidthWithThePngsAspect) {
  ScratchDir dir("figure_output");
  std::vector<std::pair<int, int>> sizes;
  const SceneBuilder build = [&](int w, int h) {
    sizes.push_back({w, h});
    render::Scene s(w, h, {255, 255, 255, 255});
    s.Text({10, 20}, "x", 13, {0, 0, 0, 255});
    return s;
  };
  const std::vector<FigureTarget> targets = {{FigureFormat::kPdf, (dir.path() / "f.pdf").string()},
                                             {FigureFormat::kSvg, (dir.path() / "f.svg").string()}};
  ASSERT_TRUE(WriteFigure(nullptr, build, 1600, 1200, targets, 88.0).ok());
  ASSERT_EQ(sizes.size(), 2u);
  EXPECT_EQ(sizes[0], (std::pair<int, int>{635, 476}));  // 635 x 1200 / 1600 = 476.25
  EXPECT_TRUE(fs::exists(dir.path() / "f.pdf"));
  EXPECT_TRUE(fs::exists(dir.path() / "f.svg"));
  // A PNG needs a renderer: without one the error names the file.
  const Status no_renderer =
      WriteFigure(nullptr, build, 100, 100, {{FigureFormat::kPng, "x.png"}}, 88.0);
  ASSERT_FALSE(no_renderer.ok());
  EXPECT_NE(no_renderer.message().find("x.png"), std::string::npos);
}

// Every figure laid out for a one-column (88 mm) or two-column (180 mm) page keeps its text at
// 7 pt or more: the figures' smallest text is what VectorLayoutWidthPx assumes.
TEST(FigureOutputTest, EveryFiguresTextIsAtLeastSevenPointsInPrint) {
  PoseCellOptions cells;
  cells.dim_xy_cells = 21;
  PoseCellNetwork network(cells);
  network.Reset({5.3, 7.6, 10.0});
  ExperienceMapImageData map;
  for (uint32_t i = 0; i < 20; ++i) {
    Experience e;
    e.id = i;
    e.x_m = i;
    e.y_m = (i * 7) % 5;
    e.time_s = i;
    map.experiences.push_back(e);
  }
  std::vector<TemplateGraphPoint> points;
  for (uint32_t i = 0; i < 50; ++i)
    points.push_back({double(i), i % 20, i % 25, DecisionSource::kNew});
  std::vector<float> matrix(100, 0.5f);
  std::vector<double> times(10);
  for (int i = 0; i < 10; ++i) times[i] = i;
  GridField field{"mean", 4, 4, 1.0, 0.0, 0.0, std::vector<float>(16, -60.0f)};
  for (double width_mm : {88.0, 180.0}) {
    const auto [w, h] = VectorLayoutSize(1600, 1200, width_mm);
    ExperienceMapImageOptions map_options;
    map_options.width_px = w;
    map_options.height_px = h;
    TemplateGraphImageOptions graph_options;
    graph_options.width_px = w;
    graph_options.height_px = h;
    PoseCellImageOptions cell_options;
    cell_options.width_px = w;
    cell_options.height_px = h;
    SimilarityImageOptions similarity_options;
    similarity_options.size_px = w / 2;
    for (const render::Scene& scene :
         {ExperienceMapScene(map, map_options), TemplateGraphScene(points, graph_options),
          PoseCellScene(network, cell_options),
          SimilarityMatrixScene(matrix, times, similarity_options),
          GridFieldsScene({field, field}, {}, "t", w / 4),
          LocalisationCurvesScene({{"a", {1.0, 2.0}}}, "t", 30.0, w),
          PrecisionRecallScene({"within 2 m"}, {{0.1, 0.5}}, {{0.9, 0.8}}, "t", w)}) {
      ASSERT_FALSE(scene.texts().empty());
      for (const render::SceneText& t : scene.texts()) {
        EXPECT_GE(render::TextPoints(t.height_px, scene.width(), width_mm),
                  render::kMinTextPt - 1e-9)
            << "'" << t.text << "' (" << t.height_px << " px) in a scene " << scene.width()
            << " px wide printed " << width_mm << " mm wide";
      }
    }
  }
}

// Laid out for a page, no text runs off it. TextWidthPx (the PNG font's metrics) bounds the PDF
// font's width from above: DejaVu Sans set at the same cap height measures 90-97 % of it
// (Cairo's text extents of our labels), so a text that fits here fits in both.
TEST(FigureOutputTest, NoTextRunsOffAFigureLaidOutForAPage) {
  SweepFigureData sweep;
  sweep.title = "ipin2023-wifi-compass.toml";
  sweep.objective = "mean map_ate_m";
  sweep.keys = {"fused.recency_s", "local_view.injection_gain", "wifi.match_threshold"};
  for (int i = 0; i < 27; ++i) {
    sweep.points.push_back({{std::to_string(20 * (1 + i % 3)), std::to_string(0.05 * (1 + i / 9)),
                             std::to_string(0.15 + 0.1 * (i / 3 % 3))},
                            1.5 + 0.1 * i,
                            0.2 + 0.01 * i});
  }
  sweep.best = 0;
  SequencePairsData pairs;
  for (int i = 0; i < 40; ++i) pairs.positions.push_back({0.5 * i, std::sin(0.3 * i)});
  pairs.pairs = {{30, 2, true}, {31, 3, false}};
  pairs.links_made = 1;
  std::vector<float> matrix(100, 0.5f);
  std::vector<double> times(10);
  for (int i = 0; i < 10; ++i) times[i] = 100.0 * i;
  ExperienceMapImageData map;
  for (uint32_t i = 0; i < 20; ++i) {
    Experience e;
    e.id = i;
    e.x_m = i;
    e.time_s = 1234.567 * i;
    map.experiences.push_back(e);
  }
  Link closure;
  closure.from = 19;
  closure.to = 0;
  closure.loop_closure = true;
  map.links.push_back(closure);
  map.ground_truth = {{0, 0}, {19, 0}};  // its legend item too
  PoseCellOptions cells;
  cells.dim_xy_cells = 21;
  PoseCellNetwork network(cells);
  network.Reset({10.67, 10.77, 20.78});
  std::vector<int> floors(20, 0);  // the second half of the map on floor 1
  std::fill(floors.begin() + 10, floors.end(), 1);
  for (double width_mm : {88.0, 180.0}) {
    const int w = render::VectorLayoutWidthPx(width_mm);
    SimilarityImageOptions similarity;
    similarity.size_px = w - 190;  // as replay --render lays it out
    similarity.title = "Wi-Fi similarity of scans (eqs. 1-4)";
    similarity.legend = {{{220, 50, 32, 255}, "verified correspondence"},
                         {{170, 170, 170, 255}, "DP pair not verified (light)"}};
    ExperienceMapImageOptions map_options;
    map_options.width_px = w;
    map_options.height_px = w * 3 / 4;
    map_options.title =
        "experience map (IPIN2023_T3_TrainingTrial51_repetition02 and "
        "IPIN2023_T3_TrainingTrial51_repetition03)";  // a data set's long name
    TemplateGraphImageOptions graph_options;
    graph_options.width_px = w;
    graph_options.height_px = w;
    graph_options.title = map_options.title;
    PoseCellImageOptions cell_options;
    const auto [cw, ch] = VectorLayoutSize(cell_options.width_px, cell_options.height_px, width_mm);
    cell_options.width_px = cw;
    cell_options.height_px = ch;
    for (const render::Scene& scene :
         {PoseCellScene(network, cell_options), SweepParameterScene(sweep, w),
          SweepHeatmapScene(sweep, 0, 1, w), SweepParetoScene(sweep, w),
          SequencePairsScene(pairs, "Wi-Fi sequence pairs", w),
          SimilarityMatrixScene(matrix, times, similarity), ExperienceMapScene(map, map_options),
          TemplateGraphScene({{0.0, 1, 1, DecisionSource::kNew}}, graph_options),
          ExperienceMapFloorsScene(map, floors, {}, map_options)}) {
      ASSERT_FALSE(scene.texts().empty());
      EXPECT_LE(scene.width(), w + 1) << "'" << scene.texts().front().text << "'";
      for (const render::SceneText& t : scene.texts()) {
        const float width = render::TextWidthPx(t.text, t.height_px);
        const float left = t.anchor == render::TextAnchor::kLeft     ? t.position.x
                           : t.anchor == render::TextAnchor::kCenter ? t.position.x - width / 2
                                                                     : t.position.x - width;
        EXPECT_GE(left, 0.0f) << "'" << t.text << "' at " << width_mm << " mm";
        EXPECT_LE(left + width, static_cast<float>(scene.width()))
            << "'" << t.text << "' at " << width_mm << " mm (scene " << scene.width() << " px)";
        EXPECT_GE(render::TextPoints(t.height_px, scene.width(), width_mm),
                  render::kMinTextPt - 1e-9)
            << "'" << t.text << "'";
      }
    }
  }
}

// The distance axis ends just past the data, at 30 m at most (it always ran to 30 m, squeezing
// errors of a few metres into a sixth of the panel).
TEST(LocalisationFigureTest, TheDistanceAxisEndsJustPastTheData) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(LocalisationAxisEndM({{"a", {1.0, 10.4, inf, nan}}, {"b", {7.0}}}), 15.0);
  EXPECT_EQ(LocalisationAxisEndM({{"a", {0.2}}}), 5.0);
  EXPECT_EQ(LocalisationAxisEndM({{"a", {10.0}}}), 10.0);
  EXPECT_EQ(LocalisationAxisEndM({{"a", {95.0}}}), 30.0);
  EXPECT_EQ(LocalisationAxisEndM({{"a", {inf, nan}}}), 30.0);
  EXPECT_EQ(LocalisationAxisEndM({}, 20.0), 20.0);
}

}  // namespace
}  // namespace ratslam::viewer
