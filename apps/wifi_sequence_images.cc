#include "apps/wifi_sequence_images.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <vector>

#include "viewer/figures.h"

namespace ratslam::apps {

Status WriteWifiSequenceImages(render::SceneRenderer* renderer,
                               const fusion::ReplayPipeline& pipeline, const std::string& folder,
                               const std::vector<viewer::FigureFormat>& formats, double width_mm) {
  namespace fs = std::filesystem;
  const wifi_sequence::WifiSequenceLoopCloser& closer = pipeline.wifi_sequence();
  auto write = [&](const std::function<render::Scene(int)>& build, const char* name) -> Status {
    return viewer::WriteNaturalFigure(
               renderer, build, viewer::FigureTargets((fs::path(folder) / name).string(), &formats),
               width_mm)
        .WithContext(name);
  };
  // Fig. 9: every `stride`-th scan, so that long runs stay within 1000 x 1000 cells.
  const size_t n = closer.size();
  const size_t stride = std::max<size_t>(1, (n + 999) / 1000);
  const size_t cells = n == 0 ? 0 : (n - 1) / stride + 1;
  std::vector<float> matrix(cells * cells);
  std::vector<double> times(cells);
  for (size_t i = 0; i < cells; ++i) {
    times[i] = closer.pose(i * stride).time_s;
    for (size_t j = 0; j <= i; ++j) {
      const float s = static_cast<float>(closer.similarity().Similarity(i * stride, j * stride));
      matrix[i * cells + j] = matrix[j * cells + i] = s;
    }
  }
  viewer::SimilarityImageOptions options;
  options.title = "Wi-Fi similarity of scans (smoothed over travel, eqs. 1-4)";
  // Cosine similarities of signal strengths are mostly high: the colours span the lowest to 1.
  // Rounded down to a hundredth, so that the colour bar's label stays short.
  options.value_min =
      matrix.empty() ? 0.0
                     : std::floor(100.0 * *std::min_element(matrix.begin(), matrix.end())) / 100.0;
  const render::Rgba verified{220, 50, 32, 255}, rejected{235, 235, 235, 255};
  options.legend = {{verified, "verified correspondence"},
                    {{170, 170, 170, 255}, "DP pair not verified (light)"}};
  for (const wifi_sequence::SequenceLoop& loop : closer.loops()) {
    for (const wifi_sequence::SequenceCorrespondence& c : loop.correspondences) {
      const bool good = loop.accepted && c.inlier;
      options.marks.push_back({static_cast<int>(c.current_pose / stride),
                               static_cast<int>(c.past_pose / stride), good ? verified : rejected});
    }
  }
  // PNG: a 1000-pixel matrix; PDF and SVG: the matrix fills the page beside its colour bar.
  RATSLAM_RETURN_IF_ERROR(write(
      [&](int width_px) {
        viewer::SimilarityImageOptions o = options;
        if (width_px > 0) o.size_px = std::max(200, width_px - 190);
        if (width_px > 0 && width_px < 900) o.title = "Wi-Fi similarity of scans (eqs. 1-4)";
        return viewer::SimilarityMatrixScene(matrix, times, o);
      },
      "wifi_sequence_similarity.png"));

  // Fig. 10: the pairs on the final map.
  viewer::SequencePairsData pairs;
  for (size_t i = 0; i < n; ++i) {
    const Pose2 p = pipeline.MapPose(closer.pose(i));
    pairs.positions.push_back({p.x_m, p.y_m});
  }
  for (const wifi_sequence::SequenceLoop& loop : closer.loops()) {
    for (const wifi_sequence::SequenceCorrespondence& c : loop.correspondences) {
      pairs.pairs.push_back({c.current_pose, c.past_pose, loop.accepted && c.inlier});
    }
  }
  pairs.links_made = 0;
  for (const Link& l : pipeline.slam().experience_map().links())
    *pairs.links_made += l.wifi_sequence;
  return write(
      [&](int width_px) {
        return viewer::SequencePairsScene(pairs, "Wi-Fi sequence correspondences on the map",
                                          width_px);
      },
      "wifi_sequence_pairs.png");
}

}  // namespace ratslam::apps
