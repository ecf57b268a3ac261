// `ratslam simulate`: a simulated world written as a replay data set.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "apps/cli.h"
#include "apps/progress.h"
#include "common/file_util.h"
#include "render/renderer.h"
#include "sim/simulator.h"
#include "viewer/world_figure.h"

namespace ratslam::apps {

namespace fs = std::filesystem;

StatusOr<sim::World> LoadWorld(const std::string& name_or_path) {
  std::error_code ec;
  if (fs::exists(name_or_path, ec)) return sim::LoadWorldFile(name_or_path);
  return sim::BuiltInWorld(name_or_path);
}

Status SimulateWorld(const sim::World& world, uint64_t seed, const std::string& out, bool quiet,
                     dataset::Dataset* dataset) {
  const auto started = std::chrono::steady_clock::now();
  auto renderer = render::CreateOsMesaViewRenderer();
  if (!renderer.ok()) return renderer.status();
  sim::SimulationReport report;
  ProgressPrinter progress(stderr, quiet);
  RATSLAM_RETURN_IF_ERROR(sim::Simulate(
      world, seed, renderer->get(), (fs::path(out) / "images").string(), dataset, &report,
      [&](double fraction) {
        ProgressUpdate u;
        u.phase = "simulate " + world.name;
        u.total = 1000;
        u.done = static_cast<uint64_t>(std::lround(std::clamp(fraction, 0.0, 1.0) * 1000));
        progress.Update(u);
      }));
  progress.Finish();
  RATSLAM_RETURN_IF_ERROR(dataset::WriteDataset(*dataset, out));
  RATSLAM_RETURN_IF_ERROR(
      WriteFileAtomically((fs::path(out) / "world.toml").string(),
                          "# The simulated world (ratslam simulate).\n" + sim::PrintWorld(world)));
  RATSLAM_RETURN_IF_ERROR(render::RenderToPng(viewer::WorldMapScene(world, *dataset),
                                              (fs::path(out) / "ground_truth.png").string()));
  nlohmann::ordered_json j;
  j["world"] = world.name;
  j["seed"] = seed;
  j["images"] = report.images;
  j["wifi_scans"] = report.scans;
  j["odometry_rows"] = report.odometry_rows;
  j["compass_rows"] = report.compass_rows;
  j["sessions"] = dataset->session_start_times_s.size();
  j["duration_s"] = report.duration_s;
  j["wall_seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return WriteFileAtomically((fs::path(out) / "simulation.json").string(), j.dump(2) + "\n");
}

int SimulateCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  uint64_t seed = 1;
  if (args->Has("--seed")) seed = static_cast<uint64_t>(args->Whole("--seed"));
  auto world = LoadWorld(args->values.at("--world"));
  if (!world.ok()) {
    std::cerr << MessagePrefix() << world.status().message() << "\n";
    return kExitError;
  }
  dataset::Dataset dataset;
  Status s = SimulateWorld(*world, seed, args->values.at("--out"), args->quiet, &dataset);
  if (!s.ok()) {
    std::cerr << MessagePrefix() << s.message() << "\n";
    return kExitError;
  }
  if (!args->quiet) {
    std::printf("simulated '%s' into %s: %zu images, %zu Wi-Fi scans, %.0f s\n",
                world->name.c_str(), args->Shown(args->values.at("--out")).c_str(),
                dataset.images.size(), dataset.wifi.size(),
                dataset.ground_truth.back().time_s - dataset.ground_truth.front().time_s);
  }
  return kExitOk;
}

}  // namespace ratslam::apps
