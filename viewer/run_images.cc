#include "viewer/run_images.h"

#include <filesystem>
#include <limits>

#include "fusion/trajectory_metrics.h"

namespace ratslam {

std::vector<Point2> GroundTruthInMapFrame(const std::vector<Experience>& experiences,
                                          const Dataset& dataset, double until_time_s) {
  std::vector<Point2> map_points, truth_points, truth_path;
  for (const Experience& e : experiences) {
    if (auto gt = InterpolateGroundTruth(dataset.ground_truth, e.time_s)) {
      map_points.push_back({e.x_m, e.y_m});
      truth_points.push_back({gt->x_m, gt->y_m});
    }
  }
  for (const GroundTruthRow& row : dataset.ground_truth) {
    if (row.time_s <= until_time_s) truth_path.push_back({row.x_m, row.y_m});
  }
  return AlignGroundTruthToMap(map_points, truth_points, truth_path);
}

ExperienceMapImageData ExperienceMapDataOf(const ReplayPipeline& pipeline, const Dataset& dataset) {
  const ExperienceMap& map = pipeline.slam().experience_map();
  ExperienceMapImageData data;
  data.experiences = map.experiences();
  data.links = map.links();
  data.current = map.current();
  // Only the part of the ground truth the run has reached.
  const auto& trajectory = pipeline.state().trajectory;
  data.ground_truth = GroundTruthInMapFrame(data.experiences, dataset,
                                            trajectory.empty() ? -1.0 : trajectory.back().time_s);
  return data;
}

std::vector<TemplateGraphPoint> TemplateGraphOf(const ReplayPipeline& pipeline) {
  std::vector<TemplateGraphPoint> points;
  points.reserve(pipeline.state().frames.size());
  for (const FrameRecord& f : pipeline.state().frames) {
    points.push_back({f.time_s, f.template_id, f.experience_id, f.source});
  }
  return points;
}

Status WriteRunImages(SceneRenderer& renderer, const ReplayPipeline& pipeline,
                      const Dataset& dataset, const std::string& folder) {
  namespace fs = std::filesystem;
  auto write = [&](const Scene& scene, const char* name) -> Status {
    StatusOr<RgbaImage> image = renderer.Render(scene);
    if (!image.ok()) return image.status().WithContext(name);
    return WritePng(image.value(), (fs::path(folder) / name).string());
  };
  ExperienceMapImageOptions map_options;
  map_options.title = "experience map (" + dataset.name + ")";
  const std::vector<double>& sessions = dataset.session_start_times_s;
  if (sessions.size() > 1) {
    map_options.coloring = MapColoring::kSession;
    map_options.session_start_times_s = sessions;
  }
  RATSLAM_RETURN_IF_ERROR(
      write(ExperienceMapScene(ExperienceMapDataOf(pipeline, dataset), map_options),
            "experience_map.png"));
  TemplateGraphImageOptions graph_options;
  graph_options.title = "template graph (" + dataset.name + ")";
  // Every other session shaded.
  for (size_t i = 0; sessions.size() > 1 && i < sessions.size(); i += 2) {
    const double end =
        i + 1 < sessions.size() ? sessions[i + 1] : std::numeric_limits<double>::infinity();
    graph_options.shaded_spans.push_back({sessions[i], end, "session " + std::to_string(i + 1)});
  }
  RATSLAM_RETURN_IF_ERROR(
      write(TemplateGraphScene(TemplateGraphOf(pipeline), graph_options), "template_graph.png"));
  return write(PoseCellScene(pipeline.slam().pose_cells(), {}), "pose_cells.png");
}

}  // namespace ratslam
