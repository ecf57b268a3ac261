#include "sim/propagation.h"

#include <algorithm>
#include <cmath>

namespace ratslam::sim {

double ChannelFrequencyMhz(int channel) {
  if (channel == 14) return 2484.0;
  return channel <= 14 ? 2407.0 + 5.0 * channel : 5000.0 + 5.0 * channel;
}

double FreeSpaceLossDb(double distance_m, double frequency_mhz) {
  return 20.0 * std::log10(distance_m) + 20.0 * std::log10(frequency_mhz) - 27.55;
}

namespace {

// Whether segments p1-p2 and q1-q2 cross (touching counts).
bool Crosses(Point2 p1, Point2 p2, Point2 q1, Point2 q2) {
  auto orient = [](Point2 a, Point2 b, Point2 c) {
    return (b.x_m - a.x_m) * (c.y_m - a.y_m) - (b.y_m - a.y_m) * (c.x_m - a.x_m);
  };
  const double d1 = orient(q1, q2, p1), d2 = orient(q1, q2, p2);
  const double d3 = orient(p1, p2, q1), d4 = orient(p1, p2, q2);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0));
}

uint64_t Mix(uint64_t a, uint64_t b) {
  uint64_t z = a ^ (b + 0x9E3779B97F4A7C15ULL + (a << 6) + (a >> 2));
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

}  // namespace

double WifiPropagation::WallLossDb(Point2 a, Point2 b, int floor) const {
  double loss = 0.0;
  for (const Wall& w : world_.walls) {
    if (w.floor == floor && Crosses(a, b, w.from, w.to)) loss += world_.materials_db.at(w.material);
  }
  return loss;
}

double WifiPropagation::MeanPowerDbm(size_t ap_index, Point2 at, int floor, int session) const {
  const AccessPoint& ap = world_.access_points[ap_index];
  const bool moved =
      std::count(ap.moved_in_sessions.begin(), ap.moved_in_sessions.end(), session) > 0;
  const Point2 from = moved ? ap.moved_to : ap.position;
  const WifiSettings& s = world_.wifi;
  const double d =
      std::max(std::hypot(at.x_m - from.x_m, at.y_m - from.y_m), s.reference_distance_m);
  const double f = ChannelFrequencyMhz(ap.channel);
  double loss = FreeSpaceLossDb(s.reference_distance_m, f) +
                10.0 * s.path_loss_exponent * std::log10(d / s.reference_distance_m);
  // Walls on the receiver's floor along the straight path; each floor in between costs more.
  loss += WallLossDb(from, at, floor);
  loss += std::abs(floor - ap.floor) * s.floor_attenuation_db;
  return ap.tx_power_dbm - loss;
}

double WifiPropagation::ShadowingDb(size_t ap, Point2 at, int floor) const {
  const double c = world_.wifi.shadowing_correlation_m;
  const double gx = at.x_m / c, gy = at.y_m / c;
  const double x0 = std::floor(gx), y0 = std::floor(gy);
  const double fx = gx - x0, fy = gy - y0;
  auto node = [&](double i, double j) {
    uint64_t key = Mix(seed_, ap);
    key = Mix(key, static_cast<uint64_t>(static_cast<int64_t>(i)));
    key = Mix(key, static_cast<uint64_t>(static_cast<int64_t>(j)));
    key = Mix(key, static_cast<uint64_t>(static_cast<int64_t>(floor)));
    Random r(key);
    return r.Gaussian();
  };
  const double v = node(x0, y0) * (1 - fx) * (1 - fy) + node(x0 + 1, y0) * fx * (1 - fy) +
                   node(x0, y0 + 1) * (1 - fx) * fy + node(x0 + 1, y0 + 1) * fx * fy;
  // Bilinear mixing shrinks the variance; rescale so that S has the configured sigma.
  const double w2 = ((1 - fx) * (1 - fx) + fx * fx) * ((1 - fy) * (1 - fy) + fy * fy);
  return world_.wifi.shadowing_sigma_db * v / std::sqrt(w2);
}

std::vector<WifiReading> WifiPropagation::Scan(Point2 at, int floor, int session,
                                               Random* random) const {
  std::vector<WifiReading> readings;
  const WifiSettings& s = world_.wifi;
  for (size_t i = 0; i < world_.access_points.size(); ++i) {
    const AccessPoint& ap = world_.access_points[i];
    // Draw the per-scan terms for every AP, so that one AP's state does not shift the others'.
    const double fading = random->Gaussian(0.0, s.fading_sigma_db);
    const bool missed = random->Uniform() < s.miss_probability;
    if (std::count(ap.off_in_sessions.begin(), ap.off_in_sessions.end(), session)) continue;
    const double rssi = MeanPowerDbm(i, at, floor, session) + ShadowingDb(i, at, floor) + fading;
    if (rssi < s.sensitivity_dbm || missed) continue;
    readings.push_back({ap.name, std::round(rssi)});  // phones report whole dBm
  }
  return readings;
}

}  // namespace ratslam::sim
