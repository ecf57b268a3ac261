#include "phone/particle_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>

#include "common/circular.h"

namespace ratslam::phone {

std::string ToString(ScanLikelihood likelihood) {
  return likelihood == ScanLikelihood::kSum ? "sum" : "product";
}

StatusOr<ScanLikelihood> ScanLikelihoodFromString(const std::string& name) {
  if (name == "sum") return ScanLikelihood::kSum;
  if (name == "product") return ScanLikelihood::kProduct;
  return Status::Error("unknown scan likelihood '" + name + "' (sum, product)");
}

bool ParticleFilterOptions::IsValid(std::string* error) const {
  return schema::CheckFields(*this, error);
}

std::vector<size_t> SystematicResample(const std::vector<double>& weights, size_t count, double u) {
  double total = 0.0;
  for (double w : weights) total += std::max(w, 0.0);
  std::vector<size_t> out;
  if (!(total > 0.0) || count == 0) return out;
  out.reserve(count);
  const double step = total / static_cast<double>(count);
  double target = u * step, cumulative = 0.0;
  size_t i = 0;
  for (size_t k = 0; k < count; ++k) {
    while (i + 1 < weights.size() && cumulative + std::max(weights[i], 0.0) <= target) {
      cumulative += std::max(weights[i], 0.0);
      ++i;
    }
    out.push_back(i);
    target += step;
  }
  return out;
}

std::vector<std::pair<Point2, double>> WeightedKMeans(const std::vector<Point2>& points,
                                                      const std::vector<double>& weights, int k,
                                                      Random* random) {
  std::vector<std::pair<Point2, double>> out;
  if (points.empty() || k <= 0 || weights.size() != points.size()) return out;
  auto d2 = [](const Point2& a, const Point2& b) {
    return (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y);
  };
  // k-means++: the first centre by weight, each next with probability ~ weight * distance^2.
  std::vector<Point2> centres;
  std::vector<double> nearest(points.size(), std::numeric_limits<double>::infinity());
  auto pick = [&](const std::vector<double>& mass) -> std::optional<size_t> {
    double total = 0.0;
    for (double m : mass) total += m;
    if (!(total > 0.0)) return std::nullopt;
    double r = random->Uniform() * total;
    for (size_t i = 0; i < mass.size(); ++i) {
      r -= mass[i];
      if (r < 0.0) return i;
    }
    return mass.size() - 1;
  };
  std::optional<size_t> first = pick(weights);
  if (!first) return out;
  centres.push_back(points[*first]);
  while (static_cast<int>(centres.size()) < k) {
    std::vector<double> mass(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      nearest[i] = std::min(nearest[i], d2(points[i], centres.back()));
      mass[i] = weights[i] * nearest[i];
    }
    std::optional<size_t> next = pick(mass);
    if (!next) break;  // every point sits on a centre
    centres.push_back(points[*next]);
  }
  std::vector<size_t> label(points.size(), 0);
  std::vector<double> mass(centres.size());
  for (int round = 0; round < 50; ++round) {
    bool moved = round == 0;
    for (size_t i = 0; i < points.size(); ++i) {
      size_t best = 0;
      for (size_t c = 1; c < centres.size(); ++c) {
        if (d2(points[i], centres[c]) < d2(points[i], centres[best])) best = c;
      }
      moved |= best != label[i];
      label[i] = best;
    }
    if (!moved) break;
    std::vector<Point2> sum(centres.size());
    std::fill(mass.begin(), mass.end(), 0.0);
    for (size_t i = 0; i < points.size(); ++i) {
      sum[label[i]].x += weights[i] * points[i].x;
      sum[label[i]].y += weights[i] * points[i].y;
      mass[label[i]] += weights[i];
    }
    for (size_t c = 0; c < centres.size(); ++c) {
      if (mass[c] > 0) centres[c] = {sum[c].x / mass[c], sum[c].y / mass[c]};
    }
  }
  std::fill(mass.begin(), mass.end(), 0.0);
  double total = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    mass[label[i]] += weights[i];
    total += weights[i];
  }
  for (size_t c = 0; c < centres.size(); ++c) {
    if (mass[c] > 0) out.push_back({centres[c], total > 0 ? mass[c] / total : 0.0});
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  return out;
}

namespace {
const ParticleFilterOptions& Validated(const ParticleFilterOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("ParticleFilterOptions: " + error);
  return options;
}
}  // namespace

namespace {
constexpr double kWallCellM = 2.0;
int WallCell(double v) {
  return static_cast<int>(std::floor(std::clamp(v, -1e8, 1e8) / kWallCellM));
}
double Cross(const Point2& o, const Point2& a, const Point2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}
bool OnSegment(const Point2& p, const Point2& q, const Point2& r) {  // q on p-r, collinear
  return std::min(p.x, r.x) <= q.x && q.x <= std::max(p.x, r.x) && std::min(p.y, r.y) <= q.y &&
         q.y <= std::max(p.y, r.y);
}
int Sign(double v) { return (v > 0) - (v < 0); }

// (AP index, RSSI) readings as a Fingerprint.
sensors::Fingerprint ToFingerprint(const std::vector<std::pair<int64_t, double>>& readings) {
  std::vector<std::pair<uint32_t, double>> by_id;
  by_id.reserve(readings.size());
  for (const auto& [ap, rssi] : readings) by_id.emplace_back(static_cast<uint32_t>(ap), rssi);
  return sensors::FingerprintOf(std::move(by_id));
}
}  // namespace

ParticleFilter::ParticleFilter(const WifiGpMap& map, const ParticleFilterOptions& options)
    : map_(map),
      options_(Validated(options)),
      random_(options.seed),
      floors_(map.floors()),
      offset_(options.rssi_offset_min_common_aps, options.rssi_offset_min_estimates) {
  for (uint32_t k = 0; k < map_.walls().size(); ++k) {
    const WallSegment& w = map_.walls()[k];
    const int x0 = WallCell(std::min(w.a.x, w.b.x)), x1 = WallCell(std::max(w.a.x, w.b.x));
    const int y0 = WallCell(std::min(w.a.y, w.b.y)), y1 = WallCell(std::max(w.a.y, w.b.y));
    if (static_cast<int64_t>(x1 - x0 + 1) * (y1 - y0 + 1) > 4096) {
      long_walls_.push_back(k);  // tested for every move rather than bucketed
      continue;
    }
    for (int x = x0; x <= x1; ++x) {
      for (int y = y0; y <= y1; ++y) wall_cells_[{w.floor, x, y}].push_back(k);
    }
  }
  for (const WifiMapSample& sample : map_.training_samples()) {
    std::vector<std::pair<int64_t, double>> f;
    for (const auto& [bssid, rssi] : sample.readings) {
      const int64_t ap = map_.Find(bssid);
      if (ap >= 0) f.emplace_back(ap, rssi);
    }
    std::sort(f.begin(), f.end());
    fingerprints_.push_back(std::move(f));
  }
  if (options_.online_rssi_offset) {
    offset_.OnSessionStart(0.0, 0);  // the map's scans: the reference units
    for (const auto& f : fingerprints_) {
      offset_references_.push_back(ToFingerprint(f));
      offset_.AddTemplate();
    }
    offset_.OnSessionStart(1.0, static_cast<uint32_t>(offset_references_.size()));  // the phone
  }
}

void ParticleFilter::Reseed(const std::vector<std::pair<int64_t, double>>& known) {
  const double fraction = reseeded_ ? options_.reseed_fraction : options_.first_reseed_fraction;
  reseeded_ = true;
  const size_t count = static_cast<size_t>(fraction * static_cast<double>(particles_.size()));
  if (count == 0 || fingerprints_.empty()) return;
  std::vector<std::pair<int64_t, double>> query = known;
  std::sort(query.begin(), query.end());
  // Squared Euclidean RSSI distance over the union of APs, -100 dBm where one side lacks it.
  constexpr double kAbsent = -100.0;
  std::vector<std::pair<double, size_t>> distance;
  distance.reserve(fingerprints_.size());
  for (size_t s = 0; s < fingerprints_.size(); ++s) {
    const auto& f = fingerprints_[s];
    double d2 = 0.0;
    size_t i = 0, j = 0;
    while (i < query.size() || j < f.size()) {
      double a = kAbsent, b = kAbsent;
      if (j == f.size() || (i < query.size() && query[i].first < f[j].first)) {
        a = query[i++].second;
      } else if (i == query.size() || f[j].first < query[i].first) {
        b = f[j++].second;
      } else {
        a = query[i++].second;
        b = f[j++].second;
      }
      d2 += (a - b) * (a - b);
    }
    distance.emplace_back(d2, s);
  }
  const size_t k = std::min(distance.size(), static_cast<size_t>(options_.reseed_neighbours));
  std::partial_sort(distance.begin(), distance.begin() + static_cast<std::ptrdiff_t>(k),
                    distance.end());
  // The lightest particles (ties by index) make way.
  std::vector<size_t> order(particles_.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(count), order.end(),
                    [&](size_t a, size_t b) {
                      return particles_[a].weight < particles_[b].weight ||
                             (particles_[a].weight == particles_[b].weight && a < b);
                    });
  const double mean_weight = 1.0 / static_cast<double>(particles_.size());
  for (size_t n = 0; n < count; ++n) {
    const WifiMapSample& near = map_.training_samples()[distance[n % k].second];
    Particle& p = particles_[order[n]];
    p.floor = near.floor;
    p.x_m = near.position.x + random_.Gaussian(0.0, options_.reseed_spread_m);
    p.y_m = near.position.y + random_.Gaussian(0.0, options_.reseed_spread_m);
    p.heading_offset_rad = have_compass_ ? random_.Gaussian(0.0, options_.compass_offset_sigma_rad)
                                         : random_.Uniform(-std::numbers::pi, std::numbers::pi);
    p.weight = mean_weight;
  }
  Normalise();
}

Status ParticleFilter::Initialise(bool have_compass) {
  have_compass_ = have_compass;
  reseeded_ = false;
  std::vector<std::pair<int, Point2>> cells;
  for (int floor : map_.floors()) {
    for (const Point2& c : map_.KnownCells(floor)) cells.emplace_back(floor, c);
  }
  if (cells.empty()) return Status::Error("the Wi-Fi map stores no cell to locate a phone in");
  const double half = 0.5 * map_.options().cell_size_m;
  particles_.assign(static_cast<size_t>(options_.particles), Particle());
  for (Particle& p : particles_) {
    const auto& [floor, c] =
        cells[std::min(cells.size() - 1,
                       static_cast<size_t>(random_.Uniform() * static_cast<double>(cells.size())))];
    p.floor = floor;
    p.x_m = c.x + random_.Uniform(-half, half);
    p.y_m = c.y + random_.Uniform(-half, half);
    p.heading_offset_rad = have_compass ? random_.Gaussian(0.0, options_.compass_offset_sigma_rad)
                                        : random_.Uniform(-std::numbers::pi, std::numbers::pi);
    p.weight = 1.0 / static_cast<double>(particles_.size());
  }
  return Status::Ok();
}

bool SegmentsIntersect(const Point2& p1, const Point2& p2, const Point2& q1, const Point2& q2) {
  const int d1 = Sign(Cross(q1, q2, p1)), d2 = Sign(Cross(q1, q2, p2));
  const int d3 = Sign(Cross(p1, p2, q1)), d4 = Sign(Cross(p1, p2, q2));
  if (d1 * d2 < 0 && d3 * d4 < 0) return true;
  return (d1 == 0 && OnSegment(q1, p1, q2)) || (d2 == 0 && OnSegment(q1, p2, q2)) ||
         (d3 == 0 && OnSegment(p1, q1, p2)) || (d4 == 0 && OnSegment(p1, q2, p2));
}

bool ParticleFilter::CrossesWall(int floor, const Point2& a, const Point2& b) const {
  const int x0 = WallCell(std::min(a.x, b.x)), x1 = WallCell(std::max(a.x, b.x));
  const int y0 = WallCell(std::min(a.y, b.y)), y1 = WallCell(std::max(a.y, b.y));
  if (static_cast<int64_t>(x1 - x0 + 1) * (y1 - y0 + 1) > 64) {  // a long jump: test them all
    for (const WallSegment& w : map_.walls()) {
      if (w.floor == floor && SegmentsIntersect(a, b, w.a, w.b)) return true;
    }
    return false;
  }
  for (uint32_t k : long_walls_) {
    const WallSegment& w = map_.walls()[k];
    if (w.floor == floor && SegmentsIntersect(a, b, w.a, w.b)) return true;
  }
  for (int x = x0; x <= x1; ++x) {
    for (int y = y0; y <= y1; ++y) {
      const auto it = wall_cells_.find({floor, x, y});
      if (it == wall_cells_.end()) continue;
      for (uint32_t k : it->second) {
        const WallSegment& w = map_.walls()[k];
        if (SegmentsIntersect(a, b, w.a, w.b)) return true;
      }
    }
  }
  return false;
}

void ParticleFilter::ApplyWalls(const std::vector<Point2>& before) {
  bool any = false;
  for (size_t i = 0; i < particles_.size(); ++i) {
    Particle& p = particles_[i];
    if (CrossesWall(p.floor, before[i], {p.x_m, p.y_m})) {
      p.weight *= options_.wall_crossing_weight;
      ++wall_crossings_;
      any = true;
    }
  }
  if (any) Normalise();
}

std::vector<Point2> ParticleFilter::PositionsBeforeMove() const {
  std::vector<Point2> before;
  if (map_.walls().empty()) return before;  // nothing to cross
  before.reserve(particles_.size());
  for (const Particle& p : particles_) before.push_back({p.x_m, p.y_m});
  return before;
}

void ParticleFilter::Step(double forward_m, double heading_rad) {
  const std::vector<Point2> before = PositionsBeforeMove();
  for (Particle& p : particles_) {
    p.heading_offset_rad += random_.Gaussian(0.0, options_.heading_offset_walk_rad);
    const double heading =
        heading_rad + p.heading_offset_rad + random_.Gaussian(0.0, options_.heading_sigma_rad);
    const double length = forward_m * (1.0 + random_.Gaussian(0.0, options_.step_length_sigma));
    p.x_m += length * std::cos(heading);
    p.y_m += length * std::sin(heading);
  }
  if (!before.empty()) ApplyWalls(before);
}

void ParticleFilter::Diffuse(double dt_s) {
  const double sigma = options_.random_walk_m_per_s * std::sqrt(std::max(dt_s, 0.0));
  const std::vector<Point2> before = PositionsBeforeMove();
  for (Particle& p : particles_) {
    p.x_m += random_.Gaussian(0.0, sigma);
    p.y_m += random_.Gaussian(0.0, sigma);
  }
  if (!before.empty()) ApplyWalls(before);
}

double ParticleFilter::Likelihood(const Point2& p, int floor,
                                  const std::vector<std::pair<int64_t, double>>& known) const {
  const double noise2 = map_.options().noise_sigma_dbm * map_.options().noise_sigma_dbm;
  double sum = 0.0, log_product = 0.0;
  for (const auto& [ap, rssi] : known) {
    const WifiGpMap::Cell c = map_.Predict(static_cast<size_t>(ap), floor, p);
    const double variance = c.variance_dbm2 + noise2;
    const double z = rssi - c.mean_dbm;
    const double log_density =
        -0.5 * z * z / variance - 0.5 * std::log(2 * std::numbers::pi * variance);
    sum += std::exp(log_density);  // eq. 14 (a reading of an AP not heard is 0 and absent)
    log_product += log_density;
  }
  return options_.likelihood == ScanLikelihood::kSum ? sum : log_product;
}

size_t ParticleFilter::Update(const std::vector<std::pair<std::string, double>>& readings) {
  std::vector<std::pair<int64_t, double>> known;
  for (const auto& [bssid, rssi] : readings) {
    const int64_t ap = map_.Find(bssid);
    if (ap >= 0 && std::isfinite(rssi)) known.emplace_back(ap, rssi);
  }
  if (known.empty() || particles_.empty()) return known.size();
  if (options_.online_rssi_offset) {
    sensors::Fingerprint scan = ToFingerprint(known);
    offset_.Calibrate(offset_references_, &scan);
    const double offset = offset_.CurrentOffset();
    for (auto& reading : known) reading.second -= offset;
  }
  // Floor changes: before weighting, a particle moves to another floor the map knows (same x, y)
  // with probability floor_change_per_scan, so a phone that took the stairs is found again.
  if (options_.floor_change_per_scan > 0.0 && floors_.size() > 1) {
    for (Particle& p : particles_) {
      if (random_.Uniform() >= options_.floor_change_per_scan) continue;
      // The k-th of the floors other than the particle's, k uniform.
      size_t k = std::min(static_cast<size_t>(random_.Uniform() * (floors_.size() - 1)),
                          floors_.size() - 2);
      for (int f : floors_) {
        if (f == p.floor) continue;
        if (k-- == 0) {
          p.floor = f;
          break;
        }
      }
    }
  }
  Reseed(known);
  std::vector<double> value(particles_.size());
  double max_log = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < particles_.size(); ++i) {
    const Particle& p = particles_[i];
    value[i] = Likelihood({p.x_m, p.y_m}, p.floor, known);
    if (options_.likelihood == ScanLikelihood::kProduct) max_log = std::max(max_log, value[i]);
  }
  for (size_t i = 0; i < particles_.size(); ++i) {
    Particle& p = particles_[i];
    // The product in logs, shifted by its largest value so that exp stays in range.
    const double l =
        options_.likelihood == ScanLikelihood::kSum ? value[i] : std::exp(value[i] - max_log);
    p.weight *= l * (map_.Covers(p.floor, {p.x_m, p.y_m}) ? 1.0 : options_.off_map_weight);
  }
  Normalise();
  if (EffectiveSampleSize() < options_.resample_below * static_cast<double>(particles_.size())) {
    Resample();
  }
  return known.size();
}

void ParticleFilter::Normalise() {
  double total = 0.0;
  for (const Particle& p : particles_) total += p.weight;
  if (!(total > 0.0) || !std::isfinite(total)) {
    // Every particle explained the scan equally badly: start the weights over.
    for (Particle& p : particles_) p.weight = 1.0 / static_cast<double>(particles_.size());
    return;
  }
  for (Particle& p : particles_) p.weight /= total;
}

double ParticleFilter::EffectiveSampleSize() const {
  double sum2 = 0.0;
  for (const Particle& p : particles_) sum2 += p.weight * p.weight;
  return sum2 > 0.0 ? 1.0 / sum2 : 0.0;
}

void ParticleFilter::Resample() {
  std::vector<double> w(particles_.size());
  for (size_t i = 0; i < particles_.size(); ++i) w[i] = particles_[i].weight;
  const std::vector<size_t> pick = SystematicResample(w, particles_.size(), random_.Uniform());
  if (pick.empty()) return;
  std::vector<Particle> next;
  next.reserve(pick.size());
  for (size_t i : pick) {
    next.push_back(particles_[i]);
    next.back().weight = 1.0 / static_cast<double>(pick.size());
  }
  particles_ = std::move(next);
  ++resamplings_;
}

LocationEstimate ParticleFilter::Estimate() const {
  std::map<int, double> by_floor;
  for (const Particle& p : particles_) by_floor[p.floor] += p.weight;
  LocationEstimate e;
  double best = -1.0;
  for (const auto& [floor, w] : by_floor) {
    if (w > best) {
      best = w;
      e.floor = floor;
    }
  }
  double sx = 0, sy = 0, sw = 0;
  for (const Particle& p : particles_) {
    if (p.floor != e.floor) continue;
    sx += p.weight * p.x_m;
    sy += p.weight * p.y_m;
    sw += p.weight;
  }
  if (sw > 0) {
    e.x_m = sx / sw;
    e.y_m = sy / sw;
  }
  return e;
}

std::vector<std::pair<Point2, double>> ParticleFilter::Candidates() {
  const int floor = Estimate().floor;
  std::vector<Point2> points;
  std::vector<double> weights;
  for (const Particle& p : particles_) {
    if (p.floor != floor) continue;
    points.push_back({p.x_m, p.y_m});
    weights.push_back(p.weight);
  }
  return WeightedKMeans(points, weights, options_.candidates, &random_);
}

}  // namespace ratslam::phone
