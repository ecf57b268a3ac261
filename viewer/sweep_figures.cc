#include "viewer/sweep_figures.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "render/image.h"
#include "viewer/figures.h"

namespace ratslam::viewer {
namespace {

constexpr render::Rgba kDot{70, 110, 170, 200};
constexpr render::Rgba kBest{215, 40, 40, 255};
constexpr float kLabelGapPx = 6.0f;  // least space between two tick labels

std::optional<double> AsNumber(const std::string& text) {
  double v = 0.0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (r.ec != std::errc() || r.ptr != text.data() + text.size()) return std::nullopt;
  return v;
}

std::string Short(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

// Where a parameter's values go along an axis of unit length: numbers linearly, anything else
// (or a single number) evenly in order of first appearance.
class ValueAxis {
 public:
  explicit ValueAxis(const std::vector<std::string>& values) {
    for (const std::string& v : values) {
      if (std::find(distinct_.begin(), distinct_.end(), v) == distinct_.end()) {
        distinct_.push_back(v);
      }
    }
    numeric_ = distinct_.size() > 1;
    for (const std::string& v : distinct_) {
      const std::optional<double> x = AsNumber(v);
      if (!x) {
        numeric_ = false;
        break;
      }
      lo_ = std::min(lo_, *x);
      hi_ = std::max(hi_, *x);
    }
    if (numeric_ && !(hi_ > lo_)) numeric_ = false;
    if (!numeric_) {
      std::sort(distinct_.begin(), distinct_.end(), [](const std::string& a, const std::string& b) {
        const auto x = AsNumber(a), y = AsNumber(b);
        return x && y ? *x < *y : a < b;
      });
    }
  }
  double operator()(const std::string& v) const {
    if (numeric_) return 0.05 + 0.9 * (*AsNumber(v) - lo_) / (hi_ - lo_);
    const auto it = std::find(distinct_.begin(), distinct_.end(), v);
    return (static_cast<double>(it - distinct_.begin()) + 0.5) / distinct_.size();
  }
  const std::vector<std::string>& distinct() const { return distinct_; }

 private:
  std::vector<std::string> distinct_;
  bool numeric_ = false;
  double lo_ = std::numeric_limits<double>::infinity();
  double hi_ = -std::numeric_limits<double>::infinity();
};

struct Range {
  double lo = 0.0, hi = 1.0;
  double Fraction(double v) const { return (v - lo) / (hi - lo); }
};

Range ObjectiveRange(const SweepFigureData& data) {
  Range r{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const SweepFigurePoint& p : data.points) {
    if (!p.objective) continue;
    r.lo = std::min(r.lo, *p.objective);
    r.hi = std::max(r.hi, *p.objective);
  }
  if (!std::isfinite(r.lo)) return {0.0, 1.0};
  const double pad = r.hi > r.lo ? 0.05 * (r.hi - r.lo) : std::max(1e-9, 0.05 * std::abs(r.lo));
  return {r.lo - pad, r.hi + pad};
}

// A left axis with ticks for `range` over a panel.
void ValueTicks(render::Scene& scene, const Range& range, float left, float top, float width,
                float height) {
  const double step = NiceStep(range.hi - range.lo, 5);
  for (double v = std::ceil(range.lo / step) * step; v <= range.hi; v += step) {
    if (std::abs(v) < 1e-9 * step) v = 0.0;  // a sum of steps near 0 printed as "-0"
    const float y = top + height * static_cast<float>(1.0 - range.Fraction(v));
    scene.Line({left, y}, {left + width, y}, 1.0f, kGrid);
    scene.Text({left - 8, y + 5}, Short(v), 14, kInk, render::TextAnchor::kRight);
  }
  scene.Line({left, top + height}, {left + width, top + height}, 1.5f, kInk);
  scene.Line({left, top}, {left, top + height}, 1.5f, kInk);
}

// The value axis's title: the objective, with the unit its name ends in (map_ate_m: m).
std::string ValueAxisTitle(const SweepFigureData& data) {
  // The objective as the sweep aggregates it ("mean map_ate_m"): the unit is the metric's.
  std::string o = data.objective;
  for (const char* aggregate : {"mean ", "worst "}) {
    if (o.rfind(aggregate, 0) == 0) o = o.substr(std::string(aggregate).size());
  }
  auto ends = [&](const std::string& suffix) {
    return o.size() > suffix.size() &&
           o.compare(o.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  const bool plain = o.find_first_of(" +-*/()") == std::string::npos;
  const std::string& title = data.objective;
  if (plain && ends("_m")) return title + " (m)";
  if (plain && ends("_s")) return title + " (s)";
  if (plain && ends("_db")) return title + " (dB)";
  if (plain && ends("_ms")) return title + " (ms)";
  return title;
}

std::string Goal(const SweepFigureData& data) {
  return data.objective + (data.minimize ? " (lower is better)" : " (higher is better)");
}

// The subtitle in lines that fit `width_px` (split after "; " first, else at a space).
std::vector<std::string> SubtitleLines(const std::string& text, float width_px) {
  const float room = width_px - 40;
  if (render::TextWidthPx(text, 15) <= room) return {text};
  if (size_t semi = text.find("; "); semi != std::string::npos) {
    return {text.substr(0, semi + 1), text.substr(semi + 2)};
  }
  size_t cut = text.rfind(' ');
  while (cut != std::string::npos && cut > 0 &&
         render::TextWidthPx(text.substr(0, cut), 15) > room) {
    cut = text.rfind(' ', cut - 1);
  }
  if (cut == std::string::npos || cut == 0) return {text};
  return {text.substr(0, cut), text.substr(cut + 1)};
}

// The title and subtitle lines; returns how far the subtitle's extra lines push the plot down.
float Heading(render::Scene& scene, const std::string& title,
              const std::vector<std::string>& lines) {
  scene.Text({20, 32}, title, 20, kInk);
  for (size_t i = 0; i < lines.size(); ++i) {
    scene.Text({20, 58 + 20.0f * i}, lines[i], 15, kInk);
  }
  return 20.0f * (lines.size() - 1);
}

}  // namespace

render::Scene SweepParameterScene(const SweepFigureData& data, int width_px) {
  const int panels = std::max<int>(1, static_cast<int>(data.keys.size()));
  const float panel_w = 380, panel_h = 280, left0 = 90, gap_x = 110, gap_y = 110;
  // Up to three panels a row, fewer when a given width holds fewer.
  const int fit = width_px > 0 ? static_cast<int>((width_px - left0) / (panel_w + gap_x)) : 3;
  const int columns = std::clamp(fit, 1, std::min(panels, 3));
  const int rows = (panels + columns - 1) / columns;
  const float scene_w = left0 + columns * (panel_w + gap_x);
  const std::vector<std::string> lines =
      SubtitleLines(Goal(data) + " of each point; the best in red", scene_w);
  const float top0 = 100 + 20.0f * (lines.size() - 1);  // the value-axis title clears the heading
  render::Scene scene(static_cast<int>(scene_w), static_cast<int>(top0 + rows * (panel_h + gap_y)),
                      render::Rgba{255, 255, 255, 255});
  Heading(scene, data.title, lines);
  const Range range = ObjectiveRange(data);
  for (int k = 0; k < static_cast<int>(data.keys.size()); ++k) {
    const float left = left0 + (k % columns) * (panel_w + gap_x);
    const float top = top0 + (k / columns) * (panel_h + gap_y);
    std::vector<std::string> values;
    for (const SweepFigurePoint& p : data.points) values.push_back(p.values.at(k));
    const ValueAxis axis(values);
    ValueTicks(scene, range, left, top, panel_w, panel_h);
    scene.Text({left - 8, top - 12}, ValueAxisTitle(data), 14, kInk);
    // A tick at every value; labels left to right, each only where it clears the last one drawn
    // (values close together on a numeric axis printed over each other).
    float last_label_right = -std::numeric_limits<float>::infinity();
    for (const std::string& value : axis.distinct()) {
      const float x = left + panel_w * static_cast<float>(axis(value));
      scene.Line({x, top + panel_h}, {x, top + panel_h + 5}, 1.0f, kInk);
      const float half = render::TextWidthPx(value, 13) / 2;
      if (x - half < last_label_right + kLabelGapPx) continue;
      scene.Text({x, top + panel_h + 22}, value, 13, kInk, render::TextAnchor::kCenter);
      last_label_right = x + half;
    }
    scene.Text({left + panel_w / 2, top + panel_h + 48}, data.keys[k], 15, kInk,
               render::TextAnchor::kCenter);
    auto at = [&](const SweepFigurePoint& p) {
      return render::ScenePoint{
          left + panel_w * static_cast<float>(axis(p.values[k])),
          top + panel_h * static_cast<float>(1.0 - range.Fraction(*p.objective))};
    };
    for (const SweepFigurePoint& p : data.points) {
      if (p.objective) scene.Disc(at(p), 3.5f, kDot);
    }
    if (data.best) scene.Disc(at(data.points[*data.best]), 6.0f, kBest);
  }
  return scene;
}

// The heat map's colour scale beside its cells: the objective along the bar (higher values up),
// coloured as the cells are (bright is better), with ticks and labels at the sweep's worst and
// best values.
void ColourBar(render::Scene& scene, const SweepFigureData& data, const Range& range, float left,
               float top, float height) {
  constexpr float kBarWidth = 18;
  constexpr int kSteps = 64;
  auto colour = [&](double v) {
    double t = range.Fraction(v);
    if (!data.minimize) t = 1.0 - t;
    return SequentialColor(1.0 - t);
  };
  const float step_h = height / kSteps;
  for (int k = 0; k < kSteps; ++k) {
    const double v = range.lo + (range.hi - range.lo) * (k + 0.5) / kSteps;
    scene.Rect(left, top + height - step_h * (k + 1), kBarWidth, step_h + 0.5f, colour(v));
  }
  std::optional<double> lo, hi;
  for (const SweepFigurePoint& p : data.points) {
    if (!p.objective) continue;
    lo = lo ? std::min(*lo, *p.objective) : *p.objective;
    hi = hi ? std::max(*hi, *p.objective) : *p.objective;
  }
  if (!lo) return;
  for (double v : {*lo, *hi}) {
    const float y = top + height * static_cast<float>(1.0 - range.Fraction(v));
    scene.Line({left + kBarWidth, y}, {left + kBarWidth + 6, y}, 1.5f, kInk);
    scene.Text({left + kBarWidth + 10, y + 5}, Short(v), 13, kInk);
  }
}

render::Scene SweepHeatmapScene(const SweepFigureData& data, int a, int b, int width_px) {
  std::vector<std::string> xs, ys;
  for (const SweepFigurePoint& p : data.points) {
    xs.push_back(p.values.at(a));
    ys.push_back(p.values.at(b));
  }
  const ValueAxis x_axis(xs), y_axis(ys);
  const auto& columns = x_axis.distinct();
  const auto& rows = y_axis.distinct();
  const float left = 150;
  // A given width sets the cells' width (at least wide enough for a 4-digit label).
  const float cell_w =
      width_px > 0 ? std::max(44.0f, (width_px - left - 110) / static_cast<float>(columns.size()))
                   : std::max(60.0f, 560.0f / columns.size());
  const float cell_h = std::max(34.0f, 380.0f / rows.size());
  const float width = cell_w * columns.size(), height = cell_h * rows.size();
  // Room on the right for the colour bar and its labels.
  const float bar_room = 110;
  const int scene_w =
      std::max(width_px > 0 ? width_px : 760, static_cast<int>(left + width + bar_room));
  const std::vector<std::string> lines =
      SubtitleLines("best " + Goal(data) + " over the other parameters", scene_w);
  const float top = 120 + 20.0f * (lines.size() - 1);
  render::Scene scene(scene_w, static_cast<int>(top + height + 90),
                      render::Rgba{255, 255, 255, 255});
  Heading(scene, data.title, lines);
  const Range range = ObjectiveRange(data);
  for (size_t c = 0; c < columns.size(); ++c) {
    for (size_t r = 0; r < rows.size(); ++r) {
      std::optional<double> best;
      for (const SweepFigurePoint& p : data.points) {
        if (!p.objective || p.values[a] != columns[c] || p.values[b] != rows[r]) continue;
        if (!best || (data.minimize ? *p.objective < *best : *p.objective > *best)) {
          best = p.objective;
        }
      }
      const float cx = left + cell_w * c, cy = top + height - cell_h * (r + 1);
      if (!best) {
        scene.Rect(cx + 1, cy + 1, cell_w - 2, cell_h - 2, kGrid);
        continue;
      }
      // Bright is good whichever the goal (the colour bar shows the scale).
      double t = range.Fraction(*best);
      if (!data.minimize) t = 1.0 - t;
      scene.Rect(cx + 1, cy + 1, cell_w - 2, cell_h - 2, SequentialColor(1.0 - t));
      scene.Text({cx + cell_w / 2, cy + cell_h / 2 + 5}, Short(*best), 13,
                 t < 0.5 ? kInk : render::Rgba{255, 255, 255, 255}, render::TextAnchor::kCenter);
    }
  }
  for (size_t c = 0; c < columns.size(); ++c) {
    scene.Text({left + cell_w * (c + 0.5f), top + height + 22}, columns[c], 13, kInk,
               render::TextAnchor::kCenter);
  }
  for (size_t r = 0; r < rows.size(); ++r) {
    scene.Text({left - 10, top + height - cell_h * (r + 0.5f) + 5}, rows[r], 13, kInk,
               render::TextAnchor::kRight);
  }
  scene.Text({left + width / 2, top + height + 50}, data.keys[a], 15, kInk,
             render::TextAnchor::kCenter);
  scene.Text({20, top - 16}, data.keys[b], 15, kInk);
  ColourBar(scene, data, range, left + width + 24, top, height);
  return scene;
}

render::Scene SweepParetoScene(const SweepFigureData& data, int width_px) {
  const float left = 100, height = 420;
  const float width = width_px > 0 ? std::max(300.0f, width_px - left - 60.0f) : 700.0f;
  const std::vector<std::string> lines =
      SubtitleLines(Goal(data) + " against run time; the Pareto front in red", left + width + 60);
  const float top = 100 + 20.0f * (lines.size() - 1);  // likewise
  render::Scene scene(static_cast<int>(left + width + 60), static_cast<int>(top + height + 90),
                      render::Rgba{255, 255, 255, 255});
  Heading(scene, data.title, lines);
  const Range y = ObjectiveRange(data);
  Range x{std::numeric_limits<double>::infinity(), 0.0};
  for (const SweepFigurePoint& p : data.points) {
    if (!p.objective) continue;
    x.lo = std::min(x.lo, p.mean_wall_s);
    x.hi = std::max(x.hi, p.mean_wall_s);
  }
  if (!std::isfinite(x.lo)) x = {0.0, 1.0};
  const double pad = x.hi > x.lo ? 0.05 * (x.hi - x.lo) : std::max(1e-3, 0.05 * x.lo);
  x = {std::max(0.0, x.lo - pad), x.hi + pad};
  ValueTicks(scene, y, left, top, width, height);
  scene.Text({left - 8, top - 12}, ValueAxisTitle(data), 14, kInk);
  const double step = NiceStep(x.hi - x.lo, 6);
  for (double v = std::ceil(x.lo / step) * step; v <= x.hi; v += step) {
    const float px = left + width * static_cast<float>(x.Fraction(v));
    scene.Line({px, top}, {px, top + height}, 1.0f, kGrid);
    scene.Text({px, top + height + 22}, Short(v), 14, kInk, render::TextAnchor::kCenter);
  }
  scene.Text({left + width / 2, top + height + 50}, "mean wall time per run (s)", 15, kInk,
             render::TextAnchor::kCenter);
  auto at = [&](const SweepFigurePoint& p) {
    return render::ScenePoint{left + width * static_cast<float>(x.Fraction(p.mean_wall_s)),
                              top + height * static_cast<float>(1.0 - y.Fraction(*p.objective))};
  };
  std::vector<const SweepFigurePoint*> ranked;
  for (const SweepFigurePoint& p : data.points) {
    if (!p.objective) continue;
    ranked.push_back(&p);
    scene.Disc(at(p), 3.5f, kDot);
  }
  // The front: by time, each point better than every faster one.
  std::sort(ranked.begin(), ranked.end(),
            [&](const SweepFigurePoint* a, const SweepFigurePoint* b) {
              if (a->mean_wall_s != b->mean_wall_s) return a->mean_wall_s < b->mean_wall_s;
              return data.minimize ? *a->objective < *b->objective : *a->objective > *b->objective;
            });
  std::vector<render::ScenePoint> front;
  std::optional<double> best;
  for (const auto* p : ranked) {
    if (best && !(data.minimize ? *p->objective < *best : *p->objective > *best)) continue;
    best = p->objective;
    front.push_back(at(*p));
    scene.Disc(front.back(), 5.0f, kBest);
  }
  if (front.size() > 1) scene.Polyline(front, 2.0f, kBest);
  return scene;
}

}  // namespace ratslam::viewer
