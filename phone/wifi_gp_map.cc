#include "phone/wifi_gp_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "common/byte_buffer.h"
#include "common/checksum.h"
#include "common/text_file.h"

namespace ratslam::phone {
namespace {

constexpr char kMagic[] = "RSWIFIGP";
// 1: first; 2: adds the frame of maps made from a run (compass_to_map, truth_from_map), walls
// and the options fit_hyperparameters and fit_length_scale.
// The most grid cells a Wi-Fi map may store (by its bounding boxes): each is a GP prediction,
// about 1.5 us here (IPIN route 22, repetition 01, 40 APs: 4.2e6 cells at 0.05 m in 6.3 s; at
// 0.01 m, 1e8 cells ran for minutes), so 2^25 is under a minute of fitting and 256 MiB of grids.
// The default 1 m cell stores 1e4 there.
constexpr double kMaxWifiMapCells = double{1 << 25};

// Format 3 adds a CRC-32C trailer (common/checksum.h) to format 2.
constexpr uint32_t kVersion = 3;
constexpr uint32_t kFirstChecksummedVersion = 3;
constexpr int kTileCells = 8;  // cells per tile side: one local GP per tile

using Key = std::pair<int, int>;

// The cell holding `p`; a point beyond a billion cells (or not finite) lands in a cell no grid
// holds, as int cannot represent it.
Key CellOf(const Point2& p, double size) {
  const double x = std::floor(p.x / size), y = std::floor(p.y / size);
  if (!(std::abs(x) < 1e9 && std::abs(y) < 1e9)) {
    return {std::numeric_limits<int>::min(), std::numeric_limits<int>::min()};
  }
  return {static_cast<int>(x), static_cast<int>(y)};
}

struct Bin {
  double sum_x = 0, sum_y = 0;
  std::vector<size_t> samples;
};

struct TrainingSet {
  int floor = 0;
  std::vector<Key> heard_bins;  // sorted
  std::vector<Point2> points;   // bin centroids
  std::vector<double> values;   // mean RSSI per bin
  std::vector<double> counts;   // samples per bin
};

// Marginal-likelihood fit of sigma_f and sigma_p (and l when asked), shared by every AP: the
// summed log marginal likelihood of the largest training sets (at most kFitSets, each thinned to
// at most kFitPoints by a fixed stride), maximised by coordinate search over fixed grids of
// values from the given options, until a round changes nothing. Deterministic.
constexpr size_t kFitSets = 40;
constexpr size_t kFitPoints = 150;

StatusOr<WifiGpOptions> FitHyperparameters(const std::vector<std::vector<TrainingSet>>& sets,
                                           const WifiGpOptions& start, WifiGpFitReport* report) {
  std::vector<const TrainingSet*> chosen;
  for (const auto& per_ap : sets) {
    for (const TrainingSet& set : per_ap) {
      if (set.points.size() >= 5) chosen.push_back(&set);
    }
  }
  std::stable_sort(chosen.begin(), chosen.end(), [](const TrainingSet* a, const TrainingSet* b) {
    return a->points.size() > b->points.size();
  });
  if (chosen.size() > kFitSets) chosen.resize(kFitSets);
  if (chosen.empty()) {
    return Status::Error("Wi-Fi map: fit_hyperparameters needs an AP heard in at least 5 places");
  }
  struct Thinned {
    std::vector<Point2> points;
    std::vector<double> values, counts;
  };
  std::vector<Thinned> data;
  size_t total = 0;
  for (const TrainingSet* set : chosen) {
    Thinned t;
    const size_t stride = (set->points.size() + kFitPoints - 1) / kFitPoints;
    for (size_t i = 0; i < set->points.size(); i += stride) {
      t.points.push_back(set->points[i]);
      t.values.push_back(set->values[i]);
      t.counts.push_back(set->counts[i]);
    }
    total += t.points.size();
    data.push_back(std::move(t));
  }
  auto objective = [&](const WifiGpOptions& o) {
    double sum = 0.0;
    for (const Thinned& t : data) {
      std::vector<double> noise;
      for (double n : t.counts) noise.push_back(o.noise_sigma_dbm * o.noise_sigma_dbm / n);
      StatusOr<double> l = GaussianProcess2D::LogMarginalLikelihood(
          t.points, t.values, noise, o.unheard_rssi_dbm, o.signal_sigma_dbm * o.signal_sigma_dbm,
          o.length_scale_m);
      if (!l.ok()) return -std::numeric_limits<double>::infinity();
      sum += *l;
    }
    return sum;
  };
  static const std::vector<double> kSignal = {2, 3, 4, 5, 6, 8, 10, 12, 15, 20, 25, 30};
  static const std::vector<double> kNoise = {1, 1.5, 2, 3, 4, 5, 6, 8, 10, 12};
  static const std::vector<double> kLength = {0.5, 0.75, 1, 1.5, 2, 3, 4, 6, 8, 12};
  WifiGpOptions best = start;
  double best_value = objective(best);
  report->log_likelihood_before = best_value;
  for (int round = 0; round < 6; ++round) {
    bool changed = false;
    auto search = [&](double WifiGpOptions::*field, const std::vector<double>& grid) {
      for (double v : grid) {
        WifiGpOptions trial = best;
        trial.*field = v;
        const double value = objective(trial);
        if (value > best_value) {
          best_value = value;
          best = trial;
          changed = true;
        }
      }
    };
    search(&WifiGpOptions::signal_sigma_dbm, kSignal);
    search(&WifiGpOptions::noise_sigma_dbm, kNoise);
    if (start.fit_length_scale) search(&WifiGpOptions::length_scale_m, kLength);
    if (!changed) break;
  }
  report->log_likelihood_after = best_value;
  report->sets = data.size();
  report->points = total;
  return best;
}

// Training sets per AP and floor: heard bins, and bins within unheard_reach_m of one (an AP not
// heard counts as unheard_rssi_dbm), as bin centroid, mean RSSI and sample count. `heard_by[ap]`
// maps each sample that heard the AP to its RSSI.
std::vector<std::vector<TrainingSet>> TrainingSetsOf(
    const std::vector<WifiMapSample>& samples,
    const std::vector<std::map<size_t, double>>& heard_by, const WifiGpOptions& options) {
  // Samples binned per floor.
  std::map<int, std::map<Key, Bin>> bins;
  for (size_t i = 0; i < samples.size(); ++i) {
    Bin& b = bins[samples[i].floor][CellOf(samples[i].position, options.bin_size_m)];
    b.sum_x += samples[i].position.x;
    b.sum_y += samples[i].position.y;
    b.samples.push_back(i);
  }
  std::vector<std::vector<TrainingSet>> sets(heard_by.size());
  for (size_t ap = 0; ap < heard_by.size(); ++ap) {
    std::map<int, std::vector<Key>> heard_bins;  // per floor
    for (const auto& [i, rssi] : heard_by[ap]) {
      heard_bins[samples[i].floor].push_back(CellOf(samples[i].position, options.bin_size_m));
    }
    for (auto& [floor, keys] : heard_bins) {
      std::sort(keys.begin(), keys.end());
      keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
      const std::set<Key> heard(keys.begin(), keys.end());
      const int span = static_cast<int>(std::ceil(options.unheard_reach_m / options.bin_size_m));
      TrainingSet set;
      set.floor = floor;
      set.heard_bins = keys;
      for (const auto& [key, bin] : bins[floor]) {
        bool near = heard.count(key) > 0;
        for (int dx = -span; !near && dx <= span; ++dx) {
          for (int dy = -span; !near && dy <= span; ++dy) {
            near = heard.count({key.first + dx, key.second + dy}) > 0 &&
                   std::hypot(dx, dy) * options.bin_size_m <= options.unheard_reach_m;
          }
        }
        if (!near) continue;
        double sum = 0.0;
        for (size_t i : bin.samples) {
          auto it = heard_by[ap].find(i);
          sum += it == heard_by[ap].end() ? options.unheard_rssi_dbm : it->second;
        }
        const double n = static_cast<double>(bin.samples.size());
        set.points.push_back({bin.sum_x / n, bin.sum_y / n});
        set.values.push_back(sum / n);
        set.counts.push_back(n);
      }
      sets[ap].push_back(std::move(set));
    }
  }
  return sets;
}

// Grid cells the maps of `sets` would need at most, from each grid's bounding box (heard bins
// plus the margin): checked before any is built (a cell of 1 cm once started and ran the machine
// out of memory).
double GridCellsNeeded(const std::vector<std::vector<TrainingSet>>& sets,
                       const WifiGpOptions& options) {
  const double cell = options.cell_size_m;
  double total_cells = 0.0;
  for (size_t ap = 0; ap < sets.size(); ++ap) {
    for (const TrainingSet& set : sets[ap]) {
      int min_x = std::numeric_limits<int>::max(), min_y = min_x;
      int max_x = std::numeric_limits<int>::min(), max_y = max_x;
      for (const Key& k : set.heard_bins) {
        min_x = std::min(min_x, k.first);
        min_y = std::min(min_y, k.second);
        max_x = std::max(max_x, k.first);
        max_y = std::max(max_y, k.second);
      }
      if (set.heard_bins.empty()) continue;
      const double width_m = (max_x - min_x + 1) * options.bin_size_m + 2 * options.grid_margin_m;
      const double height_m = (max_y - min_y + 1) * options.bin_size_m + 2 * options.grid_margin_m;
      total_cells += std::ceil(width_m / cell + 1) * std::ceil(height_m / cell + 1);
    }
  }
  return total_cells;
}

// One AP's map on one floor: the cells within grid_margin_m of a heard bin, each predicted by a
// local GP fitted per tile to the training points within reach of the tile. `fitted` holds the
// GP's hyperparameters (fitted or as configured), `options` the grid's layout.
StatusOr<WifiGpMap::Grid> PredictGrid(const TrainingSet& set, const WifiGpOptions& fitted,
                                      const WifiGpOptions& options, const std::string& bssid) {
  const WifiGpOptions& o = fitted;
  const double noise2 = o.noise_sigma_dbm * o.noise_sigma_dbm;
  const double signal2 = o.signal_sigma_dbm * o.signal_sigma_dbm;
  const double reach = 4.0 * o.length_scale_m;  // kernel below e^-8 beyond
  const double cell = options.cell_size_m;
  const int floor = set.floor;
  const std::vector<Key>& keys = set.heard_bins;
  const std::vector<Point2>& points = set.points;
  const std::vector<double>& values = set.values;
  std::vector<double> noise;
  for (double n : set.counts) noise.push_back(noise2 / n);
  // Cells to store: within grid_margin_m of a heard bin's centre.
  std::set<Key> cells;
  const int margin = static_cast<int>(std::ceil(options.grid_margin_m / cell)) + 1;
  for (const Key& k : keys) {
    const Point2 c{(k.first + 0.5) * options.bin_size_m, (k.second + 0.5) * options.bin_size_m};
    const Key center = CellOf(c, cell);
    for (int dx = -margin; dx <= margin; ++dx) {
      for (int dy = -margin; dy <= margin; ++dy) {
        const Point2 q{(center.first + dx + 0.5) * cell, (center.second + dy + 0.5) * cell};
        if (std::hypot(q.x - c.x, q.y - c.y) <= options.grid_margin_m) {
          cells.insert({center.first + dx, center.second + dy});
        }
      }
    }
  }
  WifiGpMap::Grid grid;
  grid.floor = floor;
  int max_x = std::numeric_limits<int>::min(), max_y = max_x;
  grid.min_x = grid.min_y = std::numeric_limits<int>::max();
  for (const Key& k : cells) {
    grid.min_x = std::min(grid.min_x, k.first);
    grid.min_y = std::min(grid.min_y, k.second);
    max_x = std::max(max_x, k.first);
    max_y = std::max(max_y, k.second);
  }
  grid.width = max_x - grid.min_x + 1;
  grid.height = max_y - grid.min_y + 1;
  const size_t size = static_cast<size_t>(grid.width) * grid.height;
  grid.mean_dbm.assign(size, std::numeric_limits<float>::quiet_NaN());
  grid.variance_dbm2.assign(size, std::numeric_limits<float>::quiet_NaN());
  // One local GP per tile, from the training points within reach of the tile.
  std::map<Key, std::vector<Key>> tiles;
  for (const Key& k : cells) {
    tiles[{static_cast<int>(std::floor(static_cast<double>(k.first) / kTileCells)),
           static_cast<int>(std::floor(static_cast<double>(k.second) / kTileCells))}]
        .push_back(k);
  }
  for (const auto& [tile, tile_cells] : tiles) {
    const double x0 = tile.first * kTileCells * cell - reach,
                 x1 = (tile.first + 1) * kTileCells * cell + reach;
    const double y0 = tile.second * kTileCells * cell - reach,
                 y1 = (tile.second + 1) * kTileCells * cell + reach;
    std::vector<Point2> p;
    std::vector<double> v, n;
    for (size_t i = 0; i < points.size(); ++i) {
      if (points[i].x < x0 || points[i].x > x1 || points[i].y < y0 || points[i].y > y1) {
        continue;
      }
      p.push_back(points[i]);
      v.push_back(values[i]);
      n.push_back(noise[i]);
    }
    std::optional<GaussianProcess2D> gp;
    if (!p.empty()) {
      StatusOr<GaussianProcess2D> fit =
          GaussianProcess2D::Fit(p, v, n, o.unheard_rssi_dbm, signal2, o.length_scale_m);
      if (!fit.ok()) return fit.status().WithContext("Wi-Fi map: AP " + bssid);
      gp = std::move(fit.value());
    }
    for (const Key& k : tile_cells) {
      const Point2 q{(k.first + 0.5) * cell, (k.second + 0.5) * cell};
      double mean = options.unheard_rssi_dbm, variance = signal2;
      if (gp) {
        mean = gp->Mean(q);
        std::optional<double> here;
        if (options.signal_dependent_variance) {
          // Eq. 12 on eq. 1's scale, back in dBm^2 (an SQ unit is half a dB).
          here = SignalDependentVariance(2.0 * (mean + 100.0)) / 4.0;
        }
        variance = gp->Variance(q, here);
      }
      const size_t at =
          static_cast<size_t>(k.second - grid.min_y) * grid.width + (k.first - grid.min_x);
      grid.mean_dbm[at] = static_cast<float>(mean);
      grid.variance_dbm2[at] = static_cast<float>(variance);
    }
  }
  return grid;
}

}  // namespace

StatusOr<WifiGpMap> WifiGpMap::Build(const std::vector<WifiMapSample>& samples,
                                     const WifiGpOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) return Status::Error("Wi-Fi map options: " + error);
  if (samples.empty()) return Status::Error("Wi-Fi map: no scan with a position to learn from");
  WifiGpMap map;
  map.options_ = options;
  map.training_ = samples;
  // Per AP, the samples that heard it (the strongest reading of a BSSID heard twice).
  std::vector<std::map<size_t, double>> heard_by;
  for (size_t i = 0; i < samples.size(); ++i) {
    const WifiMapSample& s = samples[i];
    if (!std::isfinite(s.position.x) || !std::isfinite(s.position.y) ||
        std::abs(s.position.x) > 1e7 || std::abs(s.position.y) > 1e7) {
      return Status::Error("Wi-Fi map: sample " + std::to_string(i) + " has no finite position");
    }
    for (const auto& [bssid, rssi] : s.readings) {
      if (!std::isfinite(rssi)) {
        return Status::Error("Wi-Fi map: sample " + std::to_string(i) + " has a non-finite RSSI");
      }
      auto [it, added] = map.index_.emplace(bssid, map.bssids_.size());
      if (added) {
        map.bssids_.push_back(bssid);
        heard_by.emplace_back();
      }
      auto [at, first] = heard_by[it->second].emplace(i, rssi);
      if (!first) at->second = std::max(at->second, rssi);
    }
  }
  const std::vector<std::vector<TrainingSet>> sets = TrainingSetsOf(samples, heard_by, options);
  if (options.fit_hyperparameters) {
    WifiGpFitReport report;
    StatusOr<WifiGpOptions> fitted = FitHyperparameters(sets, options, &report);
    if (!fitted.ok()) return fitted.status();
    map.options_ = *fitted;
    map.fit_ = report;
  }
  const double cell = options.cell_size_m;
  const double total_cells = GridCellsNeeded(sets, options);
  if (total_cells > kMaxWifiMapCells) {
    char text[320];
    std::snprintf(text, sizeof text,
                  "Wi-Fi map: [wifi_map] cell_size_m = %g m would need up to %.2g grid cells for "
                  "%zu access points (%.1f GiB, each a prediction to compute; at most %.2g): use "
                  "a larger cell_size_m or a smaller grid_margin_m",
                  cell, total_cells, map.bssids_.size(), total_cells * 8 / (1 << 30),
                  kMaxWifiMapCells);
    return Status::Error(text);
  }
  map.grids_.resize(map.bssids_.size());
  for (size_t ap = 0; ap < map.bssids_.size(); ++ap) {
    for (const TrainingSet& set : sets[ap]) {
      StatusOr<Grid> grid = PredictGrid(set, map.options_, options, map.bssids_[ap]);
      if (!grid.ok()) return grid.status();
      map.grids_[ap].push_back(std::move(grid.value()));
    }
  }
  map.IndexCoverage();
  return map;
}

void WifiGpMap::IndexCoverage() {
  coverage_.clear();
  for (const auto& per_ap : grids_) {
    for (const Grid& g : per_ap) {
      std::set<Key>& c = coverage_[g.floor];
      for (int y = 0; y < g.height; ++y) {
        for (int x = 0; x < g.width; ++x) {
          if (!std::isnan(g.mean_dbm[static_cast<size_t>(y) * g.width + x])) {
            c.insert({g.min_x + x, g.min_y + y});
          }
        }
      }
    }
  }
}

WifiGpMap::Cell WifiGpMap::Predict(size_t ap, int floor, const Point2& p, bool* stored) const {
  const Key k = CellOf(p, options_.cell_size_m);
  if (stored) *stored = false;
  if (ap < grids_.size()) {
    for (const Grid& g : grids_[ap]) {
      if (g.floor != floor) continue;
      const int64_t x = int64_t{k.first} - g.min_x, y = int64_t{k.second} - g.min_y;
      if (x < 0 || y < 0 || x >= g.width || y >= g.height) break;
      const size_t at = static_cast<size_t>(y) * g.width + x;
      if (std::isnan(g.mean_dbm[at])) break;
      if (stored) *stored = true;
      return {g.mean_dbm[at], g.variance_dbm2[at]};
    }
  }
  return {static_cast<float>(options_.unheard_rssi_dbm),
          static_cast<float>(options_.signal_sigma_dbm * options_.signal_sigma_dbm)};
}

int64_t WifiGpMap::Find(const std::string& bssid) const {
  auto it = index_.find(bssid);
  return it == index_.end() ? -1 : static_cast<int64_t>(it->second);
}

std::vector<int> WifiGpMap::floors() const {
  std::vector<int> out;
  for (const auto& [floor, cells] : coverage_) {
    if (!cells.empty()) out.push_back(floor);
  }
  return out;
}

std::vector<Point2> WifiGpMap::KnownCells(int floor) const {
  std::vector<Point2> out;
  auto it = coverage_.find(floor);
  if (it == coverage_.end()) return out;
  for (const Key& k : it->second) {
    out.push_back(
        {(k.first + 0.5) * options_.cell_size_m, (k.second + 0.5) * options_.cell_size_m});
  }
  return out;
}

bool WifiGpMap::Covers(int floor, const Point2& p) const {
  auto it = coverage_.find(floor);
  return it != coverage_.end() && it->second.count(CellOf(p, options_.cell_size_m)) > 0;
}

size_t WifiGpMap::stored_cells() const {
  size_t n = 0;
  for (const auto& per_ap : grids_) {
    for (const Grid& g : per_ap) {
      n += static_cast<size_t>(std::count_if(g.mean_dbm.begin(), g.mean_dbm.end(),
                                             [](float v) { return !std::isnan(v); }));
    }
  }
  return n;
}

std::string WifiGpMap::Encode() const {
  ByteWriter w;
  w.String(kMagic);
  w.Pod(kVersion);
  WifiGpOptions o = options_;
  o.VisitFields([&](const char*, auto& field, const char*, const auto&) {
    using T = std::decay_t<decltype(field)>;
    if constexpr (std::is_same_v<T, bool>) {
      w.Bool(field);
    } else {
      w.Pod(field);
    }
  });
  w.Bool(reference_.has_value());
  w.Pod(reference_ ? reference_->first : 0.0);
  w.Pod(reference_ ? reference_->second : 0.0);
  w.Pod(compass_to_map_rad_);
  w.Bool(truth_from_map_.has_value());
  const RigidAlignment2D a = truth_from_map_.value_or(RigidAlignment2D{});
  w.Pod(a.rotation_rad);
  w.Pod(a.translation_x_m);
  w.Pod(a.translation_y_m);
  w.Pod(a.rmse_m);
  w.Count(walls_.size());
  for (const WallSegment& wall : walls_) {
    w.Pod<int32_t>(wall.floor);
    w.Pod(wall.a.x);
    w.Pod(wall.a.y);
    w.Pod(wall.b.x);
    w.Pod(wall.b.y);
  }
  w.Count(bssids_.size());
  for (size_t ap = 0; ap < bssids_.size(); ++ap) {
    w.String(bssids_[ap]);
    w.Count(grids_[ap].size());
    for (const Grid& g : grids_[ap]) {
      w.Pod(g.floor);
      w.Pod(g.min_x);
      w.Pod(g.min_y);
      w.Pod(g.width);
      w.Pod(g.height);
      w.PodVector(g.mean_dbm);
      w.PodVector(g.variance_dbm2);
    }
  }
  // The training samples, readings by AP index.
  w.Count(training_.size());
  for (const WifiMapSample& s : training_) {
    w.Pod(s.position.x);
    w.Pod(s.position.y);
    w.Pod<int32_t>(s.floor);
    w.Count(s.readings.size());
    for (const auto& [bssid, rssi] : s.readings) {
      w.Pod<uint32_t>(static_cast<uint32_t>(index_.at(bssid)));
      w.Pod(rssi);
    }
  }
  AppendChecksum(&w.bytes());
  return std::move(w.bytes());
}

// Reads a Wi-Fi map file's parts in their order (header, options, frame and walls, grids,
// samples), checking every count and value; each error names the file.
class WifiGpMap::Decoder {
 public:
  Decoder(std::string_view file, const std::string& name) : r_(file, name), name_(name) {}

  StatusOr<WifiGpMap> Run() {
    RATSLAM_RETURN_IF_ERROR(Header());
    RATSLAM_RETURN_IF_ERROR(Options());
    RATSLAM_RETURN_IF_ERROR(Frame());
    RATSLAM_RETURN_IF_ERROR(Grids());
    RATSLAM_RETURN_IF_ERROR(Samples());
    if (!r_.AtEnd()) return Fail("trailing bytes");
    map_.IndexCoverage();
    return std::move(map_);
  }

 private:
  // The reader's own error (it names the byte) before `what`.
  Status Fail(const std::string& what) const {
    return Status::Error(name_ + ": " + (r_.error().empty() ? what : r_.error()));
  }

  Status Header() {
    std::string magic;
    if (!r_.String(&magic) || magic != kMagic) return Fail("not a Wi-Fi map file");
    if (!r_.Pod(&version_)) return Fail("truncated");
    if (version_ < 1 || version_ > kVersion) {
      return Fail("Wi-Fi map format " + std::to_string(version_) + " (this program reads 1 to " +
                  std::to_string(kVersion) + ")");
    }
    return Status::Ok();
  }

  Status Options() {
    bool ok = true;
    map_.options_.VisitFields([&](const char* name, auto& field, const char*, const auto&) {
      using T = std::decay_t<decltype(field)>;
      if (version_ == 1 &&
          (std::string(name) == "fit_hyperparameters" || std::string(name) == "fit_length_scale")) {
        return;  // added in format 2
      }
      if constexpr (std::is_same_v<T, bool>) {
        ok = ok && r_.Bool(&field);
      } else {
        ok = ok && r_.Pod(&field);
      }
    });
    std::string invalid;
    if (!ok) return Fail("truncated options");
    if (!map_.options_.IsValid(&invalid)) return Fail("options: " + invalid);
    return Status::Ok();
  }

  // The geographic reference, the map frame and walls (format 2 on), and the number of APs (read
  // before the reference is checked).
  Status Frame() {
    bool has_reference = false;
    double latitude = 0, longitude = 0;
    if (!r_.Bool(&has_reference) || !r_.Pod(&latitude) || !r_.Pod(&longitude)) {
      return Fail("truncated");
    }
    if (version_ >= 2) {
      RATSLAM_RETURN_IF_ERROR(Alignment());
      RATSLAM_RETURN_IF_ERROR(Walls());
    }
    if (!r_.Count(16, &aps_)) return Fail("truncated");
    if (has_reference) {
      if (!(std::abs(latitude) <= 90) || !(std::abs(longitude) <= 180)) {
        return Fail("geographic reference out of range");
      }
      map_.reference_ = std::make_pair(latitude, longitude);
    }
    return Status::Ok();
  }

  Status Alignment() {
    bool has_alignment = false;
    RigidAlignment2D a;
    if (!(r_.Pod(&map_.compass_to_map_rad_) && r_.Bool(&has_alignment) && r_.Pod(&a.rotation_rad) &&
          r_.Pod(&a.translation_x_m) && r_.Pod(&a.translation_y_m) && r_.Pod(&a.rmse_m))) {
      return Fail("truncated frame");
    }
    if (!(std::abs(map_.compass_to_map_rad_) <= 7.0) || !(std::abs(a.rotation_rad) <= 7.0) ||
        !(std::abs(a.translation_x_m) <= 1e7) || !(std::abs(a.translation_y_m) <= 1e7) ||
        !(a.rmse_m >= 0 && a.rmse_m <= 1e7)) {
      return Fail("map frame out of range");
    }
    if (has_alignment) map_.truth_from_map_ = a;
    return Status::Ok();
  }

  Status Walls() {
    size_t walls = 0;
    if (!r_.Count(36, &walls)) return Fail("truncated walls");
    map_.walls_.resize(walls);
    for (WallSegment& wall : map_.walls_) {
      int32_t floor = 0;
      if (!(r_.Pod(&floor) && r_.Pod(&wall.a.x) && r_.Pod(&wall.a.y) && r_.Pod(&wall.b.x) &&
            r_.Pod(&wall.b.y))) {
        return Fail("truncated walls");
      }
      wall.floor = floor;
      for (double v : {wall.a.x, wall.a.y, wall.b.x, wall.b.y}) {
        if (!(std::abs(v) <= 1e7)) return Fail("a wall's end is not finite or out of range");
      }
    }
    return Status::Ok();
  }

  // Per AP: its BSSID (once in the file) and its grids, one per floor.
  Status Grids() {
    map_.grids_.resize(aps_);
    for (size_t ap = 0; ap < aps_; ++ap) {
      std::string bssid;
      size_t grids = 0;
      if (!r_.String(&bssid) || !r_.Count(36, &grids)) return Fail("truncated");
      if (!map_.index_.emplace(bssid, map_.bssids_.size()).second) {
        return Fail("BSSID " + bssid + " appears twice");
      }
      map_.bssids_.push_back(bssid);
      for (size_t k = 0; k < grids; ++k) {
        StatusOr<Grid> g = OneGrid(bssid);
        if (!g.ok()) return g.status();
        map_.grids_[ap].push_back(std::move(*g));
      }
    }
    return Status::Ok();
  }

  StatusOr<Grid> OneGrid(const std::string& bssid) {
    Grid g;
    if (!(r_.Pod(&g.floor) && r_.Pod(&g.min_x) && r_.Pod(&g.min_y) && r_.Pod(&g.width) &&
          r_.Pod(&g.height) && r_.PodVector(&g.mean_dbm) && r_.PodVector(&g.variance_dbm2))) {
      return Fail("truncated grid");
    }
    const int64_t cells = static_cast<int64_t>(g.width) * g.height;
    if (g.width <= 0 || g.height <= 0 || std::abs(int64_t{g.min_x}) > 1e8 ||
        std::abs(int64_t{g.min_y}) > 1e8 || cells != static_cast<int64_t>(g.mean_dbm.size()) ||
        g.mean_dbm.size() != g.variance_dbm2.size()) {
      return Fail("grid of AP " + bssid + " has a size that does not fit its cells");
    }
    for (size_t c = 0; c < g.mean_dbm.size(); ++c) {
      const float m = g.mean_dbm[c], v = g.variance_dbm2[c];
      if (std::isnan(m) != std::isnan(v) ||
          (!std::isnan(m) && (!std::isfinite(m) || !std::isfinite(v) || v < 0))) {
        return Fail("grid of AP " + bssid + " has an invalid cell");
      }
    }
    return g;
  }

  // The training samples: positions and readings by AP number.
  Status Samples() {
    size_t samples = 0;
    if (!r_.Count(24, &samples)) return Fail("truncated samples");
    map_.training_.resize(samples);
    for (WifiMapSample& s : map_.training_) {
      int32_t floor = 0;
      size_t readings = 0;
      if (!(r_.Pod(&s.position.x) && r_.Pod(&s.position.y) && r_.Pod(&floor) &&
            r_.Count(12, &readings))) {
        return Fail("truncated sample");
      }
      if (!std::isfinite(s.position.x) || !std::isfinite(s.position.y) ||
          std::abs(s.position.x) > 1e7 || std::abs(s.position.y) > 1e7) {
        return Fail("a sample's position is not finite");
      }
      s.floor = floor;
      for (size_t k = 0; k < readings; ++k) {
        uint32_t ap = 0;
        double rssi = 0;
        if (!(r_.Pod(&ap) && r_.Pod(&rssi))) return Fail("truncated sample");
        if (ap >= map_.bssids_.size() || !std::isfinite(rssi) || std::abs(rssi) > 1000) {
          return Fail("a sample's reading refers to no AP or is out of range");
        }
        s.readings.emplace_back(map_.bssids_[ap], rssi);
      }
    }
    return Status::Ok();
  }

  ByteReader r_;
  const std::string& name_;
  uint32_t version_ = 0;
  size_t aps_ = 0;
  WifiGpMap map_;
};

StatusOr<WifiGpMap> WifiGpMap::Decode(const std::string& bytes, const std::string& name) {
  std::string_view file(bytes);
  {  // Format 3 on ends in a checksum of everything before it.
    ByteReader header(file, name);
    std::string magic;
    uint32_t version = 0;
    if (header.String(&magic) && magic == kMagic && header.Pod(&version) &&
        version >= kFirstChecksummedVersion) {
      StatusOr<std::string_view> body = StripChecksum(file, name);
      if (!body.ok()) return body.status();
      file = *body;
    }
  }
  return Decoder(file, name).Run();
}

StatusOr<WifiGpMap> WifiGpMap::Load(const std::string& path) {
  StatusOr<std::string> bytes = ReadRegularFile(path, "Wi-Fi map", size_t{1} << 31);
  if (!bytes.ok()) return bytes.status();
  return Decode(*bytes, path);
}

}  // namespace ratslam::phone
