#include "viewer/figures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>

#include "render/image.h"

namespace ratslam::viewer {
namespace {

constexpr render::Rgba kWhite{255, 255, 255, 255};
constexpr render::Rgba kLoopClosure{220, 50, 32, 255};
constexpr render::Rgba kWifiSequence{
    0, 0, 0, 255};  // links of Wi-Fi sequence loop closure (no category colour)
constexpr render::Rgba kGroundTruth{160, 160, 160, 200};

std::string FormatNumber(double value) {
  char buffer[32];
  if (std::abs(value) >= 1e5 || (std::abs(value) < 1e-3 && value != 0.0)) {
    std::snprintf(buffer, sizeof buffer, "%.3g", value);
  } else {
    std::snprintf(buffer, sizeof buffer, "%.6g", value);
  }
  return buffer;
}

render::Rgba WithAlpha(render::Rgba c, uint8_t alpha) {
  c.a = alpha;
  return c;
}

render::Rgba Mix(render::Rgba a, render::Rgba b, double t) {
  auto lerp = [t](uint8_t x, uint8_t y) {
    return static_cast<uint8_t>(std::lround(x + (y - x) * t));
  };
  return {lerp(a.r, b.r), lerp(a.g, b.g), lerp(a.b, b.b), lerp(a.a, b.a)};
}

// A horizontal gradient strip for colour bars.
render::SceneImage ColorBar(float left, float top, float width, float height) {
  render::SceneImage bar;
  bar.left = left;
  bar.top = top;
  bar.width = width;
  bar.height = height;
  bar.pixels_wide = 256;
  bar.pixels_high = 1;
  bar.smooth = true;
  for (int i = 0; i < 256; ++i) {
    const render::Rgba c = SequentialColor(i / 255.0);
    bar.rgba.insert(bar.rgba.end(), {c.r, c.g, c.b, 255});
  }
  return bar;
}

// Axes with nice ticks for a plot rectangle mapping [x0, x1] x [y0, y1].
struct PlotArea {
  float left, top, width, height;
  double x0, x1, y0, y1;
  render::ScenePoint Map(double x, double y) const {
    return {static_cast<float>(left + (x - x0) / (x1 - x0) * width),
            static_cast<float>(top + height - (y - y0) / (y1 - y0) * height)};
  }
};

void DrawAxes(render::Scene& scene, const PlotArea& p, const std::string& x_label,
              const std::string& y_label, bool grid = true) {
  // At most 8 x and 6 y ticks, fewer on small plots (vector figures are laid out small): a tick
  // label needs about 50 px across and 40 px up.
  const int x_ticks = std::clamp(static_cast<int>(p.width / 50), 2, 8);
  const int y_ticks = std::clamp(static_cast<int>(p.height / 40), 2, 6);
  const double x_step = NiceStep(p.x1 - p.x0, x_ticks), y_step = NiceStep(p.y1 - p.y0, y_ticks);
  for (double x = std::ceil(p.x0 / x_step) * x_step; x <= p.x1 + 1e-9; x += x_step) {
    const render::ScenePoint a = p.Map(x, p.y0);
    if (grid) scene.Line({a.x, p.top}, {a.x, p.top + p.height}, 1.0f, kGrid);
    scene.Line(a, {a.x, a.y + 6}, 1.5f, kInk);
    scene.Text({a.x, a.y + 24}, FormatNumber(x), 15, kInk, render::TextAnchor::kCenter);
  }
  for (double y = std::ceil(p.y0 / y_step) * y_step; y <= p.y1 + 1e-9; y += y_step) {
    const render::ScenePoint a = p.Map(p.x0, y);
    if (grid) scene.Line({p.left, a.y}, {p.left + p.width, a.y}, 1.0f, kGrid);
    scene.Line({a.x - 6, a.y}, a, 1.5f, kInk);
    scene.Text({a.x - 10, a.y + 5}, FormatNumber(y), 15, kInk, render::TextAnchor::kRight);
  }
  scene.Line({p.left, p.top + p.height}, {p.left + p.width, p.top + p.height}, 1.5f, kInk);
  scene.Line({p.left, p.top}, {p.left, p.top + p.height}, 1.5f, kInk);
  if (!x_label.empty()) {
    scene.Text({p.left + p.width / 2, p.top + p.height + 48}, x_label, 16, kInk,
               render::TextAnchor::kCenter);
  }
  scene.Text({p.left - 10, p.top - 14}, y_label, 16, kInk, render::TextAnchor::kLeft);
}

constexpr float kLegendGap = 24;
constexpr float kColorBarWidth = 180;

// A legend entry: its width and how to draw it with its left end at x, centre line at y.
struct LegendItem {
  float width;
  std::function<void(render::Scene&, float x, float y)> draw;
};

// Greedy rows of legend items no wider than `max_width`.
std::vector<std::vector<size_t>> FlowRows(const std::vector<LegendItem>& items, float max_width) {
  std::vector<std::vector<size_t>> rows(1);
  float used = 0;
  for (size_t i = 0; i < items.size(); ++i) {
    const float need = items[i].width + (rows.back().empty() ? 0 : kLegendGap);
    if (!rows.back().empty() && used + need > max_width) {
      rows.emplace_back();
      used = 0;
    }
    used += rows.back().empty() ? items[i].width : need;
    rows.back().push_back(i);
  }
  return rows;
}

float RowLength(const std::vector<LegendItem>& items, const std::vector<size_t>& row) {
  float length = 0;
  for (size_t i : row) length += items[i].width + (length > 0 ? kLegendGap : 0);
  return length;
}

// Draws one row right-aligned at `right`.
void DrawRow(render::Scene& scene, const std::vector<LegendItem>& items,
             const std::vector<size_t>& row, float right, float y) {
  float x = right - RowLength(items, row);
  for (size_t i : row) {
    items[i].draw(scene, x, y);
    x += items[i].width + kLegendGap;
  }
}

}  // namespace

render::Rgba SequentialColor(double t) {
  // Anchors of a dark-blue to yellow ramp with monotonically rising lightness.
  static const render::Rgba kAnchors[] = {{48, 18, 90, 255},   {40, 70, 140, 255},
                                          {30, 120, 142, 255}, {40, 165, 120, 255},
                                          {130, 200, 70, 255}, {240, 225, 40, 255}};
  constexpr int kSegments = static_cast<int>(std::size(kAnchors)) - 1;
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * kSegments;
  const int i = std::min(static_cast<int>(t), kSegments - 1);
  return Mix(kAnchors[i], kAnchors[i + 1], t - i);
}

render::Rgba CategoryColor(int index) {
  // No red: red marks loop closures (a second session in red read as one big loop closure).
  static const render::Rgba kColors[] = {
      {31, 119, 180, 255}, {188, 189, 34, 255}, {44, 160, 44, 255}, {148, 103, 189, 255},
      {255, 127, 14, 255}, {23, 190, 207, 255}, {140, 86, 75, 255}, {227, 119, 194, 255}};
  const int n = static_cast<int>(std::size(kColors));
  return kColors[((index % n) + n) % n];
}

double NiceStep(double range, int target_count) {
  if (!(range > 0.0) || !std::isfinite(range)) return 1.0;
  const double raw = range / std::max(1, target_count);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0}) {
    if (m * power >= raw) return m * power;
  }
  return 10.0 * power;
}

std::vector<Point2> AlignGroundTruthToMap(const std::vector<Point2>& map_points,
                                          const std::vector<Point2>& truth_points,
                                          const std::vector<Point2>& truth_path) {
  // AlignRigid2D maps its first argument onto its second: align truth onto the map.
  const std::optional<RigidAlignment2D> a = AlignRigid2D(truth_points, map_points);
  if (!a) return {};
  std::vector<Point2> out;
  out.reserve(truth_path.size());
  for (const Point2& p : truth_path) out.push_back(Apply(*a, p));
  return out;
}

namespace {

// `text` with its middle elided until it fits `max_width_px` at `height_px`.
std::string ElideMiddle(const std::string& text, float height_px, float max_width_px) {
  std::string fitted = text;
  // A character at a time from the centre outwards.
  for (size_t cut = 1;
       render::TextWidthPx(fitted, height_px) > max_width_px && cut + 2 < text.size(); ++cut) {
    const size_t keep = text.size() - cut;
    fitted = text.substr(0, (keep + 1) / 2) + "..." + text.substr(text.size() - keep / 2);
  }
  return fitted;
}

}  // namespace

float FittedText::ExtraHeightPx() const {
  return lines.size() > 1 ? 1.25f * height_px * static_cast<float>(lines.size() - 1) : 0.0f;
}

FittedText FitTitle(const std::string& text, float height_px, float max_width_px, int max_lines) {
  constexpr float kSmallest = 13.0f;
  FittedText out;
  // Two lines are tried before the type gets small: 15 px is the last size on one line.
  const float one_line_floor = max_lines > 1 ? std::min(height_px, 15.0f) : kSmallest;
  float h = height_px;
  while (h > one_line_floor && render::TextWidthPx(text, h) > max_width_px) h -= 1.0f;
  if (render::TextWidthPx(text, h) <= max_width_px || max_lines < 2) {
    out.height_px = h;
    out.lines = {ElideMiddle(text, h, max_width_px)};
    return out;
  }
  // The break (at a space) that makes the wider of the two lines narrowest.
  size_t best = std::string::npos;
  float best_width = std::numeric_limits<float>::infinity();
  for (size_t i = text.find(' '); i != std::string::npos; i = text.find(' ', i + 1)) {
    const float wider = std::max(render::TextWidthPx(text.substr(0, i), height_px),
                                 render::TextWidthPx(text.substr(i + 1), height_px));
    if (wider < best_width) best_width = wider, best = i;
  }
  if (best == std::string::npos) {
    out.height_px = kSmallest;
    out.lines = {ElideMiddle(text, kSmallest, max_width_px)};
    return out;
  }
  const std::string first = text.substr(0, best), second = text.substr(best + 1);
  h = height_px;
  while (h > kSmallest &&
         std::max(render::TextWidthPx(first, h), render::TextWidthPx(second, h)) > max_width_px) {
    h -= 1.0f;
  }
  out.height_px = h;
  out.lines = {ElideMiddle(first, h, max_width_px), ElideMiddle(second, h, max_width_px)};
  return out;
}

void DrawTitle(render::Scene& scene, render::ScenePoint position, const FittedText& title,
               render::Rgba color) {
  for (size_t i = 0; i < title.lines.size(); ++i) {
    scene.Text({position.x, position.y + 1.25f * title.height_px * static_cast<float>(i)},
               title.lines[i], title.height_px, color);
  }
}

void FittedTitle(render::Scene& scene, render::ScenePoint position, const std::string& text,
                 float height_px, float max_width_px, render::Rgba color) {
  DrawTitle(scene, position, FitTitle(text, height_px, max_width_px), color);
}

namespace {

// World bounds over experiences and ground truth (or the options' fixed bounds); a square of 2 m
// around the origin when there is nothing to bound.
struct MapBounds {
  double min_x, max_x, min_y, max_y;
};
MapBounds BoundsOf(const ExperienceMapImageData& data, const ExperienceMapImageOptions& options) {
  double min_x = std::numeric_limits<double>::infinity(), max_x = -min_x;
  double min_y = min_x, max_y = -min_x;
  auto include = [&](double x, double y) {
    min_x = std::min(min_x, x);
    max_x = std::max(max_x, x);
    min_y = std::min(min_y, y);
    max_y = std::max(max_y, y);
  };
  if (options.bounds) {
    include(options.bounds->min_x_m, options.bounds->min_y_m);
    include(options.bounds->max_x_m, options.bounds->max_y_m);
  } else {
    for (const Experience& e : data.experiences) include(e.x_m, e.y_m);
    for (const Point2& p : data.ground_truth) include(p.x, p.y);
  }
  if (!std::isfinite(min_x)) {
    min_x = min_y = -1;
    max_x = max_y = 1;
  }
  return {min_x, max_x, min_y, max_y};
}

// Legend items (a sample and a label each) of an experience map: ground truth, loop closures,
// Wi-Fi sequence links when there are any, and the colour key (time bar or sessions).
std::vector<LegendItem> MapLegendItems(const ExperienceMapImageData& data,
                                       const ExperienceMapImageOptions& options, double t_first,
                                       double t_last) {
  std::vector<LegendItem> items;
  const ExperienceMapImageData& legend_data = options.legend_data ? *options.legend_data : data;
  if (legend_data.ground_truth.size() > 1) {
    // The truth is drawn in the map's frame after a rigid fit (AlignGroundTruthToMap): say so.
    static const char* const kTruthLabel = "ground truth (rigidly aligned)";
    items.push_back(
        {38 + render::TextWidthPx(kTruthLabel, 14), [](render::Scene& s, float x, float y) {
           s.Line({x, y}, {x + 30, y}, 2.0f, kGroundTruth);
           s.Text({x + 38, y + 5}, kTruthLabel, 14, kInk);
         }});
  }
  items.push_back(
      {38 + render::TextWidthPx("loop closure", 14), [](render::Scene& s, float x, float y) {
         s.Line({x, y}, {x + 30, y}, 3.0f, kLoopClosure);
         s.Text({x + 38, y + 5}, "loop closure", 14, kInk);
       }});
  if (std::any_of(legend_data.links.begin(), legend_data.links.end(),
                  [](const Link& l) { return l.wifi_sequence; })) {
    items.push_back({38 + render::TextWidthPx("Wi-Fi sequence link", 14),
                     [](render::Scene& s, float x, float y) {
                       s.Line({x, y}, {x + 30, y}, 3.0f, kWifiSequence);
                       s.Text({x + 38, y + 5}, "Wi-Fi sequence link", 14, kInk);
                     }});
  }
  if (options.coloring == MapColoring::kTime && std::isfinite(t_first)) {
    // The end labels are centred on the bar's ends: room for half the last one.
    const float half_label = 0.5f * render::TextWidthPx(FormatNumber(t_last) + " s", 13);
    items.push_back(
        {kColorBarWidth + std::max(20.0f, half_label + 6),
         [t_first, t_last](render::Scene& s, float x, float y) {
           s.Image(ColorBar(x, y - 7, kColorBarWidth, 14));
           s.Text({x, y + 24}, FormatNumber(t_first) + " s", 13, kInk, render::TextAnchor::kCenter);
           s.Text({x + kColorBarWidth, y + 24}, FormatNumber(t_last) + " s", 13, kInk,
                  render::TextAnchor::kCenter);
           s.Text({x + kColorBarWidth / 2, y - 12}, "experience created at", 13, kInk,
                  render::TextAnchor::kCenter);
         }});
  } else if (options.coloring == MapColoring::kSession) {
    for (size_t i = 0; i < options.session_start_times_s.size(); ++i) {
      const std::string label =
          i < options.session_names.size() && !options.session_names[i].empty()
              ? options.session_names[i]
              : "session " + std::to_string(i + 1);
      items.push_back(
          {20 + render::TextWidthPx(label, 14), [i, label](render::Scene& s, float x, float y) {
             s.Rect(x, y - 7, 14, 14, CategoryColor(static_cast<int>(i)));
             s.Text({x + 20, y + 5}, label, 14, kInk);
           }});
    }
  }
  return items;
}

// The map itself: ground truth, odometry links coloured by time or session, experiences, loop
// closures over them and the current pose. Strokes thin out for large maps. Returns the number of
// loop closures and how many of them Wi-Fi sequences made.
std::pair<size_t, size_t> DrawExperienceGraph(render::Scene& scene,
                                              const ExperienceMapImageData& data,
                                              const ExperienceMapImageOptions& options,
                                              const WorldToImage& to_image, double t_first,
                                              double t_last, float w, float h) {
  // Time or session of each experience, for colouring.
  auto session_of = [&](double t) {
    const auto& starts = options.session_start_times_s;
    return static_cast<int>(std::upper_bound(starts.begin(), starts.end(), t) - starts.begin()) - 1;
  };
  auto color_of = [&](const Experience& e) {
    if (options.coloring == MapColoring::kSession)
      return CategoryColor(std::max(0, session_of(e.time_s)));
    return SequentialColor(t_last > t_first ? (e.time_s - t_first) / (t_last - t_first) : 0.0);
  };

  // Stay legible from a few links to 100k: thinner, more transparent strokes for larger maps.
  const size_t n_links = data.links.size();
  // Strokes scale with the image (a 2048 px image is not a 1200 px one seen closer).
  const float zoom = std::max(1.0f, std::min(w, h) / 1200.0f);
  const float link_width = zoom * (n_links > 20000 ? 1.2f : (n_links > 2000 ? 1.5f : 2.5f));
  const uint8_t link_alpha = n_links > 20000 ? 200 : 230;
  const float node_radius = data.experiences.size() > 20000  ? 0.0f
                            : data.experiences.size() > 2000 ? 1.5f
                                                             : 3.0f;

  if (data.ground_truth.size() > 1) {
    std::vector<render::ScenePoint> path;
    for (const Point2& p : data.ground_truth) path.push_back(to_image(p.x, p.y));
    scene.Polyline(path, 1.5f, kGroundTruth);
  }
  for (const Link& l : data.links) {
    if (l.loop_closure) continue;
    const Experience& a = data.experiences[l.from];
    const Experience& b = data.experiences[l.to];
    scene.Line(to_image(a.x_m, a.y_m), to_image(b.x_m, b.y_m), link_width,
               WithAlpha(color_of(b), link_alpha));
  }
  if (node_radius > 0) {
    for (const Experience& e : data.experiences) {
      scene.Disc(to_image(e.x_m, e.y_m), node_radius, color_of(e), 10);
    }
  }
  size_t loop_closures = 0, sequence_links = 0;
  for (const Link& l : data.links) {
    if (!l.loop_closure) continue;
    ++loop_closures;
    sequence_links += l.wifi_sequence;
    const Experience& a = data.experiences[l.from];
    const Experience& b = data.experiences[l.to];
    scene.Line(
        to_image(a.x_m, a.y_m), to_image(b.x_m, b.y_m),
        n_links > 20000 ? link_width : link_width + 1.0f,
        WithAlpha(l.wifi_sequence ? kWifiSequence : kLoopClosure, n_links > 20000 ? 150 : 220));
  }
  if (data.current && *data.current < data.experiences.size()) {
    // The current pose: an arrow head pointing along the experience's facing.
    const Experience& e = data.experiences[*data.current];
    const render::ScenePoint c = to_image(e.x_m, e.y_m);
    const float size = 16, dx = std::cos(e.theta_rad), dy = -std::sin(e.theta_rad);
    scene.Triangle(
        {c.x + dx * size, c.y + dy * size},
        {c.x - dx * size * 0.6f - dy * size * 0.5f, c.y - dy * size * 0.6f + dx * size * 0.5f},
        {c.x - dx * size * 0.6f + dy * size * 0.5f, c.y - dy * size * 0.6f - dx * size * 0.5f},
        {0, 0, 0, 255});
  }

  return {loop_closures, sequence_links};
}

}  // namespace

render::Scene ExperienceMapScene(const ExperienceMapImageData& data,
                                 const ExperienceMapImageOptions& options,
                                 WorldToImage* transform) {
  render::Scene scene(options.width_px, options.height_px, kWhite);
  const float w = static_cast<float>(options.width_px), h = static_cast<float>(options.height_px);
  const float margin = 30;
  const FittedText title = FitTitle(options.title.empty() ? "experience map" : options.title, 18,
                                    w - 2 * margin, /*max_lines=*/2);
  const float top_band = 66 + title.ExtraHeightPx();
  // The bottom band holds the scale bar and the legend; the legend moves to a row of its own
  // when both do not fit side by side (small images).
  float bottom_band = 60;

  const MapBounds bounds = BoundsOf(data, options);
  const double min_x = bounds.min_x, max_x = bounds.max_x;
  const double min_y = bounds.min_y, max_y = bounds.max_y;
  const double span_x = std::max(max_x - min_x, 1e-3), span_y = std::max(max_y - min_y, 1e-3);
  // The time range of the colours (shared between panels when the options fix it).
  double t_first = std::numeric_limits<double>::infinity(), t_last = -t_first;
  for (const Experience& e : data.experiences) {
    t_first = std::min(t_first, e.time_s);
    t_last = std::max(t_last, e.time_s);
  }
  if (options.time_range_s) {
    t_first = options.time_range_s->first;
    t_last = options.time_range_s->second;
  }
  // Legend items flowed right to left into rows; the first row sits beside the scale bar when it
  // fits there, further rows stack above it.
  const std::vector<LegendItem> items = MapLegendItems(data, options, t_first, t_last);
  const float row_width = w - 2 * margin;
  const std::vector<std::vector<size_t>> rows = FlowRows(items, row_width);
  auto row_length = [&](const std::vector<size_t>& row) { return RowLength(items, row); };
  constexpr float kScaleBarRoom = 160;  // the scale bar and its label
  const bool first_row_beside_bar =
      row_length(rows.front()) + kScaleBarRoom < row_width && rows.size() == 1;
  const size_t stacked_rows = first_row_beside_bar ? 0 : rows.size();
  bottom_band += 46 * stacked_rows;
  const double plot_w = w - 2 * margin, plot_h = h - top_band - bottom_band;
  WorldToImage to_image;
  to_image.scale_px_per_m = std::min(plot_w / span_x, plot_h / span_y);
  to_image.center_x_m = 0.5 * (min_x + max_x);
  to_image.center_y_m = 0.5 * (min_y + max_y);
  to_image.center_x_px = margin + 0.5 * plot_w;
  to_image.center_y_px = top_band + 0.5 * plot_h;
  if (transform) *transform = to_image;

  const size_t n_links = data.links.size();
  const auto [loop_closures, sequence_links] =
      DrawExperienceGraph(scene, data, options, to_image, t_first, t_last, w, h);

  // Title, and the counts on a line of their own.
  DrawTitle(scene, {margin, 26}, title);
  scene.Text({margin, 50 + title.ExtraHeightPx()},
             std::to_string(data.experiences.size()) + " experiences, " + std::to_string(n_links) +
                 " links, " + std::to_string(loop_closures) +
                 (loop_closures == 1 ? " loop closure" : " loop closures") +
                 (sequence_links ? " (" + std::to_string(sequence_links) + " by Wi-Fi sequences)"
                                 : std::string()),
             14, kInk);

  if (!options.legend) return scene;
  // Scale bar, bottom left: a nice length near a fifth of the plot width.
  const double bar_m = NiceStep(0.2 * plot_w / to_image.scale_px_per_m, 1);
  const float bar_px = static_cast<float>(bar_m * to_image.scale_px_per_m);
  const float bar_y = h - 16;
  scene.Line({margin, bar_y}, {margin + bar_px, bar_y}, 3.0f, kInk);
  scene.Line({margin, bar_y - 7}, {margin, bar_y + 7}, 2.0f, kInk);
  scene.Line({margin + bar_px, bar_y - 7}, {margin + bar_px, bar_y + 7}, 2.0f, kInk);
  scene.Text({margin + bar_px / 2, bar_y - 12}, FormatNumber(bar_m) + " m", 16, kInk,
             render::TextAnchor::kCenter);

  // Legend rows, right-aligned, the last row lowest.
  for (size_t r = 0; r < rows.size(); ++r) {
    // Beside the scale bar the row sits higher, leaving room for colour-bar labels below it.
    const float y = first_row_beside_bar ? bar_y - 16 : bar_y - 46.0f * (rows.size() - r);
    DrawRow(scene, items, rows[r], w - margin, y);
  }
  return scene;
}

render::Scene TemplateGraphScene(const std::vector<TemplateGraphPoint>& points,
                                 const TemplateGraphImageOptions& options) {
  render::Scene scene(options.width_px, options.height_px, kWhite);
  double t0 = std::numeric_limits<double>::infinity(), t1 = -t0;
  for (const TemplateGraphPoint& p : points) {
    t0 = std::min(t0, p.time_s);
    t1 = std::max(t1, p.time_s);
  }
  if (!std::isfinite(t0)) t0 = 0, t1 = 1;
  if (t1 <= t0) t1 = t0 + 1;
  const render::Rgba source_colors[] = {{31, 119, 180, 255}, {44, 160, 44, 255}, {70, 70, 70, 255}};
  static constexpr render::Rgba kExperienceColor{230, 110, 0, 255};
  // Legend, only for what the graph contains, in rows under the title.
  bool present[3] = {false, false, false};
  for (const TemplateGraphPoint& p : points) present[static_cast<int>(p.source)] = true;
  const char* names[3] = {"camera match", "Wi-Fi match", "new template"};
  std::vector<LegendItem> items;
  for (int s = 0; s < 3; ++s) {
    if (!present[s]) continue;
    const std::string name = names[s];
    const render::Rgba color = source_colors[s];
    items.push_back(
        {12 + render::TextWidthPx(name, 14), [s, name, color](render::Scene& sc, float x, float y) {
           if (s == 2) {
             sc.Disc({x + 3, y}, 2.5f, color, 8);
           } else {
             sc.Ring({x + 3, y}, 2.2f, 3.8f, 0, 2 * std::numbers::pi_v<float>, color, 10);
           }
           sc.Text({x + 12, y + 5}, name, 14, kInk);
         }});
  }
  items.push_back(
      {12 + render::TextWidthPx("experience", 14), [](render::Scene& sc, float x, float y) {
         sc.Disc({x + 3, y}, 2.5f, kExperienceColor, 8);
         sc.Text({x + 12, y + 5}, "experience", 14, kInk);
       }});
  // A long title (a data set's name at a column's width) takes a second line, not an ellipsis.
  const FittedText title = FitTitle(options.title.empty() ? "template graph" : options.title, 18,
                                    options.width_px - 40.0f, /*max_lines=*/2);
  const float legend_top = 52 + title.ExtraHeightPx();
  const float right = static_cast<float>(options.width_px) - 30;
  const std::vector<std::vector<size_t>> rows = FlowRows(items, right - 20);
  for (size_t r = 0; r < rows.size(); ++r) {
    DrawRow(scene, items, rows[r], right, legend_top + 24.0f * r);
  }
  // Two panels over one time axis: template ids above, experience ids below (on one axis the
  // experience dots hid under the template circles, their ids being nearly the same).
  const float plot_top = legend_top + 24.0f * rows.size() + 30;
  const float gap = 72;  // the upper panel's tick labels and the lower panel's axis title
  const float both = static_cast<float>(options.height_px) - plot_top - 70;
  const float panel_h = std::max(20.0f, (both - gap) / 2);
  double template_max = 1, experience_max = 1;
  for (const TemplateGraphPoint& p : points) {
    template_max = std::max(template_max, static_cast<double>(p.template_id));
    experience_max = std::max(experience_max, static_cast<double>(p.experience_id));
  }
  const float plot_w = static_cast<float>(options.width_px - 110);
  const PlotArea upper{80, plot_top, plot_w, panel_h, t0, t1, 0, template_max * 1.02};
  const PlotArea lower{80, plot_top + panel_h + gap, plot_w, panel_h, t0, t1,
                       0,  experience_max * 1.02};
  // Spans alternate two shades, so adjacent spans stay apart.
  const render::Rgba span_shades[2] = {{200, 210, 235, 110}, {235, 215, 185, 110}};
  for (size_t k = 0; k < options.shaded_spans.size(); ++k) {
    const TimeSpan& span = options.shaded_spans[k];
    const render::ScenePoint a = upper.Map(std::max(span.start_s, t0), 0);
    const render::ScenePoint b = upper.Map(std::min(span.end_s, t1), 0);
    if (b.x <= a.x) continue;
    for (const PlotArea* plot : {&upper, &lower}) {
      scene.Rect(a.x, plot->top, b.x - a.x, plot->height, span_shades[k % 2]);
    }
    // A label wider than its span (long session names side by side) loses its middle.
    scene.Text({0.5f * (a.x + b.x), upper.top + 20}, ElideMiddle(span.label, 14, b.x - a.x - 8), 14,
               kInk, render::TextAnchor::kCenter);
  }
  DrawAxes(scene, upper, "", "template id");
  DrawAxes(scene, lower, "time (s)", "experience id");
  const bool many = points.size() > 20000;
  // Matches first, new templates over them: a template's later matches start a second after it
  // was made, so their rings would otherwise cover the dot that shows where it was made.
  for (bool new_templates : {false, true}) {
    for (const TemplateGraphPoint& p : points) {
      if ((p.source == DecisionSource::kNew) != new_templates) continue;
      const render::Rgba c = source_colors[static_cast<int>(p.source)];
      const render::ScenePoint at = upper.Map(p.time_s, p.template_id);
      if (new_templates) {
        scene.Disc(at, many ? 1.0f : 2.0f, c, 8);
      } else {
        scene.Ring(at, many ? 1.2f : 2.2f, many ? 2.2f : 3.6f, 0, 2 * std::numbers::pi_v<float>, c,
                   10);
      }
    }
  }
  for (const TemplateGraphPoint& p : points) {
    if (p.experience_id < 0) continue;
    scene.Disc(lower.Map(p.time_s, static_cast<double>(p.experience_id)), many ? 1.0f : 1.8f,
               kExperienceColor, 6);
  }
  DrawTitle(scene, {20, 26}, title);
  return scene;
}

render::Scene PoseCellScene(const PoseCellNetwork& network, const PoseCellImageOptions& options) {
  render::Scene scene(options.width_px, options.height_px, kWhite);
  const int n = network.dim_xy(), nt = network.dim_theta();
  std::vector<double> xy(static_cast<size_t>(n) * n, 0.0), theta(nt, 0.0);
  double xy_max = 0.0, theta_max = 0.0;
  for (int t = 0; t < nt; ++t) {
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const double a = network.Activity(x, y, t);
        xy[static_cast<size_t>(y) * n + x] += a;
        theta[t] += a;
      }
    }
  }
  for (double v : xy) xy_max = std::max(xy_max, v);
  for (double v : theta) theta_max = std::max(theta_max, v);

  // Left: x-y heat map, y up (image row 0 is the largest y).
  const float side = std::min(options.height_px - 190.0f, options.width_px * 0.5f - 100.0f);
  const float left = 80, top = 90;
  render::SceneImage heat;
  heat.left = left;
  heat.top = top;
  heat.width = heat.height = side;
  heat.pixels_wide = heat.pixels_high = n;
  for (int row = 0; row < n; ++row) {
    const int y = n - 1 - row;
    for (int x = 0; x < n; ++x) {
      const render::Rgba c =
          SequentialColor(xy_max > 0 ? xy[static_cast<size_t>(y) * n + x] / xy_max : 0);
      heat.rgba.insert(heat.rgba.end(), {c.r, c.g, c.b, 255});
    }
  }
  scene.Image(std::move(heat));
  const PoseCellPosition best = network.BestPosition();
  const float cell = side / n;
  const render::ScenePoint best_px{left + static_cast<float>(best.x + 0.5) * cell,
                                   top + side - static_cast<float>(best.y + 0.5) * cell};
  scene.Line({best_px.x - 10, best_px.y}, {best_px.x + 10, best_px.y}, 2.0f, {255, 255, 255, 255});
  scene.Line({best_px.x, best_px.y - 10}, {best_px.x, best_px.y + 10}, 2.0f, {255, 255, 255, 255});
  PlotArea axes{left, top, side, side, 0, static_cast<double>(n), 0, static_cast<double>(n)};
  DrawAxes(scene, axes, "x (cells)", "y (cells)", /*grid=*/false);

  // Right: theta marginal on a ring, 0 to the right, counter-clockwise.
  const render::ScenePoint center{options.width_px * 0.75f, top + side / 2};
  const float radius = side * 0.38f;
  const float step = 2 * std::numbers::pi_v<float> / nt;
  for (int t = 0; t < nt; ++t) {
    const render::Rgba c = SequentialColor(theta_max > 0 ? theta[t] / theta_max : 0);
    scene.Ring(center, radius * 0.75f, radius, (t - 0.5f) * step, (t + 0.5f) * step, c, 4);
  }
  const float best_angle = static_cast<float>(best.theta) * step;
  scene.Line(center,
             {center.x + radius * 0.7f * std::cos(best_angle),
              center.y - radius * 0.7f * std::sin(best_angle)},
             3.0f, kInk);
  for (int deg = 0; deg < 360; deg += 90) {
    const float a = deg * std::numbers::pi_v<float> / 180;
    const render::TextAnchor anchor = deg == 0     ? render::TextAnchor::kLeft
                                      : deg == 180 ? render::TextAnchor::kRight
                                                   : render::TextAnchor::kCenter;
    const float offset = deg % 180 == 0 ? 12.0f : 24.0f;
    scene.Text({center.x + (radius + offset) * std::cos(a),
                center.y - (radius + offset) * std::sin(a) + 5},
               std::to_string(deg) + " deg", 14, kInk, anchor);
  }
  char label[128];
  std::snprintf(label, sizeof label, "best pose: x %.2f, y %.2f, theta %.2f cells (%.0f deg)",
                best.x, best.y, best.theta, best.theta * 360.0 / nt);
  if (left + render::TextWidthPx(label, 15) > options.width_px - 10.0f) {  // a narrow page: shorter
    std::snprintf(label, sizeof label, "best: x %.2f, y %.2f cells, heading %.0f deg", best.x,
                  best.y, best.theta * 360.0 / nt);
  }
  scene.Text({left, static_cast<float>(options.height_px - 16)}, label, 15, kInk);
  // Colour bar under the ring: both panels run from zero to their own largest sum.
  {
    // Under the ring, above the best-pose line (which runs under both panels at small widths).
    const float bar_w = std::max(80.0f, std::min(300.0f, options.width_px * 0.5f - 160.0f));
    const float bar_left = center.x - bar_w / 2;
    const float bar_h = 12;
    const float bar_top = static_cast<float>(options.height_px) - 46;
    scene.Image(ColorBar(bar_left, bar_top, bar_w, bar_h));
    scene.Text({bar_left - 8, bar_top + 11}, "0", 14, kInk, render::TextAnchor::kRight);
    scene.Text({bar_left + bar_w + 8, bar_top + 11}, "max", 14, kInk, render::TextAnchor::kLeft);
    char caption[128];
    std::snprintf(caption, sizeof caption, "max: x-y %.3g, heading %.3g", xy_max, theta_max);
    scene.Text({center.x, bar_top - 8}, caption, 14, kInk, render::TextAnchor::kCenter);
  }
  scene.Text({center.x, top - 30}, "heading (summed over x, y)", 15, kInk,
             render::TextAnchor::kCenter);
  scene.Text({20, 26},
             options.title.empty() ? "pose-cell activity (summed over theta)" : options.title, 18,
             kInk);
  return scene;
}

render::Scene SimilarityMatrixScene(const std::vector<float>& matrix,
                                    const std::vector<double>& times_s,
                                    const SimilarityImageOptions& options) {
  const int n = static_cast<int>(times_s.size());
  const int size = options.size_px;
  const float legend_band = options.legend.empty() ? 0 : 24;
  render::Scene scene(size + 190, size + 150 + static_cast<int>(legend_band), kWhite);
  const float left = 80, top = 80 + legend_band;
  const double range =
      options.value_max > options.value_min ? options.value_max - options.value_min : 1.0;
  if (n > 0 && matrix.size() == static_cast<size_t>(n) * n) {
    render::SceneImage heat;
    heat.left = left;
    heat.top = top;
    heat.width = heat.height = static_cast<float>(size);
    heat.pixels_wide = heat.pixels_high = n;
    for (float v : matrix) {
      const render::Rgba c = SequentialColor(std::clamp((v - options.value_min) / range, 0.0, 1.0));
      heat.rgba.insert(heat.rgba.end(), {c.r, c.g, c.b, 255});
    }
    scene.Image(std::move(heat));
    const float cell = static_cast<float>(size) / n;
    for (const SimilarityMark& m : options.marks) {
      if (m.row < 0 || m.row >= n || m.col < 0 || m.col >= n) continue;
      scene.Disc({left + (m.col + 0.5f) * cell, top + (m.row + 0.5f) * cell},
                 std::max(2.5f, 0.5f * cell), m.color, 10);
    }
    // Time runs down the rows, as in a matrix; the y axis labels show it.
    const double t0 = times_s.front(), t1 = times_s.back() > t0 ? times_s.back() : t0 + 1;
    const double step = NiceStep(t1 - t0, 8);
    for (double t = std::ceil(t0 / step) * step; t <= t1 + 1e-9; t += step) {
      const float f = static_cast<float>((t - t0) / (t1 - t0)) * size;
      scene.Line({left + f, top + size}, {left + f, top + size + 6}, 1.5f, kInk);
      scene.Text({left + f, top + size + 24}, FormatNumber(t), 15, kInk,
                 render::TextAnchor::kCenter);
      scene.Line({left - 6, top + f}, {left, top + f}, 1.5f, kInk);
      scene.Text({left - 10, top + f + 5}, FormatNumber(t), 15, kInk, render::TextAnchor::kRight);
    }
  }
  scene.Text({left + size / 2.0f, top + size + 50}, "time (s)", 16, kInk,
             render::TextAnchor::kCenter);
  scene.Text({left - 10, top - 12}, "time (s)", 16, kInk);
  // Colour bar on the right, low values at the bottom.
  render::SceneImage bar = ColorBar(0, 0, 0, 0);
  render::SceneImage vertical;
  vertical.left = left + size + 30;
  vertical.top = top;
  vertical.width = 20;
  vertical.height = static_cast<float>(size);
  vertical.pixels_wide = 1;
  vertical.pixels_high = 256;
  vertical.smooth = true;
  for (int i = 255; i >= 0; --i) {
    vertical.rgba.insert(vertical.rgba.end(), bar.rgba.begin() + i * 4,
                         bar.rgba.begin() + i * 4 + 4);
  }
  scene.Image(std::move(vertical));
  scene.Text({left + size + 55, top + 12}, FormatNumber(options.value_max), 14, kInk);
  scene.Text({left + size + 55, top + size}, FormatNumber(options.value_min), 14, kInk);
  scene.Text({left + size + 40, top - 12}, options.value_label, 14, kInk,
             render::TextAnchor::kCenter);
  scene.Text({20, 26}, options.title.empty() ? "similarity matrix" : options.title, 18, kInk);
  float x = 20;
  for (const auto& [color, label] : options.legend) {
    scene.Disc({x + 5, 49}, 5, color, 10);
    scene.Text({x + 16, 54}, label, 14, kInk);
    x += 40 + render::TextWidthPx(label, 14);
  }
  return scene;
}

render::Scene SequencePairsScene(const SequencePairsData& data, const std::string& title,
                                 int width_px) {
  const int panel = width_px > 0 ? std::max(200, width_px / 2) : 800, top = 80, margin = 30;
  render::Scene scene(2 * panel, panel + top, kWhite);
  double min_x = std::numeric_limits<double>::infinity(), max_x = -min_x, min_y = min_x,
         max_y = -min_x;
  for (const Point2& p : data.positions) {
    min_x = std::min(min_x, p.x);
    max_x = std::max(max_x, p.x);
    min_y = std::min(min_y, p.y);
    max_y = std::max(max_y, p.y);
  }
  if (!std::isfinite(min_x)) min_x = min_y = -1, max_x = max_y = 1;
  const double span = std::max({max_x - min_x, max_y - min_y, 1e-3});
  scene.Text({20, 26}, title, 18, kInk);
  for (int p = 0; p < 2; ++p) {
    WorldToImage to_image;
    to_image.scale_px_per_m = (panel - 2 * margin) / span;
    to_image.center_x_m = 0.5 * (min_x + max_x);
    to_image.center_y_m = 0.5 * (min_y + max_y);
    to_image.center_x_px = p * panel + panel / 2.0;
    to_image.center_y_px = top + panel / 2.0;
    std::vector<render::ScenePoint> track;
    for (const Point2& q : data.positions) track.push_back(to_image(q.x, q.y));
    scene.Polyline(track, 1.5f, kGroundTruth);
    size_t drawn = 0;
    for (const SequencePairsData::Pair& pair : data.pairs) {
      if (pair.current >= data.positions.size() || pair.past >= data.positions.size()) continue;
      if (p == 1 && !pair.verified) continue;
      ++drawn;
      const Point2& a = data.positions[pair.current];
      const Point2& b = data.positions[pair.past];
      scene.Line(to_image(a.x, a.y), to_image(b.x, b.y), 1.5f,
                 WithAlpha(p == 1 ? kWifiSequence : kLoopClosure, 200));
      scene.Disc(to_image(a.x, a.y), 2.5f, kInk, 8);
    }
    // The long caption where the panel has room for it, a short one on a narrow page.
    std::string caption =
        (p == 0 ? "DP pairs before verification: " : "verified: ") + std::to_string(drawn);
    if (p == 1 && data.links_made) caption += ", links made: " + std::to_string(*data.links_made);
    if (render::TextWidthPx(caption, 15) > panel - 30) {
      caption = (p == 0 ? "DP pairs: " : "verified: ") + std::to_string(drawn);
      if (p == 1 && data.links_made) caption += ", links: " + std::to_string(*data.links_made);
    }
    scene.Text({p * panel + 20.0f, 58}, caption, 15, kInk);
  }
  scene.Line({static_cast<float>(panel), static_cast<float>(top)},
             {static_cast<float>(panel), static_cast<float>(top + panel)}, 1.0f, kGrid);
  return scene;
}

render::Scene GridFieldsScene(const std::vector<GridField>& fields,
                              const std::vector<Point2>& points, const std::string& title,
                              int panel_px) {
  const int panel = panel_px, top = 70, bar = 90, bottom = 50;
  const int n = std::max<int>(1, static_cast<int>(fields.size()));
  render::Scene scene(n * (panel + bar), top + panel + bottom, kWhite);
  scene.Text({20, 26}, title, 18, kInk);
  // One world window for every panel: the union of the grids.
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const GridField& g : fields) {
    x0 = std::min(x0, g.origin_x_m);
    y0 = std::min(y0, g.origin_y_m);
    x1 = std::max(x1, g.origin_x_m + g.width * g.cell_size_m);
    y1 = std::max(y1, g.origin_y_m + g.height * g.cell_size_m);
  }
  if (!std::isfinite(x0)) x0 = y0 = 0, x1 = y1 = 1;
  const double scale = (panel - 20) / std::max({x1 - x0, y1 - y0, 1e-3});
  for (size_t k = 0; k < fields.size(); ++k) {
    const GridField& g = fields[k];
    const float left = static_cast<float>(k * (panel + bar) + 10);
    scene.Text({left, top - 12.0f}, g.label, 15, kInk);
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (float v : g.values) {
      if (std::isnan(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    if (!std::isfinite(lo)) lo = 0, hi = 1;
    if (hi <= lo) hi = lo + 1;
    if (g.width > 0 && g.height > 0 && g.values.size() == static_cast<size_t>(g.width) * g.height) {
      render::SceneImage heat;
      heat.left = left + static_cast<float>((g.origin_x_m - x0) * scale);
      heat.top = top + static_cast<float>((y1 - (g.origin_y_m + g.height * g.cell_size_m)) * scale);
      heat.width = static_cast<float>(g.width * g.cell_size_m * scale);
      heat.height = static_cast<float>(g.height * g.cell_size_m * scale);
      heat.pixels_wide = g.width;
      heat.pixels_high = g.height;
      for (int row = g.height - 1; row >= 0; --row) {  // the image's top row is the north
        for (int col = 0; col < g.width; ++col) {
          const float v = g.values[static_cast<size_t>(row) * g.width + col];
          const render::Rgba c = std::isnan(v) ? render::Rgba{255, 255, 255, 0}
                                               : SequentialColor((v - lo) / (hi - lo));
          heat.rgba.insert(heat.rgba.end(), {c.r, c.g, c.b, c.a});
        }
      }
      scene.Image(std::move(heat));
    }
    for (const Point2& p : points) {
      scene.Disc({left + static_cast<float>((p.x - x0) * scale),
                  top + static_cast<float>((y1 - p.y) * scale)},
                 1.6f, kInk, 8);
    }
    // Colour bar, low values at the bottom.
    render::SceneImage strip = ColorBar(0, 0, 0, 0);
    render::SceneImage vertical;
    vertical.left = left + panel;
    vertical.top = top;
    vertical.width = 18;
    vertical.height = panel - 20;
    vertical.pixels_wide = 1;
    vertical.pixels_high = 256;
    vertical.smooth = true;
    for (int i = 255; i >= 0; --i) {
      vertical.rgba.insert(vertical.rgba.end(), strip.rgba.begin() + i * 4,
                           strip.rgba.begin() + i * 4 + 4);
    }
    scene.Image(std::move(vertical));
    scene.Text({left + panel + 24, top + 12.0f}, FormatNumber(std::round(hi * 10) / 10), 13, kInk);
    scene.Text({left + panel + 24, top + panel - 20.0f}, FormatNumber(std::round(lo * 10) / 10), 13,
               kInk);
  }
  const double bar_m = NiceStep(0.2 * (panel - 20) / scale, 1);
  const float bar_px = static_cast<float>(bar_m * scale), y = top + panel + 20.0f;
  scene.Line({10, y}, {10 + bar_px, y}, 3.0f, kInk);
  scene.Text({10 + bar_px / 2, y - 8}, FormatNumber(bar_m) + " m", 14, kInk,
             render::TextAnchor::kCenter);
  return scene;
}

}  // namespace ratslam::viewer
