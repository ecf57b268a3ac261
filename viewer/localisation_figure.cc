#include "viewer/localisation_figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "viewer/figures.h"

namespace ratslam {

double LocalisationAxisEndM(const std::vector<LocalisationCurve>& curves, double at_most_m) {
  double largest = 0.0;
  bool any = false;
  for (const LocalisationCurve& c : curves) {
    for (double e : c.errors_m) {
      if (std::isfinite(e)) {
        largest = std::max(largest, e);
        any = true;
      }
    }
  }
  if (!any) return at_most_m;
  return std::min(at_most_m, std::max(5.0, 5.0 * std::ceil(largest / 5.0)));
}

Scene LocalisationCurvesScene(const std::vector<LocalisationCurve>& curves,
                              const std::string& title, double max_distance_m, int width_px) {
  const float left0 = 90, top = 80, gap = 130;
  // Each panel 560 x 400 at the natural width; narrower figures (vector layouts) shrink them.
  const float panel_w = width_px > 0 ? std::max(120.0f, (width_px - left0 - gap - 40) / 2) : 560;
  const float panel_h = panel_w * 400 / 560;
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
    const double step = NiceStep(max_distance_m, std::clamp(static_cast<int>(panel_w / 50), 2, 6));
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

Scene PrecisionRecallScene(const std::vector<std::string>& labels,
                           const std::vector<std::vector<double>>& recall,
                           const std::vector<std::vector<double>>& precision,
                           const std::string& title, int width_px) {
  const float left = 90, top = 104;
  const float panel = width_px > 0 ? std::max(200.0f, width_px - left - 60) : 560;
  const float legend_h = 28.0f * static_cast<float>(labels.size());
  Scene scene(static_cast<int>(left + panel + 60), static_cast<int>(top + panel + 90 + legend_h),
              Rgba{255, 255, 255, 255});
  scene.Text({20, 32}, title, 20, kInk);
  scene.Text({20, 58}, "accepted: the best place's posterior >= a threshold", 14, kInk);
  auto to_px = [&](double r, double p) {
    return ScenePoint{static_cast<float>(left + panel * r),
                      static_cast<float>(top + panel * (1 - p))};
  };
  for (int k = 0; k <= 5; ++k) {
    const double v = k / 5.0;
    char text[16];
    std::snprintf(text, sizeof text, "%d", k * 20);
    scene.Line(to_px(0, v), to_px(1, v), 1.0f, kGrid);
    scene.Text({left - 10, to_px(0, v).y + 5}, text, 15, kInk, TextAnchor::kRight);
    scene.Line(to_px(v, 0), to_px(v, 1), 1.0f, kGrid);
    scene.Text({to_px(v, 0).x, top + panel + 24}, text, 15, kInk, TextAnchor::kCenter);
  }
  scene.Line(to_px(0, 0), to_px(1, 0), 1.5f, kInk);
  scene.Line(to_px(0, 0), to_px(0, 1), 1.5f, kInk);
  scene.Text({left + panel / 2, top + panel + 52}, "recall (%)", 16, kInk, TextAnchor::kCenter);
  scene.Text({left, top - 14}, "precision (%)", 16, kInk);
  for (size_t c = 0; c < labels.size() && c < recall.size() && c < precision.size(); ++c) {
    std::vector<ScenePoint> line;
    for (size_t i = 0; i < recall[c].size() && i < precision[c].size(); ++i) {
      line.push_back(to_px(recall[c][i], precision[c][i]));
    }
    if (line.size() == 1) line.push_back(line.front());
    if (!line.empty()) scene.Polyline(line, 2.5f, CategoryColor(static_cast<int>(c)));
    const float y = top + panel + 80 + 28.0f * c;
    scene.Rect(left, y - 10, 28, 6, CategoryColor(static_cast<int>(c)));
    scene.Text({left + 38, y - 2}, labels[c], 16, kInk);
  }
  return scene;
}

}  // namespace ratslam
