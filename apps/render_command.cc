// `ratslam render ...`: images from a run folder, a saved map, or a data set.
#include <filesystem>
#include <iostream>
#include <sstream>

#include "apps/cli.h"
#include "common/file_util.h"
#include "dataset/dataset.h"
#include "dataset/dataset_loader.h"
#include "dataset/image_loader.h"
#include "io/config.h"
#include "io/map_file.h"
#include "io/run_reader.h"
#include "phone/wifi_gp_map.h"
#include "render/renderer.h"
#include "viewer/figure_output.h"
#include "viewer/figures.h"
#include "viewer/run_images.h"
#include "viewer/similarity.h"

namespace ratslam::apps {
namespace {

namespace fs = std::filesystem;

int Fail(const std::string& message) {
  std::cerr << MessagePrefix() << message << "\n";
  return kExitError;
}

// --size (checked by the parser), when given.
void TakeSize(const Arguments& args, int* width, int* height) {
  if (auto it = args.sizes.find("--size"); it != args.sizes.end()) {
    *width = it->second.width;
    *height = it->second.height;
  }
}

std::optional<std::vector<viewer::TimeSpan>> ParseSpans(const std::string& text) {
  std::vector<viewer::TimeSpan> spans;
  std::istringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const auto dash = item.find('-', 1);
    const auto colon = item.find(':');
    if (dash == std::string::npos) {
      std::cerr << MessagePrefix() << "--spans item '" << item << "' is not START-END[:label]\n";
      return std::nullopt;
    }
    auto start = ParseNumber("--spans", item.substr(0, dash));
    auto end = ParseNumber(
        "--spans",
        item.substr(dash + 1, colon == std::string::npos ? std::string::npos : colon - dash - 1));
    if (!start || !end) return std::nullopt;
    spans.push_back({*start, *end, colon == std::string::npos ? "" : item.substr(colon + 1)});
  }
  return spans;
}

// Writes the figure `build` makes to --out, in the formats --format names (else the one --out's
// extension names): PNG at width_px x height_px, PDF and SVG laid out for --width-mm.
// `default_width_mm`: the page width without --width-mm (two-panel figures need two columns).
Status Write(const Arguments& args, const std::string& out, const viewer::SceneBuilder& build,
             int width_px, int height_px, double default_width_mm = render::kOneColumnMm) {
  StatusOr<CommandFigure> figure = CommandFigureOf(args, out, default_width_mm);
  if (!figure.ok()) return figure.status();
  RATSLAM_RETURN_IF_ERROR(viewer::WriteFigure(figure->renderer.get(), build, width_px, height_px,
                                              figure->targets, figure->width_mm));
  for (const viewer::FigureTarget& t : figure->targets) {
    std::cerr << MessagePrefix() << "wrote " << t.path << "\n";
  }
  return Status::Ok();
}

}  // namespace

int RenderExperienceMapCommand(const Arguments& args) {
  const std::string run_folder = args.values.at("--run");
  StatusOr<io::RunFolder> run = io::ReadRunFolder(run_folder);
  if (!run.ok()) return Fail(run.status().message());
  viewer::ExperienceMapImageData data;
  data.experiences = run->experiences;
  data.links = run->links;
  data.current = run->current_experience;
  if (!data.current && !run->frames.empty() && run->frames.back().experience_id >= 0) {
    data.current = static_cast<uint32_t>(run->frames.back().experience_id);
  }
  // The run's own data sets (every session, phone logs too) read as the run read them, under its
  // own configuration, unless --data names others: the figure is the one replay --render drew.
  std::vector<std::string> inputs = run->inputs;
  if (auto it = args.all.find("--data"); it != args.all.end()) {
    inputs = it->second;
  } else if (inputs.empty() && !run->dataset_folder.empty()) {
    inputs = {run->dataset_folder};
  }
  viewer::ExperienceMapFigure figure;
  if (inputs.empty()) {
    figure.data = std::move(data);
    figure.floors.assign(figure.data.experiences.size(), 0);
  } else {
    fusion::PipelineOptions config;
    const fs::path config_path = fs::path(run_folder) / "config.toml";
    if (IsRegularFile(config_path)) {
      StatusOr<fusion::PipelineOptions> loaded = io::LoadConfigFile(config_path.string());
      if (!loaded.ok()) return Fail(loaded.status().message());
      config = *loaded;
    }
    dataset::PhoneLogOptions phone;
    phone.lenient = true;  // for ground truth to draw: a line the run skipped is skipped here
    phone.pdr = config.pdr;
    StatusOr<dataset::Dataset> dataset =
        dataset::LoadSessions(inputs, phone, 1.0, config.bag, config.video);
    if (!dataset.ok()) {
      return Fail(dataset.status().message() +
                  " (the data set the run read, for its ground truth; --data names another)");
    }
    // The ground truth the run reached: up to its trajectory's end, as replay --render drew it.
    double until_s = run->frames.empty() ? -1.0 : run->frames.back().time_s;
    StatusOr<std::vector<GroundTruthRow>> trajectory =
        io::ReadTumTrajectory((fs::path(run_folder) / "trajectory_tum.txt").string());
    if (trajectory.ok() && !trajectory->empty()) until_s = trajectory->back().time_s;
    figure = viewer::ExperienceMapFigureOf(std::move(data), *dataset, until_s);
  }
  viewer::ExperienceMapImageOptions& options = figure.options;
  TakeSize(args, &options.width_px, &options.height_px);
  if (auto it = args.values.find("--color"); it != args.values.end()) {
    if (it->second == "time") {
      options.coloring = viewer::MapColoring::kTime;
    } else if (it->second == "session") {
      options.coloring = viewer::MapColoring::kSession;
    } else {
      return Fail("--color must be time or session, not '" + it->second + "'");
    }
  }
  if (auto it = args.number_lists.find("--sessions"); it != args.number_lists.end()) {
    options.session_start_times_s = it->second;
    std::sort(options.session_start_times_s.begin(), options.session_start_times_s.end());
  } else if (options.coloring == viewer::MapColoring::kSession &&
             options.session_start_times_s.empty()) {
    options.session_start_times_s = {run->experiences.empty() ? 0.0 : run->experiences[0].time_s};
  }
  const std::string out = args.values.count("--out")
                              ? args.values.at("--out")
                              : (fs::path(run_folder) / "experience_map.png").string();
  Status status = Write(args, out,
                        viewer::Sized(options,
                                      [&](const viewer::ExperienceMapImageOptions& o) {
                                        return viewer::ExperienceMapFloorsScene(
                                            figure.data, figure.floors, figure.truth_floors, o);
                                      }),
                        options.width_px, options.height_px);
  return status.ok() ? kExitOk : Fail(status.message());
}

int RenderTemplateGraphCommand(const Arguments& args) {
  const std::string run_folder = args.values.at("--run");
  StatusOr<io::RunFolder> run = io::ReadRunFolder(run_folder);
  if (!run.ok()) return Fail(run.status().message());
  viewer::TemplateGraphImageOptions options;
  TakeSize(args, &options.width_px, &options.height_px);
  if (auto it = args.values.find("--spans"); it != args.values.end()) {
    auto spans = ParseSpans(it->second);
    if (!spans) return kExitUsage;
    options.shaded_spans = *spans;
  }
  std::vector<viewer::TemplateGraphPoint> points;
  for (const FrameRecord& f : run->frames) {
    points.push_back({f.time_s, f.template_id, f.experience_id, f.source});
  }
  const std::string out = args.values.count("--out")
                              ? args.values.at("--out")
                              : (fs::path(run_folder) / "template_graph.png").string();
  Status status = Write(args, out,
                        viewer::Sized(options,
                                      [&](const viewer::TemplateGraphImageOptions& o) {
                                        return viewer::TemplateGraphScene(points, o);
                                      }),
                        options.width_px, options.height_px);
  return status.ok() ? kExitOk : Fail(status.message());
}

int RenderPoseCellsCommand(const Arguments& args) {
  const std::string& map_path = args.values.at("--map");
  StatusOr<io::MapFile> map = io::LoadMapFile(map_path);
  if (!map.ok()) return Fail(map.status().message());
  // The map carries the configuration that made it (format 3 on); --config overrides it.
  std::optional<fusion::PipelineOptions> options;
  if (args.values.count("--config") || map->config.empty()) {
    if (!args.values.count("--config")) {
      return Fail(map_path + ": a map of format " + std::to_string(map->format_version) +
                  " holds no configuration: pass the --config it was made with");
    }
    options = LoadOptions(args);
    if (!options) return kExitError;
  } else {
    StatusOr<fusion::PipelineOptions> from_map =
        io::ParseMapConfig(map->config, map->format_version);
    if (!from_map.ok()) return Fail(map_path + ": " + from_map.status().message());
    options = *from_map;
  }
  PoseCellNetwork network(options->ratslam.pose_cells);
  Status restored = network.SetState(map->state.ratslam.pose_cells);
  if (!restored.ok()) {
    return Fail(args.values.at("--map") + ": " + restored.message() +
                " (pass the --config the map was made with)");
  }
  viewer::PoseCellImageOptions image_options;
  image_options.title = "pose-cell activity (" + map->dataset_name + ", summed over theta)";
  Status status = Write(args, args.values.at("--out"),
                        viewer::Sized(image_options,
                                      [&](const viewer::PoseCellImageOptions& o) {
                                        return viewer::PoseCellScene(network, o);
                                      }),
                        image_options.width_px, image_options.height_px);
  return status.ok() ? kExitOk : Fail(status.message());
}

int RenderSimilarityCommand(const Arguments& args) {
  auto options = LoadOptions(args);
  if (!options) return kExitError;
  const int frames = args.Has("--frames") ? static_cast<int>(args.Whole("--frames")) : 600;
  dataset::PhoneLogOptions phone;
  phone.pdr = options->pdr;
  StatusOr<dataset::Dataset> dataset =
      dataset::LoadSessions(args.all.at("--data"), phone, 1.0, options->bag, options->video);
  if (!dataset.ok()) return Fail(dataset.status().message());
  const std::string sensor = args.values.count("--sensor") ? args.values.at("--sensor") : "camera";
  viewer::SimilarityImageOptions image_options;
  StatusOr<viewer::SimilarityMatrix> m =
      Status::Error("--sensor must be camera or wifi, not '" + sensor + "'");
  if (sensor == "camera") {
    dataset::FileImageLoader images;
    m = viewer::CameraSimilarityMatrix(dataset.value(), &images, options->sensors.classic_camera,
                                       frames);
    image_options.title = "camera template similarity (" + dataset->name + ")";
  } else if (sensor == "wifi") {
    m = viewer::WifiSimilarityMatrix(dataset.value(), options->sensors.wifi, frames);
    image_options.title = "Wi-Fi similarity, eq. 6 (" + dataset->name + ")";
    image_options.value_label = "weight w";
  }
  if (!m.ok()) return Fail(m.status().message());
  // The matrix's side sets the figure's size; the margins around it are fixed.
  const render::Scene natural = viewer::SimilarityMatrixScene(m->values, m->times_s, image_options);
  const int margins = natural.width() - image_options.size_px;
  Status status = Write(
      args, args.values.at("--out"),
      [&](int w, int) {
        viewer::SimilarityImageOptions o = image_options;
        o.size_px = std::max(100, w - margins);
        return viewer::SimilarityMatrixScene(m->values, m->times_s, o);
      },
      natural.width(), natural.height());
  return status.ok() ? kExitOk : Fail(status.message());
}

// The GP mean and variance of one AP (Kudo and Miura, fig. 15), with the training scans.
int RenderWifiMapCommand(const Arguments& args) {
  const std::string path = args.values.at("--wifi-map");
  StatusOr<phone::WifiGpMap> map = phone::WifiGpMap::Load(path);
  if (!map.ok()) return Fail(map.status().message());
  if (map->bssids().empty()) return Fail(path + ": the map holds no access point");
  // The AP asked for, or the one with the most stored cells.
  size_t ap = 0;
  if (args.values.count("--ap")) {
    const int64_t found = map->Find(args.values.at("--ap"));
    if (found < 0) return Fail(path + ": no access point " + args.values.at("--ap"));
    ap = static_cast<size_t>(found);
  } else {
    size_t most = 0;
    for (size_t a = 0; a < map->bssids().size(); ++a) {
      size_t cells = 0;
      for (const auto& g : map->grids(a)) cells += g.mean_dbm.size();
      if (cells > most) most = cells, ap = a;
    }
  }
  const auto& grids = map->grids(ap);
  if (grids.empty()) return Fail(path + ": access point " + map->bssids()[ap] + " has no grid");
  int floor = grids.front().floor;
  if (args.Has("--floor")) floor = static_cast<int>(args.Whole("--floor"));
  const auto grid =
      std::find_if(grids.begin(), grids.end(),
                   [floor](const phone::WifiGpMap::Grid& g) { return g.floor == floor; });
  if (grid == grids.end()) {
    return Fail(path + ": access point " + map->bssids()[ap] + " was not heard on floor " +
                std::to_string(floor));
  }
  const double cell = map->options().cell_size_m;
  viewer::GridField mean{"mean RSSI (dBm), eq. 8", grid->width,        grid->height,  cell,
                         grid->min_x * cell,       grid->min_y * cell, grid->mean_dbm};
  viewer::GridField variance{
      "variance (dBm^2), eq. 10", grid->width,        grid->height,       cell,
      grid->min_x * cell,         grid->min_y * cell, grid->variance_dbm2};
  std::vector<Point2> points;
  for (const phone::WifiMapSample& s : map->training_samples()) {
    if (s.floor == floor) points.push_back(s.position);
  }
  const std::string title = "Wi-Fi map of " + map->bssids()[ap] + ", floor " +
                            std::to_string(floor) + " (dots: training scans)";
  const render::Scene natural = viewer::GridFieldsScene({mean, variance}, points, title);
  Status status = Write(
      args, args.values.at("--out"),
      [&](int w, int) {
        // Two panels of `panel` pixels plus fixed margins; the panel follows the width.
        const int panel = std::max(100, 700 - (natural.width() - w) / 2);
        return viewer::GridFieldsScene({mean, variance}, points, title, panel);
      },
      natural.width(), natural.height(), render::kTwoColumnMm);
  return status.ok() ? kExitOk : Fail(status.message());
}

}  // namespace ratslam::apps
