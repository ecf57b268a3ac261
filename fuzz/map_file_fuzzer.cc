// Map files: decoding never crashes; a map that decodes and is accepted by a pipeline (classic
// camera, fused, FABMAP front end, descriptors, or Wi-Fi sequence loop closure alone) runs on for a
// few hundred events and summarises its outputs without touching an id that does not exist. The
// fuzzer found a dangling trajectory id (Summarise) in 19 executions before restores were
// validated.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include "fuzz/fuzz_support.h"
#include "io/map_file.h"
#include "io/run_outputs.h"

namespace ratslam::fuzz {
namespace {

// Two laps of a 16 m square: odometry 10 Hz, scans every 2 s from four APs, compass 2 Hz, a
// barometer at 10 Hz, one camera image a second whose content depends on the position (so templates
// re-match).
dataset::Dataset MakeDataset() {
  dataset::Dataset d;
  d.name = "fuzz-square";
  const double side = 16.0, lap = 4 * side;
  auto where = [&](double t, double* x, double* y, double* heading) {
    const double along = std::fmod(t, lap);
    const int leg = static_cast<int>(along / side);
    const double f = along - leg * side;
    const double c[4][2] = {{0, 0}, {side, 0}, {side, side}, {0, side}};
    const double h[4] = {0, std::numbers::pi / 2, std::numbers::pi, -std::numbers::pi / 2};
    *x = c[leg][0] + f * std::cos(h[leg]);
    *y = c[leg][1] + f * std::sin(h[leg]);
    *heading = h[leg];
  };
  for (int i = 0; i <= static_cast<int>(2 * lap * 10); ++i) {
    const double t = i / 10.0;
    const bool turn = i > 0 && std::fmod(t, side) < 1e-9;
    d.odometry.push_back({t, 1.0, turn ? std::numbers::pi / 2 * 10.0 : 0.0});
  }
  for (double t = 0.5; t < 2 * lap; t += 2.0) {
    double x, y, h;
    where(t, &x, &y, &h);
    WifiScan scan{t, {}};
    const double ap[4][2] = {{0, 0}, {side, 0}, {side, side}, {0, side}};
    for (int k = 0; k < 4; ++k) {
      scan.readings.push_back(
          {std::string(1, static_cast<char>('a' + k)) + "0:00",
           -40.0 - 20.0 * std::log10(1.0 + std::hypot(x - ap[k][0], y - ap[k][1]))});
    }
    d.wifi.push_back(scan);
  }
  for (double t = 0.25; t < 2 * lap; t += 0.5) {
    double x, y, h;
    where(t, &x, &y, &h);
    d.compass.push_back({t, h});
  }
  // The barometer: the second lap is a floor up (3.5 m climbed in 8 s at its start).
  for (double t = 0.05; t < 2 * lap; t += 0.1) {
    const double h = t < lap ? 0.0 : std::min(3.5, 3.5 * (t - lap) / 8.0);
    d.pressure.push_back({t, 1000.0 * std::exp(-h / 8434.5)});
  }
  for (int t = 0; t < 2 * lap; ++t) {
    d.images.push_back({t + 0.7, std::to_string(t % static_cast<int>(lap)) + ".png", t + 2});
  }
  d.session_start_times_s = {0.0, lap};  // the second lap is another session
  return d;
}

// Images made from their file name: the same place gives the same picture on every lap.
class GeneratedImages : public ImageLoader {
 public:
  StatusOr<GrayImage> Load(const std::string& path) override {
    const int place = std::atoi(path.substr(path.find_last_of('/') + 1).c_str());
    GrayImage image;
    image.width = 64;
    image.height = 32;
    image.pixels.resize(64 * 32);
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 64; ++x) {
        image.pixels[y * 64 + x] =
            static_cast<uint8_t>(128 + 100 * std::sin(0.3 * x * (1 + place % 7) + 0.2 * y + place));
      }
    }
    return image;
  }
};

struct Setup {
  dataset::Dataset dataset = MakeDataset();
  GeneratedImages images;
  std::vector<fusion::PipelineOptions> options;
  std::vector<fusion::FrontEndResources> resources;

  Setup() {
    fusion::PipelineOptions classic;
    classic.sensors.classic_camera.template_width_px = 32;
    classic.sensors.classic_camera.template_height_px = 8;
    fusion::PipelineOptions fused;
    fused.sensors.front_end.kind = fusion::FrontEndKind::kFused;
    fused.sensors.fused.use_camera = true;
    fused.sensors.fused.use_compass = true;
    fused.sensors.fused.recency_s = 20.0;
    fused.sensors.fused.online_rssi_offset = true;     // its estimates are part of the state
    fused.sensors.barometer.use_barometer = true;      // and so are its floors
    fused.sensors.fused.revisit_update_weight = 0.25;  // and the revisit counts
    fusion::PipelineOptions fabmap_wifi;
    fabmap_wifi.sensors.front_end.kind = fusion::FrontEndKind::kFabmap;
    fabmap_wifi.sensors.fabmap.localiser.localiser.mode = fabmap::FabmapMode::kWifi;
    fabmap_wifi.sensors.fabmap.localiser.virtual_wifi.use_exploration_scans = true;
    fabmap_wifi.sensors.barometer.use_barometer = true;
    fabmap_wifi.sensors.fabmap.front_end.online_rssi_offset = true;  // its estimates: state
    // Wi-Fi sequence loop closure alone (its poses, loops and links in the saved state).
    fusion::PipelineOptions sequence;
    sequence.sensors.front_end.kind = fusion::FrontEndKind::kNone;
    sequence.wifi_sequence.enabled = true;
    sequence.wifi_sequence.min_loop_travel_m = 20.0;
    // Descriptors of the place each image shows (8 dimensions), re-matching on the second lap.
    fusion::PipelineOptions descriptors;
    descriptors.sensors.front_end.kind = fusion::FrontEndKind::kDescriptors;
    descriptors.sensors.descriptors.min_similarity = 0.99;
    // FABMAP with earlier sessions apart, its threshold learnt from the loop closer's revisits
    // (scan records, queries and revisit scores in the state; the second lap is a session).
    fusion::PipelineOptions fabmap_learn = fabmap_wifi;
    fabmap_learn.sensors.barometer.use_barometer = false;
    fabmap_learn.sensors.fabmap.front_end.decide_by_log_odds = true;
    fabmap_learn.sensors.fabmap.front_end.earlier_sessions_apart = true;
    fabmap_learn.sensors.fabmap.front_end.earlier_session_log_odds = 50.0;
    fabmap_learn.sensors.fabmap.front_end.learn_earlier_session_log_odds = true;
    fabmap_learn.sensors.fabmap.front_end.learn_min_revisits = 2;
    fabmap_learn.wifi_sequence.enabled = true;
    fabmap_learn.wifi_sequence.min_loop_travel_m = 20.0;
    // The same threshold from a calibration pass (in the state: the value and its revisits).
    fusion::PipelineOptions fabmap_calibrated = fabmap_learn;
    fabmap_calibrated.sensors.fabmap.front_end.learn_earlier_session_log_odds = false;
    fabmap_calibrated.sensors.fabmap.front_end.calibrate_earlier_session_log_odds = true;
    options = {classic, fused, fabmap_wifi, sequence, descriptors, fabmap_learn, fabmap_calibrated};
    dataset::DescriptorMatrix places{dataset.images.size(), 8, {}};
    for (const ImageRow& image : dataset.images) {
      const int place = std::atoi(image.file.c_str());
      for (int k = 0; k < 8; ++k) places.values.push_back(std::cos(0.7 * place * (k + 1) + k));
    }
    for (const fusion::PipelineOptions& o : options) {
      fusion::FrontEndResources r;
      if (o.sensors.front_end.kind == fusion::FrontEndKind::kFabmap) {
        r.fabmap = fusion::PrepareFabmapResources(o.sensors, dataset, std::nullopt).value();
      } else if (o.sensors.front_end.kind == fusion::FrontEndKind::kDescriptors) {
        r.descriptors = fusion::DescriptorTable::Make(places, dataset, "places").value();
      }
      resources.push_back(r);
    }
  }
  std::unique_ptr<fusion::ReplayPipeline> Pipeline(size_t i) {
    return std::make_unique<fusion::ReplayPipeline>(options[i], dataset, &images, resources[i]);
  }
};

Setup& Shared() {
  static Setup setup;
  return setup;
}

}  // namespace

std::vector<std::string> FuzzSeeds() {
  std::vector<std::string> seeds;
  for (size_t i = 0; i < Shared().options.size(); ++i) {
    for (double until : {30.0, 100.0, 127.0}) {
      auto pipeline = Shared().Pipeline(i);
      fusion::ReplayControl control;
      control.until_time_s = until;
      if (fusion::CalibrationPassOptions(Shared().options[i]) &&
          !pipeline->Calibrate({-3.0, 12}).ok()) {
        InvariantFailed("the seed calibration failed");
      }
      if (!pipeline->Run(control).ok()) InvariantFailed("the seed replay failed");
      io::MapFile map;
      map.dataset_name = Shared().dataset.name;
      map.state = pipeline->Snapshot();
      seeds.push_back(io::EncodeMapFile(map));
    }
  }
  return seeds;
}

}  // namespace ratslam::fuzz

namespace {

int DecodeAndRun(const std::string& bytes) {
  using namespace ratslam;
  StatusOr<io::MapFile> map = io::DecodeMapFile(bytes, "fuzz.map");
  if (!map.ok()) return 0;
  fuzz::Setup& setup = fuzz::Shared();
  for (size_t i = 0; i < setup.options.size(); ++i) {
    auto pipeline = setup.Pipeline(i);
    if (!pipeline->Restore(map->state).ok()) continue;
    // A few hundred events on from where the map stopped, then everything the outputs read.
    const auto& events = pipeline->events();
    const uint64_t stop = std::min<uint64_t>(events.size(), map->state.next_event + 300);
    fusion::ReplayControl control;
    control.until_time_s = stop < events.size() ? events[stop].time_s : events.back().time_s;
    (void)pipeline->Run(control);
    const io::RunSummary summary = io::Summarise(*pipeline, setup.dataset, io::RunInfo{});
    if (summary.json.empty()) fuzz::InvariantFailed("empty summary");
  }
  return 0;
}

}  // namespace

// The input as it is (old formats have no checksum), and behind a matching checksum, so that
// mutations reach the decoder (a flipped byte under the checksum is refused: map_file_test).
extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return ratslam::fuzz::AsIsAndChecksummed(data, size, DecodeAndRun);
}
