// The precomputed Wi-Fi maps of Kudo and Miura's section IV-A (fig. 15): per access point and
// floor, the GP's mean and variance on grid cells near where the AP was heard (see
// gaussian_process.h for the choices behind them). The GP is fitted per tile of cells from the
// training bins within reach (the kernel is negligible beyond a few length scales), so a map of
// thousands of poses and hundreds of APs builds in seconds and stores only cells near the APs.
#ifndef RATSLAM_PHONE_WIFI_GP_MAP_H_
#define RATSLAM_PHONE_WIFI_GP_MAP_H_

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "common/geometry.h"
#include "common/status.h"
#include "phone/gaussian_process.h"

namespace ratslam::phone {

// A training sample: a position on the map, its floor, and the scan heard there.
struct WifiMapSample {
  Point2 position;
  int floor = 0;
  std::vector<std::pair<std::string, double>> readings;  // BSSID, RSSI (dBm)
};

// A wall the map knows (simulated worlds): a segment on a floor that nobody walks through.
struct WallSegment {
  int floor = 0;
  Point2 a, b;
};

// What a marginal-likelihood fit of the hyper-parameters did (not stored in the file; the fitted
// values are, in the map's options).
struct WifiGpFitReport {
  double log_likelihood_before = 0.0;  // at the configured values
  double log_likelihood_after = 0.0;   // at the fitted ones
  size_t sets = 0;                     // AP-floor training sets used
  size_t points = 0;                   // training points in them
};

class WifiGpMap {
 public:
  struct Cell {
    float mean_dbm = 0.0f;
    float variance_dbm2 = 0.0f;  // the GP's (latent) variance; add the noise for a measurement
  };
  struct Grid {
    int32_t floor = 0;
    int32_t min_x = 0, min_y = 0, width = 0, height = 0;  // in cells
    std::vector<float> mean_dbm;                          // row-major; NaN: not stored
    std::vector<float> variance_dbm2;                     // row-major
  };

  // Fits every AP heard in `samples` on every floor it was heard on. Fails on invalid options, no
  // sample, or a non-finite position or reading.
  static StatusOr<WifiGpMap> Build(const std::vector<WifiMapSample>& samples,
                                   const WifiGpOptions& options);

  // The prediction for AP `ap` (index into bssids()) at `p` on `floor`: the stored cell, or the
  // prior (unheard mean, sigma_f^2) where none is. `stored` says which.
  Cell Predict(size_t ap, int floor, const Point2& p, bool* stored = nullptr) const;
  // AP index of a BSSID, or -1.
  int64_t Find(const std::string& bssid) const;
  // The options the map was built with (fitted hyper-parameters included).
  const WifiGpOptions& options() const { return options_; }
  // Set when Build fitted the hyper-parameters.
  const std::optional<WifiGpFitReport>& fit_report() const { return fit_; }
  const std::vector<std::string>& bssids() const { return bssids_; }
  const std::vector<Grid>& grids(size_t ap) const { return grids_[ap]; }
  // Floors with a stored cell, ascending.
  std::vector<int> floors() const;
  // Centres of the cells any AP stores on `floor` (where a phone can be, as far as the map knows).
  std::vector<Point2> KnownCells(int floor) const;
  // Whether any AP stores the cell holding `p` on `floor`.
  bool Covers(int floor, const Point2& p) const;
  size_t stored_cells() const;
  size_t samples() const { return training_.size(); }
  // The samples the map was fitted on (for fingerprint baselines beside the filter).
  const std::vector<WifiMapSample>& training_samples() const { return training_; }
  // The geographic origin of the map's frame (latitude, longitude in degrees) when its data came
  // from geo-referenced logs: a phone log must be read in the same frame.
  const std::optional<std::pair<double, double>>& geo_reference_deg() const { return reference_; }
  void set_geo_reference_deg(std::optional<std::pair<double, double>> r) { reference_ = r; }
  // Maps made from a replay's run folder live in that run's experience-map frame:
  //  - compass_to_map_rad: add to a compass heading to get a heading in the map's frame (the
  //    run's map starts facing 0 whatever the compass said; 0 for maps from ground truth);
  //  - truth_from_map: the rigid transform from the map's frame onto the ground-truth frame of
  //    the run's data (the alignment its map ATE uses), when that data had ground truth, so a
  //    phone's estimate can be scored against the phone log's truth.
  double compass_to_map_rad() const { return compass_to_map_rad_; }
  void set_compass_to_map_rad(double r) { compass_to_map_rad_ = r; }
  const std::optional<RigidAlignment2D>& truth_from_map() const { return truth_from_map_; }
  void set_truth_from_map(std::optional<RigidAlignment2D> a) { truth_from_map_ = a; }
  // Walls, when the map's data came with them (a simulated world): the particle filter keeps
  // particles from walking through them.
  const std::vector<WallSegment>& walls() const { return walls_; }
  void set_walls(std::vector<WallSegment> walls) { walls_ = std::move(walls); }

  // Versioned binary file (magic, version, options, frame, walls, BSSIDs, grids, samples). Decode
  // checks every count and value and reads format 1 (no frame: compass_to_map 0, no truth
  // alignment, no walls); an error names the file.
  std::string Encode() const;
  static StatusOr<WifiGpMap> Decode(const std::string& bytes, const std::string& name);
  // Reads and decodes the file `path` (a regular file of at most 2 GiB).
  static StatusOr<WifiGpMap> Load(const std::string& path);

 private:
  class Decoder;  // reads a file's parts in order (wifi_gp_map.cc)
  void IndexCoverage();
  WifiGpOptions options_;
  std::vector<WifiMapSample> training_;
  std::optional<std::pair<double, double>> reference_;
  double compass_to_map_rad_ = 0.0;
  std::optional<RigidAlignment2D> truth_from_map_;
  std::vector<WallSegment> walls_;
  std::optional<WifiGpFitReport> fit_;
  std::vector<std::string> bssids_;
  std::map<std::string, size_t> index_;
  std::vector<std::vector<Grid>> grids_;  // per AP, per floor it was heard on
  // Per floor, the union of the stored cells, for Covers and KnownCells.
  std::map<int, std::set<std::pair<int, int>>> coverage_;
};

}  // namespace ratslam::phone

#endif  // RATSLAM_PHONE_WIFI_GP_MAP_H_
