// Rendering through OSMesa: orientation, colours, antialiasing, errors. Skips (with the reason)
// where no OSMesa context can be made.
#include "render/renderer.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <tuple>
#include <vector>

#include "common/scratch_dir.h"

namespace ratslam::render {
namespace {

// One fresh folder per test process (two checkouts testing at once never collide).
const ScratchDir& TestScratch() {
  static const ScratchDir dir("ratslam_test");
  return dir;
}

std::unique_ptr<SceneRenderer> MakeRenderer() {
  StatusOr<std::unique_ptr<SceneRenderer>> renderer = CreateOsMesaRenderer();
  if (!renderer.ok()) return nullptr;
  return std::move(renderer.value());
}

#define REQUIRE_RENDERER(r) \
  auto r = MakeRenderer();  \
  if (!r) GTEST_SKIP() << "OSMesa unavailable: " << CreateOsMesaRenderer().status().message()

TEST(OsMesaRendererTest, ImageIsTheRightWayUpAndColoursAreExact) {
  REQUIRE_RENDERER(renderer);
  Scene scene(64, 48, {255, 255, 255, 255});
  scene.Rect(0, 0, 64, 10, {255, 0, 0, 255});   // top band red
  scene.Rect(0, 38, 64, 10, {0, 0, 255, 255});  // bottom band blue
  scene.Rect(0, 10, 8, 28, {0, 255, 0, 255});   // left band green
  StatusOr<RgbaImage> image = renderer->Render(scene);
  ASSERT_TRUE(image.ok()) << image.status().message();
  ASSERT_EQ(image->width, 64);
  ASSERT_EQ(image->height, 48);
  const Rgba top = image->At(32, 2), bottom = image->At(32, 45), left = image->At(2, 24),
             middle = image->At(40, 24);
  EXPECT_EQ((std::array<int, 3>{top.r, top.g, top.b}), (std::array<int, 3>{255, 0, 0}));
  EXPECT_EQ((std::array<int, 3>{bottom.r, bottom.g, bottom.b}), (std::array<int, 3>{0, 0, 255}));
  EXPECT_EQ((std::array<int, 3>{left.r, left.g, left.b}), (std::array<int, 3>{0, 255, 0}));
  EXPECT_EQ((std::array<int, 3>{middle.r, middle.g, middle.b}),
            (std::array<int, 3>{255, 255, 255}));
}

TEST(OsMesaRendererTest, DiagonalLinesAreAntialiased) {
  REQUIRE_RENDERER(renderer);
  Scene scene(64, 64, {255, 255, 255, 255});
  scene.Line({5, 5}, {60, 40}, 2.0f, {0, 0, 0, 255});
  StatusOr<RgbaImage> image = renderer->Render(scene);
  ASSERT_TRUE(image.ok()) << image.status().message();
  int partial = 0, dark = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const int v = image->At(x, y).r;
      if (v > 20 && v < 235) ++partial;
      if (v <= 20) ++dark;
    }
  EXPECT_GT(dark, 40);
  EXPECT_GT(partial, 40) << "edge pixels should take intermediate grey levels";
}

TEST(OsMesaRendererTest, TexturedImageKeepsRowOrder) {
  REQUIRE_RENDERER(renderer);
  Scene scene(40, 40, {255, 255, 255, 255});
  SceneImage img;
  img.left = 0;
  img.top = 0;
  img.width = 40;
  img.height = 40;
  img.pixels_wide = 1;
  img.pixels_high = 2;
  img.rgba = {255, 0, 0, 255, 0, 0, 255, 255};  // row 0 red, row 1 blue
  scene.Image(img);
  StatusOr<RgbaImage> image = renderer->Render(scene);
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(image->At(20, 5).r, 255);
  EXPECT_EQ(image->At(20, 35).b, 255);
}

TEST(OsMesaRendererTest, TextIsDrawn) {
  REQUIRE_RENDERER(renderer);
  Scene scene(200, 50, {255, 255, 255, 255});
  scene.Text({10, 35}, "ratslam 42", 24, {0, 0, 0, 255});
  StatusOr<RgbaImage> image = renderer->Render(scene);
  ASSERT_TRUE(image.ok());
  int dark = 0;
  for (int y = 0; y < 50; ++y)
    for (int x = 0; x < 200; ++x) dark += image->At(x, y).r < 128;
  EXPECT_GT(dark, 100);
}

TEST(OsMesaRendererTest, OversizedImageIsAnErrorNotACrash) {
  REQUIRE_RENDERER(renderer);
  Scene scene(100000, 10, {255, 255, 255, 255});
  EXPECT_FALSE(renderer->Render(scene).ok());
}

TEST(OsMesaRendererTest, MissingLibraryIsAClearError) {
  ::setenv("RATSLAM_OSMESA_LIBRARY", "/nonexistent/libOSMesa.so.8", 1);
  StatusOr<std::unique_ptr<SceneRenderer>> renderer = CreateOsMesaRenderer();
  ::unsetenv("RATSLAM_OSMESA_LIBRARY");
  ASSERT_FALSE(renderer.ok());
  EXPECT_NE(renderer.status().message().find("OSMesa is not available"), std::string::npos)
      << renderer.status().message();
  const Scene scene(10, 10, {0, 0, 0, 255});
  ::setenv("RATSLAM_OSMESA_LIBRARY", "/nonexistent/libOSMesa.so.8", 1);
  EXPECT_FALSE(RenderToPng(scene, (TestScratch() / "never_written.png").string()).ok());
  ::unsetenv("RATSLAM_OSMESA_LIBRARY");
}

TEST(PngTest, WriteReadRoundTrip) {
  RgbaImage image{3, 2, {1,  2,  3,  255, 4,  5,  6,  255, 7,  8,  9,  255,
                         10, 11, 12, 255, 13, 14, 15, 255, 16, 17, 18, 128}};
  const auto path = TestScratch().path() / "ratslam_png_test.png";
  ASSERT_TRUE(WritePng(image, path.string()).ok());
  StatusOr<RgbaImage> back = ReadPng(path.string());
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->pixels, image.pixels);
  std::filesystem::remove(path);
  EXPECT_FALSE(ReadPng(path.string()).ok());
}

// Our PNG writer against OpenCV's decoder (libpng): images of several bands of rows (the writer
// compresses bands in parallel), odd widths, opaque (written as RGB) and translucent (RGBA)
// pixels; the same image gives the same bytes twice.
TEST(PngTest, LargeImagesRoundTripThroughAnIndependentDecoder) {
  std::mt19937 rng(7);
  for (const auto& [w, h, opaque] : {std::tuple{1, 1, true}, std::tuple{333, 517, true},
                                     std::tuple{257, 300, false}, std::tuple{64, 128, true}}) {
    RgbaImage image{w, h, std::vector<uint8_t>(static_cast<size_t>(w) * h * 4)};
    for (size_t i = 0; i < image.pixels.size(); ++i) {
      // Runs and noise, so both compress differently.
      image.pixels[i] = (i / 4) % 97 < 40 ? 255 : static_cast<uint8_t>(rng());
      if (i % 4 == 3 && opaque) image.pixels[i] = 255;
    }
    const auto path = TestScratch().path() / "ratslam_png_large.png";
    ASSERT_TRUE(WritePng(image, path.string()).ok());
    StatusOr<RgbaImage> back = ReadPng(path.string());
    ASSERT_TRUE(back.ok()) << w << "x" << h;
    EXPECT_EQ(back->width, w);
    EXPECT_EQ(back->height, h);
    EXPECT_TRUE(back->pixels == image.pixels) << w << "x" << h;
    std::ifstream first_file(path, std::ios::binary);
    const std::string first((std::istreambuf_iterator<char>(first_file)), {});
    ASSERT_TRUE(WritePng(image, path.string()).ok());
    std::ifstream second_file(path, std::ios::binary);
    EXPECT_EQ(std::string((std::istreambuf_iterator<char>(second_file)), {}), first);
  }
  EXPECT_FALSE(WritePng(RgbaImage{2, 2, std::vector<uint8_t>(3)},
                        (TestScratch().path() / "never_written.png").string())
                   .ok());
}

}  // namespace
}  // namespace ratslam::render
