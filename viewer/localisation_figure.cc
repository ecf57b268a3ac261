#include "viewer/localisation_figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "render/image.h"
#include "viewer/figures.h"

namespace ratslam::viewer {

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

render::Scene LocalisationCurvesScene(const std::vector<LocalisationCurve>& curves,
                                      const std::string& title, double max_distance_m,
                                      int width_px) {
  const float left0 = 90, top = 80, gap = 130;
  // Each panel 560 x 400 at the natural width; narrower figures (vector layouts) shrink them.
  const float panel_w = width_px > 0 ? std::max(120.0f, (width_px - left0 - gap - 40) / 2) : 560;
  const float panel_h = panel_w * 400 / 560;
  const float legend_h = 28.0f * static_cast<float>(curves.size());
  render::Scene scene(static_cast<int>(left0 + 2 * panel_w + gap + 40),
                      static_cast<int>(top + panel_h + 90 + legend_h),
                      render::Rgba{255, 255, 255, 255});
  scene.Text({20, 32}, title, 20, kInk);
  const char* names[2] = {"correct localisations within d (%)",
                          "misplaced localisations beyond d (%)"};
  const int samples = 301;
  for (int panel = 0; panel < 2; ++panel) {
    const float left = left0 + panel * (panel_w + gap);
    auto to_px = [&](double d, double rate) {
      return render::ScenePoint{static_cast<float>(left + panel_w * d / max_distance_m),
                                static_cast<float>(top + panel_h * (1.0 - rate))};
    };
    for (int k = 0; k <= 5; ++k) {  // grid and ticks: rates 0..100 %, distances
      const double rate = k / 5.0;
      scene.Line(to_px(0, rate), to_px(max_distance_m, rate), 1.0f, kGrid);
      char text[16];
      std::snprintf(text, sizeof text, "%d", k * 20);
      scene.Text({left - 10, to_px(0, rate).y + 5}, text, 15, kInk, render::TextAnchor::kRight);
    }
    const double step = NiceStep(max_distance_m, std::clamp(static_cast<int>(panel_w / 50), 2, 6));
    for (double d = 0; d <= max_distance_m + 1e-9; d += step) {
      scene.Line(to_px(d, 0), to_px(d, 1), 1.0f, kGrid);
      char text[16];
      std::snprintf(text, sizeof text, "%g", d);
      scene.Text({to_px(d, 0).x, top + panel_h + 24}, text, 15, kInk, render::TextAnchor::kCenter);
    }
    scene.Line(to_px(0, 0), to_px(max_distance_m, 0), 1.5f, kInk);
    scene.Line(to_px(0, 0), to_px(0, 1), 1.5f, kInk);
    scene.Text({left + panel_w / 2, top + panel_h + 52}, "d (m)", 16, kInk,
               render::TextAnchor::kCenter);
    scene.Text({left, top - 14}, names[panel], 16, kInk);
    for (size_t c = 0; c < curves.size(); ++c) {
      const auto& errors = curves[c].errors_m;
      std::vector<render::ScenePoint> line;
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

render::Scene PrecisionRecallScene(const std::vector<std::string>& labels,
                                   const std::vector<std::vector<double>>& recall,
                                   const std::vector<std::vector<double>>& precision,
                                   const std::string& title, int width_px,
                                   const std::string& subtitle) {
  const float left = 90, top = 104;
  const float panel = width_px > 0 ? std::max(200.0f, width_px - left - 60) : 560;
  const float legend_h = 28.0f * static_cast<float>(labels.size());
  render::Scene scene(static_cast<int>(left + panel + 60),
                      static_cast<int>(top + panel + 90 + legend_h),
                      render::Rgba{255, 255, 255, 255});
  FittedTitle(scene, {20, 32}, title, 20, left + panel + 40);
  FittedTitle(scene, {20, 58}, subtitle, 14, left + panel + 40);
  auto to_px = [&](double r, double p) {
    return render::ScenePoint{static_cast<float>(left + panel * r),
                              static_cast<float>(top + panel * (1 - p))};
  };
  for (int k = 0; k <= 5; ++k) {
    const double v = k / 5.0;
    char text[16];
    std::snprintf(text, sizeof text, "%d", k * 20);
    scene.Line(to_px(0, v), to_px(1, v), 1.0f, kGrid);
    scene.Text({left - 10, to_px(0, v).y + 5}, text, 15, kInk, render::TextAnchor::kRight);
    scene.Line(to_px(v, 0), to_px(v, 1), 1.0f, kGrid);
    scene.Text({to_px(v, 0).x, top + panel + 24}, text, 15, kInk, render::TextAnchor::kCenter);
  }
  scene.Line(to_px(0, 0), to_px(1, 0), 1.5f, kInk);
  scene.Line(to_px(0, 0), to_px(0, 1), 1.5f, kInk);
  scene.Text({left + panel / 2, top + panel + 52}, "recall (%)", 16, kInk,
             render::TextAnchor::kCenter);
  scene.Text({left, top - 14}, "precision (%)", 16, kInk);
  for (size_t c = 0; c < labels.size() && c < recall.size() && c < precision.size(); ++c) {
    std::vector<render::ScenePoint> line;
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

render::Scene DifferenceMatrixScene(const DifferenceMatrixFigure& f) {
  const int rows = static_cast<int>(f.differences.size());
  const int cols = rows > 0 ? static_cast<int>(f.differences[0].size()) : 0;
  const int cells_y = std::max(1, std::min(rows, f.max_cells));
  const int cells_x = std::max(1, std::min(cols, f.max_cells));
  const float left = 90, top = 84, side = 600;
  const float plot_w = side,
              plot_h = side * std::min(2.0f, std::max(0.5f, float(rows) / std::max(1, cols)));
  render::Scene scene(static_cast<int>(left + plot_w + 40), static_cast<int>(top + plot_h + 110),
                      render::Rgba{255, 255, 255, 255});
  FittedTitle(scene, {20, 32}, f.title, 20, left + plot_w + 20);
  FittedTitle(scene, {20, 58},
              "darker: more alike (each row on its own scale); white: blank references", 14,
              left + plot_w + 20);
  render::SceneImage image;
  image.left = left;
  image.top = top;
  image.width = plot_w;
  image.height = plot_h;
  image.pixels_wide = cells_x;
  image.pixels_high = cells_y;
  image.rgba.assign(static_cast<size_t>(cells_x) * cells_y * 4, 255);
  // Each row stretched between its own 2nd and 98th percentiles: seasons differ in brightness
  // overall, and a global scale hides the structure of all but the most alike rows.
  std::vector<double> cell(static_cast<size_t>(cells_x) * cells_y, 0.0), count(cell.size(), 0.0);
  for (int q = 0; q < rows; ++q) {
    std::vector<float> sorted = f.differences[q];
    if (sorted.empty()) continue;
    std::sort(sorted.begin(), sorted.end());
    const double lo = sorted[sorted.size() * 2 / 100], hi = sorted[sorted.size() * 98 / 100];
    const int y = static_cast<int>(static_cast<int64_t>(q) * cells_y / rows);
    for (int r = 0; r < cols && r < static_cast<int>(f.differences[q].size()); ++r) {
      const bool blank = r < static_cast<int>(f.blank_references.size()) && f.blank_references[r];
      const double v = blank     ? 1.0
                       : hi > lo ? std::clamp((f.differences[q][r] - lo) / (hi - lo), 0.0, 1.0)
                                 : 0.5;
      const size_t k = static_cast<size_t>(y) * cells_x +
                       static_cast<size_t>(static_cast<int64_t>(r) * cells_x / cols);
      cell[k] += v;
      count[k] += 1;
    }
  }
  for (size_t k = 0; k < cell.size(); ++k) {
    const uint8_t g =
        static_cast<uint8_t>(std::lround(255 * (count[k] > 0 ? cell[k] / count[k] : 1.0)));
    image.rgba[4 * k] = image.rgba[4 * k + 1] = image.rgba[4 * k + 2] = g;
  }
  scene.Image(std::move(image));
  auto at = [&](double reference, double query) {
    return render::ScenePoint{
        static_cast<float>(left + plot_w * (reference + 0.5) / std::max(1, cols)),
        static_cast<float>(top + plot_h * (query + 0.5) / std::max(1, rows))};
  };
  // The true places: a thin blue line through runs of consecutive truths.
  std::vector<render::ScenePoint> line;
  for (int q = 0; q <= rows; ++q) {
    const bool known = q < rows && q < static_cast<int>(f.truth.size()) && f.truth[q] >= 0;
    if (known && !line.empty() && std::abs(f.truth[q] - f.truth[q - 1]) > 5) {
      if (line.size() > 1) scene.Polyline(line, 1.0f, render::Rgba{40, 110, 220, 160});
      line.clear();
    }
    if (known) {
      line.push_back(at(f.truth[q], q));
    } else {
      if (line.size() > 1) scene.Polyline(line, 1.0f, render::Rgba{40, 110, 220, 160});
      line.clear();
    }
  }
  const render::Rgba right{30, 160, 60, 255}, wrong{220, 50, 32, 255};
  for (int q = 0; q < rows && q < static_cast<int>(f.answers.size()); ++q) {
    if (f.answers[q] < 0) continue;
    const bool ok = q < static_cast<int>(f.truth.size()) && f.truth[q] >= 0 &&
                    std::abs(f.answers[q] - f.truth[q]) <= f.frame_tolerance;
    scene.Disc(at(f.answers[q], q), 1.6f, ok ? right : wrong, 6);
  }
  scene.Rect(left, top, plot_w, 1, kInk);
  scene.Text({left + plot_w / 2, top + plot_h + 30},
             "reference frame (0 to " + std::to_string(std::max(0, cols - 1)) + ")", 16, kInk,
             render::TextAnchor::kCenter);
  scene.Text({left - 10, top + 14}, "0", 15, kInk, render::TextAnchor::kRight);
  scene.Text({left - 10, top + plot_h}, std::to_string(std::max(0, rows - 1)), 15, kInk,
             render::TextAnchor::kRight);
  scene.Text({20, top + plot_h / 2}, "query", 16, kInk);
  // The legend, entries side by side as wide as their words.
  const float y = top + plot_h + 70;
  float x = left;
  for (const auto& [color, label, dot] :
       {std::tuple{right, "answer within the tolerance", true},
        std::tuple{wrong, "beyond it", true},
        std::tuple{render::Rgba{40, 110, 220, 255}, "true place", false}}) {
    if (dot) {
      scene.Disc({x + 6, y - 5}, 5, color, 10);
    } else {
      scene.Rect(x, y - 6, 14, 2, color);
    }
    scene.Text({x + 18, y}, label, 15, kInk);
    x += 18 + render::TextWidthPx(label, 15) + 28;
  }
  return scene;
}

}  // namespace ratslam::viewer
