#include "viewer/world_figure.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "render/image.h"
#include "viewer/figures.h"

namespace ratslam::viewer {

render::Scene WorldMapScene(const sim::World& world, const dataset::Dataset& dataset,
                            int panel_px) {
  std::set<int> floor_set;
  for (const sim::Wall& w : world.walls) floor_set.insert(w.floor);
  const std::vector<int> floors(floor_set.begin(), floor_set.end());
  double min_x = 1e300, min_y = 1e300, max_x = -1e300, max_y = -1e300;
  auto grow = [&](double x, double y) {
    min_x = std::min(min_x, x);
    max_x = std::max(max_x, x);
    min_y = std::min(min_y, y);
    max_y = std::max(max_y, y);
  };
  for (const sim::Wall& w : world.walls) {
    grow(w.from.x_m, w.from.y_m);
    grow(w.to.x_m, w.to.y_m);
  }
  for (const sim::AccessPoint& a : world.access_points) grow(a.position.x_m, a.position.y_m);
  const double margin = 0.05 * std::max(max_x - min_x, max_y - min_y) + 1.0;
  min_x -= margin;
  max_x += margin;
  min_y -= margin;
  max_y += margin;
  const double scale = panel_px / std::max(max_x - min_x, max_y - min_y);
  const int panel_h = static_cast<int>((max_y - min_y) * scale);
  const int top = 84, gap = 30;
  const std::string legend =
      "walls (grey: light, black: heavy), access points (red), true path (blue)";
  const int width = std::max(static_cast<int>(floors.size()) * (panel_px + gap) + gap,
                             static_cast<int>(render::TextWidthPx(legend, 15)) + 40);
  render::Scene scene(width, panel_h + top + 70, render::Rgba{255, 255, 255, 255});
  const render::Rgba ink{30, 30, 30, 255};
  scene.Text({20, 28}, "world '" + world.name + "'", 18, ink);
  scene.Text({20, 52}, legend, 15, ink);
  for (size_t f = 0; f < floors.size(); ++f) {
    const double left = gap + f * (panel_px + gap);
    WorldToImage to;
    to.scale_px_per_m = scale;
    to.center_x_m = (min_x + max_x) / 2;
    to.center_y_m = (min_y + max_y) / 2;
    to.center_x_px = left + panel_px / 2.0;
    to.center_y_px = top + panel_h / 2.0;
    scene.Text({static_cast<float>(left), static_cast<float>(top - 8)},
               "floor " + std::to_string(floors[f]), 15, ink);
    for (const sim::Wall& w : world.walls) {
      if (w.floor != floors[f]) continue;
      const double db = world.materials_db.at(w.material);
      const uint8_t g = static_cast<uint8_t>(std::clamp(170.0 - 8.0 * db, 0.0, 200.0));
      scene.Line(to(w.from.x_m, w.from.y_m), to(w.to.x_m, w.to.y_m), db >= 10 ? 3.5f : 2.0f,
                 render::Rgba{g, g, g, 255});
    }
    std::vector<render::ScenePoint> path;
    for (size_t i = 0; i < dataset.ground_truth.size(); ++i) {
      const GroundTruthRow& g = dataset.ground_truth[i];
      if (g.floor != floors[f]) {
        if (path.size() > 1) scene.Polyline(path, 1.5f, render::Rgba{40, 90, 200, 200});
        path.clear();
        continue;
      }
      path.push_back(to(g.x_m, g.y_m));
    }
    if (path.size() > 1) scene.Polyline(path, 1.5f, render::Rgba{40, 90, 200, 200});
    for (const sim::Disturbance& d : world.disturbances) {
      if (d.floor == floors[f]) {
        scene.Ring(to(d.position.x_m, d.position.y_m),
                   static_cast<float>(d.radius_m * scale) - 1.5f,
                   static_cast<float>(d.radius_m * scale), 0.0f, 6.2832f,
                   render::Rgba{230, 140, 0, 255}, 32);
      }
    }
    for (const sim::AccessPoint& a : world.access_points) {
      if (a.floor == floors[f])
        scene.Disc(to(a.position.x_m, a.position.y_m), 5.0f, render::Rgba{210, 40, 40, 255});
    }
    // Scale bar: 5 m.
    const render::ScenePoint bar = {static_cast<float>(left + 10),
                                    static_cast<float>(top + panel_h + 30)};
    scene.Line(bar, {bar.x + static_cast<float>(5.0 * scale), bar.y}, 2.0f, ink);
    scene.Text({bar.x, bar.y + 20}, "5 m", 14, ink);
  }
  return scene;
}

}  // namespace ratslam::viewer
