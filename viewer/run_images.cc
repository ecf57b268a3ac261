#include "viewer/run_images.h"

#include <algorithm>
#include <filesystem>
#include <limits>
#include <set>

#include "common/geometry.h"
#include "render/vector_figure.h"

namespace ratslam {

std::vector<Point2> GroundTruthInMapFrame(const std::vector<Experience>& experiences,
                                          const Dataset& dataset, double until_time_s,
                                          std::vector<int>* floors) {
  std::vector<Point2> map_points, truth_points, truth_path;
  for (const Experience& e : experiences) {
    if (auto gt = InterpolateGroundTruth(dataset.ground_truth, e.time_s)) {
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

ExperienceMapImageData ExperienceMapDataOf(const RunView& run, const Dataset& dataset) {
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
                                  const Dataset& dataset) {
  std::vector<int> floors;
  floors.reserve(experiences.size());
  for (const Experience& e : experiences) {
    const auto gt = InterpolateGroundTruth(dataset.ground_truth, e.time_s);
    floors.push_back(gt ? gt->floor : 0);
  }
  return floors;
}

std::vector<Scene> ExperienceMapFloorScenes(const ExperienceMapImageData& data,
                                            const std::vector<int>& experience_floors,
                                            const std::vector<int>& ground_truth_floors,
                                            const ExperienceMapImageOptions& panel) {
  std::set<int> distinct(experience_floors.begin(), experience_floors.end());
  if (distinct.size() <= 1 || experience_floors.size() != data.experiences.size()) {
    return {ExperienceMapScene(data, panel)};
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
  std::vector<Scene> panels;
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
      Link k = l;
      k.from = static_cast<uint32_t>(new_id[l.from]);
      k.to = static_cast<uint32_t>(new_id[l.to]);
      subset.links.push_back(k);
    }
    if (data.current && new_id[*data.current] >= 0) {
      subset.current = static_cast<uint32_t>(new_id[*data.current]);
    }
    for (size_t i = 0; i < data.ground_truth.size() && i < ground_truth_floors.size(); ++i) {
      if (ground_truth_floors[i] == floor) subset.ground_truth.push_back(data.ground_truth[i]);
    }
    ExperienceMapImageOptions options = panel;
    options.bounds = bounds;
    options.time_range_s = times;
    options.title = panel.title + ", floor " + std::to_string(floor);
    panels.push_back(ExperienceMapScene(subset, options));
  }
  return panels;
}

StatusOr<RgbaImage> RenderExperienceMapByFloor(SceneRenderer& renderer,
                                               const ExperienceMapImageData& data,
                                               const std::vector<int>& experience_floors,
                                               const std::vector<int>& ground_truth_floors,
                                               const ExperienceMapImageOptions& panel) {
  std::vector<RgbaImage> panels;
  for (const Scene& scene :
       ExperienceMapFloorScenes(data, experience_floors, ground_truth_floors, panel)) {
    StatusOr<RgbaImage> image = renderer.Render(scene);
    if (!image.ok()) return image.status();
    panels.push_back(std::move(image.value()));
  }
  if (panels.size() == 1) return std::move(panels.front());
  // Side by side.
  RgbaImage out;
  out.height = panel.height_px;
  out.width = panel.width_px * static_cast<int>(panels.size());
  out.pixels.resize(static_cast<size_t>(out.width) * out.height * 4);
  for (size_t k = 0; k < panels.size(); ++k) {
    for (int y = 0; y < out.height; ++y) {
      std::copy_n(&panels[k].pixels[static_cast<size_t>(y) * panel.width_px * 4],
                  static_cast<size_t>(panel.width_px) * 4,
                  &out.pixels[(static_cast<size_t>(y) * out.width + k * panel.width_px) * 4]);
    }
  }
  return out;
}

std::vector<TemplateGraphPoint> TemplateGraphOf(const RunView& run) {
  std::vector<TemplateGraphPoint> points;
  points.reserve(run.frames.size());
  for (const FrameRecord& f : run.frames) {
    points.push_back({f.time_s, f.template_id, f.experience_id, f.source});
  }
  return points;
}

Status WriteRunImages(SceneRenderer* renderer, const RunView& run, const Dataset& dataset,
                      const std::string& folder, const std::vector<FigureFormat>& formats,
                      double width_mm) {
  namespace fs = std::filesystem;
  auto targets = [&](const char* name) {
    return FigureTargets((fs::path(folder) / name).string(), &formats);
  };
  auto write = [&](const SceneBuilder& build, int w, int h, const char* name) -> Status {
    return WriteFigure(renderer, build, w, h, targets(name), width_mm).WithContext(name);
  };
  ExperienceMapImageOptions map_options;
  map_options.title = "experience map (" + dataset.name + ")";
  const std::vector<double>& sessions = dataset.session_start_times_s;
  if (sessions.size() > 1) {
    map_options.coloring = MapColoring::kSession;
    map_options.session_start_times_s = sessions;
  }
  {
    // One panel per floor when the ground truth knows several.
    ExperienceMapImageData map_data = ExperienceMapDataOf(run, dataset);
    std::vector<int> truth_floors;
    const auto& trajectory = run.trajectory;
    map_data.ground_truth =
        GroundTruthInMapFrame(map_data.experiences, dataset,
                              trajectory.empty() ? -1.0 : trajectory.back().time_s, &truth_floors);
    const std::vector<int> floors = ExperienceFloors(map_data.experiences, dataset);
    for (const FigureTarget& target : targets("experience_map.png")) {
      if (target.format == FigureFormat::kPng) {
        if (renderer == nullptr) return Status::Error(target.path + ": no PNG renderer");
        StatusOr<RgbaImage> image =
            RenderExperienceMapByFloor(*renderer, map_data, floors, truth_floors, map_options);
        if (!image.ok()) return image.status().WithContext("experience_map.png");
        RATSLAM_RETURN_IF_ERROR(WritePng(image.value(), target.path));
        continue;
      }
      // Vector: one panel per floor, stacked (a column of a paper is narrow), each laid out
      // for the page width.
      const auto [w, h] = VectorLayoutSize(map_options.width_px, map_options.height_px, width_mm);
      ExperienceMapImageOptions panel = map_options;
      panel.width_px = w;
      panel.height_px = h;
      const std::vector<Scene> scenes =
          ExperienceMapFloorScenes(map_data, floors, truth_floors, panel);
      Scene scene(w, h * static_cast<int>(scenes.size()), {255, 255, 255, 255});
      for (size_t k = 0; k < scenes.size(); ++k) {
        scene.Append(scenes[k], 0.0f, static_cast<float>(k * h));
      }
      RATSLAM_RETURN_IF_ERROR(
          WriteVectorFigure(scene, target.path, VectorFormatOf(target.format), width_mm));
    }
  }
  TemplateGraphImageOptions graph_options;
  graph_options.title = "template graph (" + dataset.name + ")";
  // Every other session shaded.
  for (size_t i = 0; sessions.size() > 1 && i < sessions.size(); i += 2) {
    const double end =
        i + 1 < sessions.size() ? sessions[i + 1] : std::numeric_limits<double>::infinity();
    graph_options.shaded_spans.push_back({sessions[i], end, "session " + std::to_string(i + 1)});
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

}  // namespace ratslam
