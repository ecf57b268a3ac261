// Rendering a large experience map (100k links) at 2048x2048: scene building, OSMesa rendering
// and PNG encoding measured separately, so the share of each can be reported, and together.
// Wall time: OSMesa's llvmpipe and the PNG writer work on other threads too.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>

#include "common/random.h"
#include "render/renderer.h"
#include "viewer/figures.h"

namespace ratslam {
namespace {

viewer::ExperienceMapImageData LargeMap(int links) {
  // Twenty laps of a 5,000-experience city-block route (a rounded square of 1 km sides, one
  // experience per 0.8 m) with lap-to-lap drift; every 50th experience of a lap closes a loop to
  // the same place on the previous lap, as a long multi-lap replay gives.
  viewer::ExperienceMapImageData data;
  Random rng(3);
  const int per_lap = 5000;
  for (int i = 0; i <= links; ++i) {
    const int lap = i / per_lap;
    const double s = 4.0 * (i % per_lap) / per_lap;  // 0..4 around the square
    const int side = static_cast<int>(s);
    const double f = s - side;
    const double corners[5][2] = {{0, 0}, {1000, 0}, {1000, 1000}, {0, 1000}, {0, 0}};
    Experience e;
    e.id = i;
    e.x_m = corners[side][0] + f * (corners[side + 1][0] - corners[side][0]) + 3.0 * lap +
            rng.Gaussian(0.0, 0.5);
    e.y_m = corners[side][1] + f * (corners[side + 1][1] - corners[side][1]) - 2.0 * lap +
            rng.Gaussian(0.0, 0.5);
    e.theta_rad = side * M_PI / 2;
    e.time_s = i;
    data.experiences.push_back(e);
  }
  for (int i = 0; i < links; ++i) {
    Link l;
    l.id = i;
    const bool closure = i >= per_lap && i % 50 == 0;
    l.from = i;
    l.to = closure ? i - per_lap : i + 1;
    l.loop_closure = closure;
    data.links.push_back(l);
  }
  return data;
}

viewer::ExperienceMapImageOptions Options() {
  viewer::ExperienceMapImageOptions o;
  o.width_px = 2048;
  o.height_px = 2048;
  return o;
}

void BM_BuildScene(benchmark::State& state) {
  const viewer::ExperienceMapImageData data = LargeMap(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(viewer::ExperienceMapScene(data, Options()));
}
BENCHMARK(BM_BuildScene)->Arg(100000)->Unit(benchmark::kMillisecond);

void BM_RenderOsMesa(benchmark::State& state) {
  auto renderer = render::CreateOsMesaRenderer();
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().message().c_str());
    return;
  }
  const render::Scene scene =
      viewer::ExperienceMapScene(LargeMap(static_cast<int>(state.range(0))), Options());
  for (auto _ : state) benchmark::DoNotOptimize(renderer.value()->Render(scene));
  state.counters["triangles"] = static_cast<double>(scene.triangles().size() / 3);
}
BENCHMARK(BM_RenderOsMesa)
    ->Arg(0)
    ->Arg(1000)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_EncodePng(benchmark::State& state) {
  auto renderer = render::CreateOsMesaRenderer();
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().message().c_str());
    return;
  }
  const render::Scene scene = viewer::ExperienceMapScene(LargeMap(100000), Options());
  const render::RgbaImage image = renderer.value()->Render(scene).value();
  const auto path = std::filesystem::temp_directory_path() / "ratslam_render_benchmark.png";
  for (auto _ : state) benchmark::DoNotOptimize(render::WritePng(image, path.string()));
  std::filesystem::remove(path);
}
BENCHMARK(BM_EncodePng)->Unit(benchmark::kMillisecond)->UseRealTime();

// The whole path for one more image of the same size: scene, OSMesa (framebuffers kept from the
// previous image), PNG file. The first image of a size also allocates the framebuffers
// (BM_RenderOsMesaFirstImage).
void BM_ExperienceMapToPng(benchmark::State& state) {
  auto renderer = render::CreateOsMesaRenderer();
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().message().c_str());
    return;
  }
  const viewer::ExperienceMapImageData data = LargeMap(100000);
  const auto path = std::filesystem::temp_directory_path() / "ratslam_render_benchmark_e2e.png";
  for (auto _ : state) {
    const render::Scene scene = viewer::ExperienceMapScene(data, Options());
    benchmark::DoNotOptimize(
        render::WritePng(renderer.value()->Render(scene).value(), path.string()));
  }
  std::filesystem::remove(path);
}
BENCHMARK(BM_ExperienceMapToPng)->Unit(benchmark::kMillisecond)->UseRealTime();

// A new renderer per image: context, shaders and framebuffers made for this one image.
void BM_RenderOsMesaFirstImage(benchmark::State& state) {
  const render::Scene scene = viewer::ExperienceMapScene(LargeMap(100000), Options());
  for (auto _ : state) {
    auto renderer = render::CreateOsMesaRenderer();
    if (!renderer.ok()) {
      state.SkipWithError(renderer.status().message().c_str());
      return;
    }
    benchmark::DoNotOptimize(renderer.value()->Render(scene));
  }
}
BENCHMARK(BM_RenderOsMesaFirstImage)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
