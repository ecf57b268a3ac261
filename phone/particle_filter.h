// Locating a phone in a Wi-Fi map with a particle filter (Kudo and Miura, section IV-B and IV-C;
// equation numbers are that paper's).
//
//  - Motion: each dead-reckoning step (forward distance, heading change) moves every particle
//    along its own heading, with step-length and heading noise; with no step source a random
//    walk. A particle's heading is the phone's (compass or integrated) plus a per-particle
//    offset, drawn at the start (small with a compass, uniform without) and walking slowly.
//  - Weight: eq. 13-14's sum over heard APs of a Gaussian density of the reading around the
//    map's mean (variance: the map's plus the measurement noise), or the documented alternative,
//    the product of those densities (the likelihood of independent readings, which the sum is
//    not). APs the map does not know are left out; a scan with none the map knows leaves the
//    weights as they are. A particle off the cells the map stores is down-weighted.
//  - Walls (when the map knows them, e.g. a simulated world's): a particle whose move crosses a
//    wall on its floor has its weight multiplied by wall_crossing_weight (0: it dies and the next
//    resampling replaces it; if every particle crossed, the weights start over). Walls are
//    bucketed in 2 m cells so a move tests only the walls near it.
//  - Resampling: systematic, when the effective sample size falls below a share of the count.
//  - Candidates: k-means (k-means++ seeding from the filter's seeded generator) over the
//    particles, the paper's twelve (section IV-C.2).
//  - Sensor resetting (Lenser and Veloso 2000): before a scan weighs the particles, the lightest
//    of them are redrawn around the reseed_neighbours training scans nearest to the scan in
//    signal space (Euclidean RSSI distance over the APs either heard, -100 dBm for an AP not
//    heard), on their floors, with the mean weight; the scan then weighs them like the rest.
//    How many: first_reseed_fraction at the first scan, reseed_fraction at every later one, so a
//    short walk in a large map, or a filter stuck in a wrong mode, is found again. (Augmented
//    MCL's adaptive share, 1 - fast/slow of two running averages of the scans' fit, was tried:
//    mean error over the twelve IPIN rows 2.49 m against 2.05 m for the fixed share.)
//  - Phones read the same place several dB apart (the map's phone and the located one). With
//    online_rssi_offset the located phone's offset to the map's training scans is estimated from
//    its own scans, with no position (sensors/rssi_offset.h: the training scan whose RSSI
//    differences to a scan spread least gives the median difference as one estimate; after
//    rssi_offset_min_estimates of them their median is removed from every later scan, before
//    sensor resetting and weighting).
// Floors: at each scan a particle moves to another floor the map knows (same x, y) with a small
// probability, so the filter follows a phone up the stairs without a stairs model; the scan's
// weight then decides.
#ifndef RATSLAM_PHONE_PARTICLE_FILTER_H_
#define RATSLAM_PHONE_PARTICLE_FILTER_H_

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "common/geometry.h"
#include "common/random.h"
#include "common/schema.h"
#include "common/status.h"
#include "phone/wifi_gp_map.h"
#include "sensors/rssi_offset.h"

namespace ratslam::phone {

// How a particle's weight follows from a scan.
//  - kSum: eq. 13, the sum of eq. 14's per-AP densities (the paper's).
//  - kProduct: their product (independent readings), computed in logs.
enum class ScanLikelihood { kSum, kProduct };
std::string ToString(ScanLikelihood likelihood);
StatusOr<ScanLikelihood> ScanLikelihoodFromString(const std::string& name);

struct ParticleFilterOptions {
  int particles = 2000;                   // particle count
  double step_length_sigma = 0.15;        // relative step-length noise per step
  double heading_sigma_rad = 0.05;        // heading noise per step
  double heading_offset_walk_rad = 0.01;  // per step: drift of a particle's heading offset
  double compass_offset_sigma_rad = 0.3;  // initial heading offset spread with a compass
  double random_walk_m_per_s = 0.8;       // no step source: position noise per second
  double off_map_weight = 0.01;           // weight factor of a particle off the stored cells
  double wall_crossing_weight = 0.0;      // weight factor of a particle that walks through a wall
  double floor_change_per_scan = 0.01;    // chance a particle tries another floor at a scan
  double reseed_fraction = 0.05;          // share of particles redrawn near fingerprint matches
  double first_reseed_fraction = 0.5;     // the same at the first scan the map knows
  int reseed_neighbours = 3;              // training scans nearest in signal space to draw around
  double reseed_spread_m = 1.5;           // spread of the redrawn particles around them
  double resample_below = 0.5;            // resample when ESS < this share of the count
  ScanLikelihood likelihood = ScanLikelihood::kSum;  // see ScanLikelihood
  int candidates = 12;                               // k of the k-means candidates (section IV-C.2)
  uint64_t seed = 1;                                 // the filter's random generator
  bool online_rssi_offset = false;                   // see the header comment
  int rssi_offset_min_common_aps = 5;  // APs a scan shares with a training scan for an estimate
  int rssi_offset_min_estimates = 10;  // estimates before the offset is removed

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("particles", particles, "particle count", schema::Unit("particles").Within(1, 10000000));
    v("step_length_sigma", step_length_sigma, "relative step-length noise per step",
      schema::Unit("").NonNegative());
    v("heading_sigma_rad", heading_sigma_rad, "heading noise per step",
      schema::Unit("rad").NonNegative());
    v("heading_offset_walk_rad", heading_offset_walk_rad,
      "per step: random walk of a particle's heading offset", schema::Unit("rad").NonNegative());
    v("compass_offset_sigma_rad", compass_offset_sigma_rad,
      "with a compass: spread of the initial heading offsets (uniform without one)",
      schema::Unit("rad").NonNegative());
    v("random_walk_m_per_s", random_walk_m_per_s,
      "without steps: position noise per second of a random walk",
      schema::Unit("m/s").NonNegative());
    v("off_map_weight", off_map_weight,
      "weight factor of a particle on a cell the map does not store",
      schema::Unit("").Within(0, 1));
    v("wall_crossing_weight", wall_crossing_weight,
      "weight factor of a particle whose move crosses a wall the map knows (0: it dies)",
      schema::Unit("").Within(0, 1));
    v("floor_change_per_scan", floor_change_per_scan,
      "chance that a particle moves to another floor the map knows (same x, y) at each scan",
      schema::Unit("").Within(0, 1));
    v("reseed_fraction", reseed_fraction,
      "share of the particles (the lightest) redrawn at each scan around the training scans "
      "nearest in signal space (sensor resetting; 0: off)",
      schema::Unit("").Within(0, 1));
    v("first_reseed_fraction", first_reseed_fraction,
      "reseed_fraction at the first scan with an AP the map knows (the initial spread over the "
      "whole map keeps the rest)",
      schema::Unit("").Within(0, 1));
    v("reseed_neighbours", reseed_neighbours,
      "how many nearest training scans the redrawn particles are spread around",
      schema::Unit("scans").Within(1, 1000));
    v("reseed_spread_m", reseed_spread_m, "standard deviation of a redrawn particle's position",
      schema::Unit("m").NonNegative());
    v("resample_below", resample_below,
      "systematic resampling when the effective sample size falls below this share",
      schema::Unit("").Within(0, 1));
    v("likelihood", likelihood,
      "sum (eq. 13, the paper's) or product (independent readings) of the per-AP densities",
      schema::Any());
    v("candidates", candidates, "k of the k-means candidate locations (the paper's 12)",
      schema::Unit("").AtLeast(1));
    v("seed", seed, "seed of the filter's random generator", schema::Any());
    v("online_rssi_offset", online_rssi_offset,
      "estimate the phone's RSSI offset to the map's training scans from its own scans and "
      "remove it (phones that read several dB apart)",
      schema::Any());
    v("rssi_offset_min_common_aps", rssi_offset_min_common_aps,
      "APs a scan must share with a training scan to estimate the offset",
      schema::Unit("APs").AtLeast(1));
    v("rssi_offset_min_estimates", rssi_offset_min_estimates,
      "offset estimates before their median is removed from the scans",
      schema::Unit("scans").AtLeast(1));
  }
};

struct Particle {
  double x_m = 0.0, y_m = 0.0;
  double heading_offset_rad = 0.0;
  int floor = 0;
  double weight = 0.0;
};

struct LocationEstimate {
  double x_m = 0.0, y_m = 0.0;
  int floor = 0;  // the floor holding most weight
};

class ParticleFilter {
 public:
  // `map` must outlive the filter; `options` must be valid (throws std::invalid_argument).
  ParticleFilter(const WifiGpMap& map, const ParticleFilterOptions& options);

  // Particles whose last move crossed a wall (since construction).
  uint64_t wall_crossings() const { return wall_crossings_; }

  // Spreads the particles uniformly over the cells the map stores (all floors), equal weights.
  // Fails when the map stores no cell.
  Status Initialise(bool have_compass);
  // One dead-reckoning step in the phone's frame, `heading_rad` the phone's heading after it.
  void Step(double forward_m, double heading_rad);
  // A random walk over `dt_s` seconds (no step source).
  void Diffuse(double dt_s);
  // Weights the particles by a scan (BSSID, RSSI); resamples when the ESS is low. Returns how
  // many readings the map knew (0: weights unchanged).
  size_t Update(const std::vector<std::pair<std::string, double>>& readings);

  LocationEstimate Estimate() const;
  // k-means centres of the particles on the estimate's floor (weighted), at most `candidates` of
  // them, heaviest first, with their weight shares.
  std::vector<std::pair<Point2, double>> Candidates();
  double EffectiveSampleSize() const;
  const std::vector<Particle>& particles() const { return particles_; }
  uint64_t resamplings() const { return resamplings_; }
  // online_rssi_offset: the offset removed from the scans now (0 until it is known; dBm, the
  // phone's reading minus the map's).
  double rssi_offset_db() const { return offset_.CurrentOffset(); }

  // The weight eq. 13-14 (or the product) gives one particle at `p` on `floor` (for tests).
  double Likelihood(const Point2& p, int floor,
                    const std::vector<std::pair<int64_t, double>>& known_readings) const;

 private:
  void Normalise();
  void Resample();
  // Whether the move from `a` to `b` on `floor` crosses a wall the map knows.
  bool CrossesWall(int floor, const Point2& a, const Point2& b) const;
  // The particles' positions before a move, when the map has walls to check it against (else
  // empty).
  std::vector<Point2> PositionsBeforeMove() const;
  // Penalises the particles whose move from `before` crossed a wall.
  void ApplyWalls(const std::vector<Point2>& before);
  // Sensor resetting (see the header comment) for a scan's known readings.
  void Reseed(const std::vector<std::pair<int64_t, double>>& known);

  const WifiGpMap& map_;
  ParticleFilterOptions options_;
  Random random_;
  std::vector<Particle> particles_;
  uint64_t resamplings_ = 0;
  uint64_t wall_crossings_ = 0;
  // Wall indices by (floor, cell x, cell y) of kWallCellM cells their bounding boxes touch.
  std::map<std::tuple<int, int, int>, std::vector<uint32_t>> wall_cells_;
  std::vector<uint32_t> long_walls_;  // walls too long to bucket
  std::vector<int> floors_;           // the map's floors
  bool have_compass_ = false;
  bool reseeded_ = false;  // whether a scan has reseeded since Initialise
  // The training scans as (AP index, RSSI) sorted by AP, for sensor resetting.
  std::vector<std::vector<std::pair<int64_t, double>>> fingerprints_;
  // online_rssi_offset: the estimator (the map is its first session, the phone its second) and
  // the training scans in its terms.
  sensors::RssiOffsetTracker offset_;
  std::vector<sensors::Fingerprint> offset_references_;
};

// Whether segments p1-p2 and q1-q2 intersect (touching counts).
bool SegmentsIntersect(const Point2& p1, const Point2& p2, const Point2& q1, const Point2& q2);

// Systematic resampling: `count` indices into `weights` (normalised or not), drawn with one
// uniform offset `u` in [0, 1): index i appears about count * w_i times, never off by more than
// one. Empty for no positive weight.
std::vector<size_t> SystematicResample(const std::vector<double>& weights, size_t count, double u);

// Weighted k-means (k-means++ seeding from `random`, then Lloyd iterations until no point moves
// or 50 rounds): at most k centres (fewer for fewer distinct points), each with its weight.
std::vector<std::pair<Point2, double>> WeightedKMeans(const std::vector<Point2>& points,
                                                      const std::vector<double>& weights, int k,
                                                      Random* random);

}  // namespace ratslam::phone

#endif  // RATSLAM_PHONE_PARTICLE_FILTER_H_
