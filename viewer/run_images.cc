#include "viewer/run_images.h"

#include <algorithm>
#include <filesystem>
#include <limits>
#include <set>

#include "common/geometry.h"
#include "render/vector_figure.h"

namespace ratslam::viewer {

std::vector<Point2> GroundTruthInMapFrame(const std::vector<Experience>& experiences,
                                          const dataset::Dataset& dataset, double until_time_s,
                                          std::vector<int>* floors) {
  std::vector<Point2> map_points, truth_points, truth_path;
  for (const Experience& e : experiences) {
    if (auto gt = dataset::GroundTruthAt(dataset, e.time_s)) {
      map_points.push_back({e.x_m, e.y_m});
      truth_points.push_back({gt->x_m, gt->y_m});
    }
  }
  if (floors) floors->clear();
  for (const GroundTruthRow& row : dataset.ground_truth) {
    if (row.time_s > until_time_s) continue;
    truth_path.push_back({row.x_m, row.y_m});
    if (floors) floors->push_back(row.floor);
  }
  std::vector<Point2> aligned = AlignGroundTruthToMap(map_points, truth_points, truth_path);
  if (floors && aligned.empty()) floors->clear();
  return aligned;
}

ExperienceMapImageData ExperienceMapDataOf(const RunView& run, const dataset::Dataset& dataset) {
  const ExperienceMap& map = run.map;
  ExperienceMapImageData data;
  data.experiences = map.experiences();
  data.links = map.links();
  data.current = map.current();
  // Only the part of the ground truth the run has reached.
  const auto& trajectory = run.trajectory;
  data.ground_truth = GroundTruthInMapFrame(data.experiences, dataset,
                                            trajectory.empty() ? -1.0 : trajectory.back().time_s);
  return data;
}

std::vector<int> ExperienceFloors(const std::vector<Experience>& experiences,
                                  const dataset::Dataset& dataset) {
  std::vector<int> floors;
  floors.reserve(experiences.size());
  const std::vector<GroundTruthRow>& rows = dataset.ground_truth;
  for (const Experience& e : experiences) {
    if (const auto gt = dataset::GroundTruthAt(dataset, e.time_s)) {
      floors.push_back(gt->floor);
      continue;
    }
    // No measured position (before a walk's first point, e.g. a phone's calibration minute, or
    // after its last): drawn on the floor of the ground-truth point nearest in time, not on a
    // floor 0 the building may not have.
    if (rows.empty()) {
      floors.push_back(0);
      continue;
    }
    auto after = std::lower_bound(rows.begin(), rows.end(), e.time_s,
                                  [](const GroundTruthRow& r, double t) { return r.time_s < t; });
    if (after == rows.end() ||
        (after != rows.begin() && e.time_s - (after - 1)->time_s < after->time_s - e.time_s)) {
      --after;
    }
    floors.push_back(after->floor);
  }
  return floors;
}

render::Scene ExperienceMapFloorsScene(const ExperienceMapImageData& data,
                                       const std::vector<int>& experience_floors,
                                       const std::vector<int>& ground_truth_floors,
                                       const ExperienceMapImageOptions& figure, int columns,
                                       FloorPanels* layout) {
  std::set<int> distinct(experience_floors.begin(), experience_floors.end());
  if (distinct.size() <= 1 || experience_floors.size() != data.experiences.size()) {
    if (layout) *layout = {};
    return ExperienceMapScene(data, figure);
  }
  // One view for all panels: the bounds of everything.
  WorldBounds bounds{1e300, 1e300, -1e300, -1e300};
  auto include = [&bounds](double x, double y) {
    bounds.min_x_m = std::min(bounds.min_x_m, x);
    bounds.min_y_m = std::min(bounds.min_y_m, y);
    bounds.max_x_m = std::max(bounds.max_x_m, x);
    bounds.max_y_m = std::max(bounds.max_y_m, y);
  };
  std::pair<double, double> times{1e300, -1e300};
  for (const Experience& e : data.experiences) {
    include(e.x_m, e.y_m);
    times = {std::min(times.first, e.time_s), std::max(times.second, e.time_s)};
  }
  for (const Point2& p : data.ground_truth) include(p.x, p.y);
  const double span_x = std::max(bounds.max_x_m - bounds.min_x_m, 1e-3);
  const double span_y = std::max(bounds.max_y_m - bounds.min_y_m, 1e-3);

  // The grid: the number of columns that draws the map largest in a panel (a panel's plot is
  // its size less the bands ExperienceMapScene keeps: 2 x 30 px across, 66 + 60 px down).
  const int n = static_cast<int>(distinct.size());
  constexpr int kHeading = 34;  // the figure's title above the panels
  const int w = figure.width_px, h = figure.height_px;
  if (columns <= 0) {
    double best = -1.0;
    for (int c = 1; c <= n; ++c) {
      const int rows = (n + c - 1) / c;
      const double scale =
          std::min((w / c - 60.0) / span_x, ((h - kHeading) / rows - 126.0) / span_y);
      if (scale > best + 1e-12) best = scale, columns = c;
    }
  }
  columns = std::min(columns, n);
  const int rows = (n + columns - 1) / columns;
  const int panel_w = w / columns, panel_h = (h - kHeading) / rows;
  if (layout) *layout = {columns, panel_w, panel_h, kHeading, {distinct.begin(), distinct.end()}};

  render::Scene scene(w, h, {255, 255, 255, 255});
  FittedTitle(scene, {30, 24}, figure.title.empty() ? "experience map" : figure.title, 18,
              w - 60.0f);
  int k = 0;
  for (int floor : distinct) {
    ExperienceMapImageData subset;
    std::vector<int64_t> new_id(data.experiences.size(), -1);
    for (size_t i = 0; i < data.experiences.size(); ++i) {
      if (experience_floors[i] != floor) continue;
      new_id[i] = static_cast<int64_t>(subset.experiences.size());
      Experience e = data.experiences[i];
      e.id = static_cast<uint32_t>(new_id[i]);
      subset.experiences.push_back(e);
    }
    for (const Link& l : data.links) {
      if (new_id[l.from] < 0 || new_id[l.to] < 0) continue;  // links between floors are left out
      Link link = l;
      link.from = static_cast<uint32_t>(new_id[l.from]);
      link.to = static_cast<uint32_t>(new_id[l.to]);
      subset.links.push_back(link);
    }
    if (data.current && new_id[*data.current] >= 0) {
      subset.current = static_cast<uint32_t>(new_id[*data.current]);
    }
    for (size_t i = 0; i < data.ground_truth.size() && i < ground_truth_floors.size(); ++i) {
      if (ground_truth_floors[i] == floor) subset.ground_truth.push_back(data.ground_truth[i]);
    }
    ExperienceMapImageOptions options = figure;
    options.width_px = panel_w;
    options.height_px = panel_h;
    options.bounds = bounds;
    options.time_range_s = times;
    options.title = "floor " + std::to_string(floor);
    // One legend and scale bar for the figure (every panel has the same scale): in the last.
    options.legend = k == n - 1;
    options.legend_data = &data;
    scene.Append(ExperienceMapScene(subset, options), static_cast<float>(k % columns * panel_w),
                 static_cast<float>(kHeading + k / columns * panel_h));
    ++k;
  }
  return scene;
}

ExperienceMapFigure ExperienceMapFigureOf(ExperienceMapImageData data,
                                          const dataset::Dataset& dataset, double until_time_s) {
  ExperienceMapFigure figure;
  figure.options.title = "experience map (" + dataset.name + ")";
  if (dataset.session_start_times_s.size() > 1) {
    figure.options.coloring = MapColoring::kSession;
    figure.options.session_start_times_s = dataset.session_start_times_s;
    for (size_t i = 0; i < dataset.session_start_times_s.size(); ++i) {
      figure.options.session_names.push_back(dataset.SessionName(i));
    }
  }
  data.ground_truth =
      GroundTruthInMapFrame(data.experiences, dataset, until_time_s, &figure.truth_floors);
  figure.floors = ExperienceFloors(data.experiences, dataset);
  figure.data = std::move(data);
  return figure;
}

std::vector<TemplateGraphPoint> TemplateGraphOf(const RunView& run) {
  std::vector<TemplateGraphPoint> points;
  points.reserve(run.frames.size());
  for (const FrameRecord& f : run.frames) {
    points.push_back({f.time_s, f.template_id, f.experience_id, f.source});
  }
  return points;
}

Status WriteRunImages(render::SceneRenderer* renderer, const RunView& run,
                      const dataset::Dataset& dataset, const std::string& folder,
                      const std::vector<FigureFormat>& formats, double width_mm) {
  namespace fs = std::filesystem;
  auto targets = [&](const char* name) {
    return FigureTargets((fs::path(folder) / name).string(), &formats);
  };
  auto write = [&](const SceneBuilder& build, int w, int h, const char* name) -> Status {
    return WriteFigure(renderer, build, w, h, targets(name), width_mm).WithContext(name);
  };
  const std::vector<double>& sessions = dataset.session_start_times_s;
  {
    ExperienceMapImageData run_data;
    run_data.experiences = run.map.experiences();
    run_data.links = run.map.links();
    run_data.current = run.map.current();
    ExperienceMapFigure figure = ExperienceMapFigureOf(
        std::move(run_data), dataset, run.trajectory.empty() ? -1.0 : run.trajectory.back().time_s);
    ExperienceMapImageData& map_data = figure.data;
    std::vector<int>& truth_floors = figure.truth_floors;
    std::vector<int>& floors = figure.floors;
    ExperienceMapImageOptions& map_options = figure.options;
    if (run.localisation) {
      // The map is another run's: this data set's path, placed by the frames localised (the
      // experiences' times belong to the other data set), on one panel.
      map_options.title = "localisation on a saved map (" + dataset.name + ")";
      std::vector<Point2> localised, truth, path;
      for (const LocalisationRecord& r : *run.localisation) {
        const auto gt = dataset::GroundTruthAt(dataset, r.time_s);
        if (!gt) continue;
        path.push_back({gt->x_m, gt->y_m});
        if (r.lost) continue;
        localised.push_back({r.x_m, r.y_m});
        truth.push_back({gt->x_m, gt->y_m});
      }
      map_data.ground_truth = AlignGroundTruthToMap(localised, truth, path);
      truth_floors.clear();
      std::fill(floors.begin(), floors.end(), 0);
    }
    for (const FigureTarget& target : targets("experience_map.png")) {
      if (target.format == FigureFormat::kPng) {
        if (renderer == nullptr) return Status::Error(target.path + ": no PNG renderer");
        StatusOr<render::RgbaImage> image =
            renderer->Render(ExperienceMapFloorsScene(map_data, floors, truth_floors, map_options));
        if (!image.ok()) return image.status().WithContext("experience_map.png");
        RATSLAM_RETURN_IF_ERROR(render::WritePng(image.value(), target.path));
        continue;
      }
      // Vector: one panel per floor, stacked (a column of a paper is narrow), each as large as
      // a single-floor map on the page.
      const auto [w, h] = VectorLayoutSize(map_options.width_px, map_options.height_px, width_mm);
      const int panels = static_cast<int>(std::set<int>(floors.begin(), floors.end()).size());
      ExperienceMapImageOptions page = map_options;
      page.width_px = w;
      page.height_px = panels > 1 ? 34 + panels * h : h;
      RATSLAM_RETURN_IF_ERROR(render::WriteVectorFigure(
          ExperienceMapFloorsScene(map_data, floors, truth_floors, page, /*columns=*/1),
          target.path, VectorFormatOf(target.format), width_mm));
    }
  }
  TemplateGraphImageOptions graph_options;
  graph_options.title = "template graph (" + dataset.name + ")";
  // Each session a shaded span with its name (the figure alternates two shades).
  for (size_t i = 0; sessions.size() > 1 && i < sessions.size(); ++i) {
    const double end =
        i + 1 < sessions.size() ? sessions[i + 1] : std::numeric_limits<double>::infinity();
    graph_options.shaded_spans.push_back({sessions[i], end, dataset.SessionName(i)});
  }
  const std::vector<TemplateGraphPoint> points = TemplateGraphOf(run);
  RATSLAM_RETURN_IF_ERROR(write(
      Sized(graph_options,
            [&](const TemplateGraphImageOptions& o) { return TemplateGraphScene(points, o); }),
      graph_options.width_px, graph_options.height_px, "template_graph.png"));
  const PoseCellImageOptions cell_options;
  return write(
      Sized(cell_options,
            [&](const PoseCellImageOptions& o) { return PoseCellScene(run.pose_cells, o); }),
      cell_options.width_px, cell_options.height_px, "pose_cells.png");
}

}  // namespace ratslam::viewer
