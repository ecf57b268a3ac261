#include "viewer/localisation_figure.h"

#include <cmath>
#include <cstdio>

#include "viewer/figures.h"

namespace ratslam {

Scene LocalisationCurvesScene(const std::vector<LocalisationCurve>& curves,
                              const std::string& title, double max_distance_m) {
  const float panel_w = 560, panel_h = 400, left0 = 90, top = 80, gap = 130;
  const float legend_h = 28.0f * static_cast<float>(curves.size());
  Scene scene(static_cast<int>(left0 + 2 * panel_w + gap + 40),
              static_cast<int>(top + panel_h + 90 + legend_h), Rgba{255, 255, 255, 255});
  scene.Text({20, 32}, title, 20, kInk);
  const char* names[2] = {"correct localisations within d (%)",
                          "misplaced localisations beyond d (%)"};
  const int samples = 301;
  for (int panel = 0; panel < 2; ++panel) {
    const float left = left0 + panel * (panel_w + gap);
    auto to_px = [&](double d, double rate) {
      return ScenePoint{static_cast<float>(left + panel_w * d / max_distance_m),
                        static_cast<float>(top + panel_h * (1.0 - rate))};
    };
    for (int k = 0; k <= 5; ++k) {  // grid and ticks: rates 0..100 %, distances
      const double rate = k / 5.0;
      scene.Line(to_px(0, rate), to_px(max_distance_m, rate), 1.0f, kGrid);
      char text[16];
      std::snprintf(text, sizeof text, "%d", k * 20);
      scene.Text({left - 10, to_px(0, rate).y + 5}, text, 15, kInk, TextAnchor::kRight);
    }
    const double step = NiceStep(max_distance_m, 6);
    for (double d = 0; d <= max_distance_m + 1e-9; d += step) {
      scene.Line(to_px(d, 0), to_px(d, 1), 1.0f, kGrid);
      char text[16];
      std::snprintf(text, sizeof text, "%g", d);
      scene.Text({to_px(d, 0).x, top + panel_h + 24}, text, 15, kInk, TextAnchor::kCenter);
    }
    scene.Line(to_px(0, 0), to_px(max_distance_m, 0), 1.5f, kInk);
    scene.Line(to_px(0, 0), to_px(0, 1), 1.5f, kInk);
    scene.Text({left + panel_w / 2, top + panel_h + 52}, "d (m)", 16, kInk, TextAnchor::kCenter);
    scene.Text({left, top - 14}, names[panel], 16, kInk);
    for (size_t c = 0; c < curves.size(); ++c) {
      const auto& errors = curves[c].errors_m;
      std::vector<ScenePoint> line;
      for (int s = 0; s < samples; ++s) {
        const double d = max_distance_m * s / (samples - 1);
        double count = 0;
        for (double e : errors) count += panel == 0 ? (e <= d) : (e > d);
        line.push_back(to_px(d, errors.empty() ? 0.0 : count / errors.size()));
      }
      scene.Polyline(line, 2.5f, CategoryColor(static_cast<int>(c)));
    }
  }
  for (size_t c = 0; c < curves.size(); ++c) {  // legend below the panels
    const float y = top + panel_h + 80 + 28.0f * c;
    scene.Rect(left0, y - 10, 28, 6, CategoryColor(static_cast<int>(c)));
    scene.Text({left0 + 38, y - 2}, curves[c].label, 16, kInk);
  }
  return scene;
}

}  // namespace ratslam
