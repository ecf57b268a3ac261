#include "render/vector_figure.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "common/scratch_dir.h"

namespace ratslam::render {
namespace {

namespace fs = std::filesystem;

std::string Slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The number after the first `key` in `text`, skipping `skip` numbers (NaN when there is none).
double NumberAfter(const std::string& text, const std::string& key, int skip = 0) {
  const size_t at = text.find(key);
  if (at == std::string::npos) return std::nan("");
  std::istringstream in(text.substr(at + key.size()));
  double value = std::nan("");
  for (int i = 0; i <= skip; ++i) {
    if (!(in >> value)) return std::nan("");
  }
  return value;
}

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Seven shapes, one image and two texts with eight characters between them.
Scene TestScene() {
  Scene scene(800, 600, {255, 255, 255, 255});
  scene.Line({10, 10}, {200, 10}, 2, {0, 0, 0, 255});
  scene.Line({10, 20}, {200, 40}, 1, {255, 0, 0, 128});
  scene.Polyline({{10, 100}, {100, 150}, {200, 100}}, 3, {0, 0, 255, 255});
  scene.Disc({400, 300}, 20, {0, 128, 0, 255});
  scene.Ring({500, 300}, 10, 30, 0.0f, 1.5f, {128, 0, 128, 255});
  scene.Rect(600, 400, 50, 30, {10, 20, 30, 255});
  scene.Triangle({700, 500}, {750, 500}, {725, 550}, {200, 100, 0, 255});
  SceneImage image;
  image.left = 50;
  image.top = 300;
  image.width = 100;
  image.height = 100;
  image.pixels_wide = 2;
  image.pixels_high = 2;
  image.rgba = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
  scene.Image(image);
  scene.Text({100, 580}, "Ab c", 14, {0, 0, 0, 255});
  scene.Text({700, 580}, "xyz", 13, {0, 0, 0, 255}, TextAnchor::kRight);
  return scene;
}

class VectorFigureTest : public ::testing::Test {
 protected:
  ScratchDir scratch_{"vector_figure"};
};

TEST_F(VectorFigureTest, TheLayoutWidthPutsTheSmallestTextAtSevenPoints) {
  // 88 mm = 249.449 pt; 13 px of cap height is 13 / 0.729 = 17.833 px of em; 7 pt of em at
  // 249.449 pt of page needs a scene 249.449 * 17.833 / 7 = 635.5 px wide.
  EXPECT_EQ(VectorLayoutWidthPx(88.0), 635);
  EXPECT_NEAR(TextPoints(13, 635, 88.0), 7.005, 1e-3);
  EXPECT_GE(TextPoints(13, VectorLayoutWidthPx(88.0), 88.0), kMinTextPt);
  EXPECT_GE(TextPoints(13, VectorLayoutWidthPx(180.0), 180.0), kMinTextPt);
  // The complaint this answers: a 1600 px figure printed 88 mm wide has 2.8 pt text.
  EXPECT_LT(TextPoints(13, 1600, 88.0), 3.0);
}

TEST_F(VectorFigureTest, SvgHasOnePathPerShapeOneGlyphPerLetterAndThePageSize) {
  const fs::path svg = scratch_.path() / "f.svg";
  ASSERT_TRUE(WriteVectorFigure(TestScene(), svg.string(), VectorFormat::kSvg, 88.0).ok());
  const std::string text = Slurp(svg);
  ASSERT_NE(text.find("<svg"), std::string::npos);
  // 88 mm wide; 800x600 keeps its aspect: 249.449 x 187.087 pt.
  EXPECT_NEAR(NumberAfter(text, " width=\""), 249.449, 0.01) << text.substr(0, 400);
  EXPECT_NEAR(NumberAfter(text, " height=\""), 187.087, 0.01);
  // Outside the glyph definitions: the background rectangle, then one path per shape.
  const size_t defs_end = text.find("</defs>");
  const std::string body = defs_end == std::string::npos ? text : text.substr(defs_end);
  EXPECT_EQ(Count(body, "<rect"), 1u) << body;
  EXPECT_EQ(Count(body, "<path"), 7u) << body;
  // Text is set in a font: one glyph run per text, one glyph per character ("Ab c", "xyz").
  EXPECT_EQ(Count(body, "<g style=\"fill:rgb(0%,0%,0%)"), 2u) << body;
  EXPECT_EQ(Count(body, "xlink:href=\"#glyph"), 7u) << body;
  EXPECT_EQ(Count(text, "<image"), 1u);
}

TEST_F(VectorFigureTest, PdfHasThePageSizeAnEmbeddedFontAndTheImage) {
  const fs::path pdf = scratch_.path() / "f.pdf";
  ASSERT_TRUE(WriteVectorFigure(TestScene(), pdf.string(), VectorFormat::kPdf, 180.0).ok());
  const std::string text = Slurp(pdf);
  ASSERT_EQ(text.rfind("%PDF-", 0), 0u);
  EXPECT_NE(text.find("%%EOF"), std::string::npos);
  // "/MediaBox [ 0 0 W H ]": 180 mm wide.
  EXPECT_NEAR(NumberAfter(text, "/MediaBox [", 2), 510.236, 0.01);
  EXPECT_NEAR(NumberAfter(text, "/MediaBox [", 3), 382.677, 0.01);
  EXPECT_EQ(Count(text, "/Type /Page\n") + Count(text, "/Type /Page "), 1u);
  EXPECT_NE(text.find("DejaVuSans"), std::string::npos);
  EXPECT_NE(text.find("/FontFile"), std::string::npos);  // embedded, not referenced
  EXPECT_NE(text.find("/Subtype /Image"), std::string::npos);
}

TEST_F(VectorFigureTest, SameSceneSameBytes) {
  for (VectorFormat format : {VectorFormat::kPdf, VectorFormat::kSvg}) {
    const fs::path a = scratch_.path() / "a", b = scratch_.path() / "b";
    ASSERT_TRUE(WriteVectorFigure(TestScene(), a.string(), format).ok());
    ASSERT_TRUE(WriteVectorFigure(TestScene(), b.string(), format).ok());
    EXPECT_EQ(Slurp(a), Slurp(b));
  }
}

TEST(SceneAppendTest, MovesEverythingByTheOffset) {
  const Scene panel = TestScene();
  Scene both(1600, 600, {255, 255, 255, 255});
  both.Append(panel, 0, 0);
  both.Append(panel, 800, 10);
  ASSERT_EQ(both.shapes().size(), 2 * panel.shapes().size());
  ASSERT_EQ(both.triangles().size(), 2 * panel.triangles().size());
  ASSERT_EQ(both.texts().size(), 2 * panel.texts().size());
  ASSERT_EQ(both.images().size(), 2 * panel.images().size());
  const size_t n = panel.shapes().size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t k = 0; k < panel.shapes()[i].points.size(); ++k) {
      EXPECT_FLOAT_EQ(both.shapes()[n + i].points[k].x, panel.shapes()[i].points[k].x + 800);
      EXPECT_FLOAT_EQ(both.shapes()[n + i].points[k].y, panel.shapes()[i].points[k].y + 10);
    }
  }
  const size_t v = panel.triangles().size();
  EXPECT_FLOAT_EQ(both.triangles()[v].x, panel.triangles()[0].x + 800);
  EXPECT_FLOAT_EQ(both.texts()[2].position.y, panel.texts()[0].position.y + 10);
  EXPECT_FLOAT_EQ(both.images()[1].left, panel.images()[0].left + 800);
}

TEST_F(VectorFigureTest, ErrorsNameTheFile) {
  const Status empty =
      WriteVectorFigure(Scene(0, 10, {}), (scratch_.path() / "e.pdf").string(), VectorFormat::kPdf);
  ASSERT_FALSE(empty.ok());
  EXPECT_NE(empty.message().find("e.pdf"), std::string::npos);
  const Status nowhere = WriteVectorFigure(TestScene(), (scratch_.path() / "no" / "f.svg").string(),
                                           VectorFormat::kSvg);
  ASSERT_FALSE(nowhere.ok());
  EXPECT_NE(nowhere.message().find("f.svg"), std::string::npos) << nowhere.message();
}

}  // namespace
}  // namespace ratslam::render
