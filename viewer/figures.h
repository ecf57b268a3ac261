// Figures as scenes: the experience map, the template graph (template and experience ids over
// time, as in the Wi-Fi RatSLAM paper's figures 5a, 6 and 8a), pose-cell activity, and a
// similarity matrix. Pure functions of their data; render with a SceneRenderer.
#ifndef RATSLAM_VIEWER_FIGURES_H_
#define RATSLAM_VIEWER_FIGURES_H_

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/geometry.h"
#include "ratslam/experience_map.h"
#include "ratslam/pose_cell_network.h"
#include "ratslam/records.h"
#include "render/scene.h"

namespace ratslam::viewer {

// The figures' ink (text, axes) and grid lines, shared so that every figure looks alike.
inline constexpr render::Rgba kInk{30, 30, 30, 255};
inline constexpr render::Rgba kGrid{225, 225, 225, 255};

// A perceptual sequential colour map for t in [0, 1] (dark blue, teal, green, yellow).
render::Rgba SequentialColor(double t);
// Distinct colours for categories (sessions, floors).
render::Rgba CategoryColor(int index);

// 1, 2 or 5 times a power of ten, near range / target_count.
double NiceStep(double range, int target_count);

// World metres to image pixels with equal x and y scale (y up in the world, down in the image).
struct WorldToImage {
  double scale_px_per_m = 1.0;
  double center_x_m = 0.0, center_y_m = 0.0;
  double center_x_px = 0.0, center_y_px = 0.0;
  render::ScenePoint operator()(double x_m, double y_m) const {
    return {static_cast<float>(center_x_px + scale_px_per_m * (x_m - center_x_m)),
            static_cast<float>(center_y_px - scale_px_per_m * (y_m - center_y_m))};
  }
};

enum class MapColoring { kTime, kSession };

// A world-space view window, metres.
struct WorldBounds {
  double min_x_m = 0, min_y_m = 0, max_x_m = 0, max_y_m = 0;
};

// A title laid out to fit `max_width_px`: smaller type first (down to 13 px, our smallest); then,
// with `max_lines` 2, broken at the space that balances two lines; then the middle of a line
// elided with "..." (a long data-set name keeps its start and end).
struct FittedText {
  std::vector<std::string> lines;
  float height_px = 18;
  // How far below the first line's baseline the last line's is (0 for one line).
  float ExtraHeightPx() const;
};
FittedText FitTitle(const std::string& text, float height_px, float max_width_px,
                    int max_lines = 1);
void DrawTitle(render::Scene& scene, render::ScenePoint position, const FittedText& title,
               render::Rgba color = kInk);
// FitTitle on one line, drawn.
void FittedTitle(render::Scene& scene, render::ScenePoint position, const std::string& text,
                 float height_px, float max_width_px, render::Rgba color = kInk);

struct ExperienceMapImageOptions {
  int width_px = 1600;
  int height_px = 1200;
  std::optional<WorldBounds> bounds;  // fixed view (e.g. shared by per-floor panels); default: fit
  std::optional<std::pair<double, double>> time_range_s;  // fixed colour range; default: the data
  MapColoring coloring = MapColoring::kTime;
  std::vector<double> session_start_times_s;  // ascending; sessions for kSession colouring
  std::vector<std::string> session_names;     // their legend labels ("session N" where missing)
  std::string title;
  // Panels of a multi-floor figure: `legend` false leaves the scale bar and legend out (the
  // band they take stays, so that every panel has the same scale); `legend_data`, when set,
  // decides which legend items appear (the whole map's, not one floor's).
  bool legend = true;
  const struct ExperienceMapImageData* legend_data = nullptr;
};

struct ExperienceMapImageData {
  std::vector<Experience> experiences;
  std::vector<Link> links;
  std::optional<uint32_t> current;   // experience where the robot is
  std::vector<Point2> ground_truth;  // already in the map's frame (see AlignGroundTruthToMap)
};

// The experience map with equal aspect, a scale bar in metres, loop-closure links highlighted,
// the current pose as an arrow, and a time colour bar or a session legend. `transform` receives
// the world-to-pixel mapping used.
render::Scene ExperienceMapScene(const ExperienceMapImageData& data,
                                 const ExperienceMapImageOptions& options,
                                 WorldToImage* transform = nullptr);

// Moves ground-truth points (paired with map points by index) into the map frame with the
// best-fit rigid transform; returns all `truth_path` points transformed.
std::vector<Point2> AlignGroundTruthToMap(const std::vector<Point2>& map_points,
                                          const std::vector<Point2>& truth_points,
                                          const std::vector<Point2>& truth_path);

struct TemplateGraphPoint {
  double time_s = 0.0;
  uint32_t template_id = 0;
  int64_t experience_id = -1;  // -1: none yet
  DecisionSource source = DecisionSource::kCamera;
};

struct TimeSpan {
  double start_s = 0.0, end_s = 0.0;
  std::string label;
};

struct TemplateGraphImageOptions {
  int width_px = 1600;
  int height_px = 1200;
  std::vector<TimeSpan> shaded_spans;  // e.g. sessions, day and night
  std::string title;
};

// Template id (circles, coloured by the deciding sensor; upper panel) and experience id (dots;
// lower panel) against one time axis; shaded spans alternate two shades.
render::Scene TemplateGraphScene(const std::vector<TemplateGraphPoint>& points,
                                 const TemplateGraphImageOptions& options);

struct PoseCellImageOptions {
  int width_px = 1200;
  int height_px = 620;
  std::string title;
};

// The activity summed over theta as an x-y heat map, and the theta marginal as a ring.
render::Scene PoseCellScene(const PoseCellNetwork& network, const PoseCellImageOptions& options);

// A dot on a similarity matrix (row and column in matrix cells), e.g. a loop's correspondences.
struct SimilarityMark {
  int row = 0, col = 0;
  render::Rgba color;
};

struct SimilarityImageOptions {
  int size_px = 1000;
  std::string title;
  std::string value_label = "similarity";
  double value_min = 0.0, value_max = 1.0;                   // the colour scale's ends
  std::vector<SimilarityMark> marks;                         // drawn over the matrix
  std::vector<std::pair<render::Rgba, std::string>> legend;  // what the marks mean, under the title
};

// Scans on the map and the pairs a loop closer matched between them (Kudo and Miura, fig. 10).
struct SequencePairsData {
  std::vector<Point2> positions;  // per scan, on the map
  struct Pair {
    uint32_t current = 0, past = 0;  // scan indices
    bool verified = false;
  };
  std::vector<Pair> pairs;
  // Links the verified pairs made in the map, when known (fewer than the verified pairs where
  // the map already joined the places), shown beside the verified count.
  std::optional<size_t> links_made;
};
// Two panels over the same view: every pair (left) and the verified ones (right); the scans'
// track in grey. The panels are square and `width_px` wide together (0: 1600).
render::Scene SequencePairsScene(const SequencePairsData& data, const std::string& title,
                                 int width_px = 0);

// A field over the plane on a grid of cells (row-major from the south-west corner; NaN: no
// value), drawn as a heat map with its own colour scale (e.g. a GP Wi-Fi map's mean or variance).
struct GridField {
  std::string label;  // panel title, with the unit
  int width = 0, height = 0;
  double cell_size_m = 1.0;
  double origin_x_m = 0.0, origin_y_m = 0.0;  // south-west corner of cell (0, 0)
  std::vector<float> values;
};
// The fields side by side at one scale (each with a colour bar from its lowest to its highest
// value), `points` (e.g. where the data was taken) as dots on every panel, a scale bar.
// `panel_px` is each panel's side.
render::Scene GridFieldsScene(const std::vector<GridField>& fields,
                              const std::vector<Point2>& points, const std::string& title,
                              int panel_px = 700);

// An n x n matrix (row-major, values in [0, 1]) sampled at `times_s` as a heat map.
render::Scene SimilarityMatrixScene(const std::vector<float>& matrix,
                                    const std::vector<double>& times_s,
                                    const SimilarityImageOptions& options);

}  // namespace ratslam::viewer

#endif  // RATSLAM_VIEWER_FIGURES_H_
