#include "viewer/figure_output.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/scratch_dir.h"
#include "ratslam/pose_cell_network.h"
#include "viewer/figures.h"
#include "viewer/localisation_figure.h"

namespace ratslam {
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
    Scene s(w, h, {255, 255, 255, 255});
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
    for (const Scene& scene :
         {ExperienceMapScene(map, map_options), TemplateGraphScene(points, graph_options),
          PoseCellScene(network, cell_options),
          SimilarityMatrixScene(matrix, times, similarity_options),
          GridFieldsScene({field, field}, {}, "t", w / 4),
          LocalisationCurvesScene({{"a", {1.0, 2.0}}}, "t", 30.0, w),
          PrecisionRecallScene({"within 2 m"}, {{0.1, 0.5}}, {{0.9, 0.8}}, "t", w)}) {
      ASSERT_FALSE(scene.texts().empty());
      for (const SceneText& t : scene.texts()) {
        EXPECT_GE(TextPoints(t.height_px, scene.width(), width_mm), kMinTextPt - 1e-9)
            << "'" << t.text << "' (" << t.height_px << " px) in a scene " << scene.width()
            << " px wide printed " << width_mm << " mm wide";
      }
    }
  }
}

}  // namespace
}  // namespace ratslam
