#include "sensors/barometer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/byte_buffer.h"

namespace ratslam::sensors {
namespace {
// R T / (g M) for dry air at 15 C: 287.05 J/(kg K) x 288.15 K / 9.80665 m/s^2 (metres).
constexpr double kScaleHeightM = 8434.5;
}  // namespace

bool BarometerOptions::IsValid(std::string* error) const {
  auto bad = [&](const char* what) {
    if (error) *error = what;
    return false;
  };
  if (!(smoothing_s > 0 && smoothing_s <= 60)) return bad("smoothing_s must be in (0, 60]");
  if (!(dwell_s > 0 && dwell_s <= 600)) return bad("dwell_s must be in (0, 600]");
  if (!(dwell_band_m > 0 && dwell_band_m <= 10)) return bad("dwell_band_m must be in (0, 10]");
  if (!(min_floor_change_m > dwell_band_m && min_floor_change_m <= 50)) {
    return bad("min_floor_change_m must be above dwell_band_m and at most 50");
  }
  if (!(storey_m >= min_floor_change_m && storey_m <= 50)) {
    return bad("storey_m must be at least min_floor_change_m and at most 50");
  }
  return true;
}

BarometricFloorTracker::BarometricFloorTracker(BarometerOptions options)
    : options_(options), storey_m_(options.storey_m) {
  options_.IsValid(&options_error_);
}

StatusOr<FloorEstimate> BarometricFloorTracker::Add(const PressureSample& sample) {
  if (!options_error_.empty()) return Status::Error("barometer: " + options_error_);
  if (!std::isfinite(sample.time_s) || sample.time_s < last_time_s_) {
    return Status::Error("barometer: time " + std::to_string(sample.time_s) +
                         " s goes backwards or is not finite");
  }
  if (!(sample.pressure_hpa >= 100 && sample.pressure_hpa <= 1100)) {
    return Status::Error("barometer: pressure " + std::to_string(sample.pressure_hpa) +
                         " hPa outside [100, 1100]");
  }
  last_time_s_ = sample.time_s;
  if (!has_reference_) {
    reference_hpa_ = sample.pressure_hpa;
    has_reference_ = true;
  }
  window_.push_back(sample);
  window_sum_ += sample.pressure_hpa - reference_hpa_;  // small numbers: no cancellation
  while (sample.time_s - window_.front().time_s > options_.smoothing_s) {
    window_sum_ -= window_.front().pressure_hpa - reference_hpa_;
    window_.pop_front();
  }
  const double smoothed = reference_hpa_ + window_sum_ / static_cast<double>(window_.size());
  const double height = -kScaleHeightM * std::log(smoothed / reference_hpa_);

  // Heights over at least the last dwell_s (the oldest may be just older).
  recent_.emplace_back(sample.time_s, height);
  while (recent_.size() > 1 && recent_[1].first <= sample.time_s - options_.dwell_s) {
    recent_.pop_front();
  }
  if (sample.time_s - recent_.front().first >= options_.dwell_s) {
    double low = std::numeric_limits<double>::infinity(), high = -low, sum = 0.0;
    for (const auto& [t, h] : recent_) {
      low = std::min(low, h);
      high = std::max(high, h);
      sum += h;
    }
    if (high - low <= options_.dwell_band_m) {
      const double level = sum / static_cast<double>(recent_.size());
      if (current_ < 0) {
        levels_.push_back({level, 0});
        current_ = 0;
      } else if (const double d = std::abs(level - levels_[current_].height_m);
                 d <= options_.dwell_band_m) {
        levels_[current_].height_m = level;  // still here: follow the weather
      } else if (d < options_.min_floor_change_m) {
        // A landing, a ramp or a slow drift out of the band: neither this floor nor another.
      } else {
        int nearest = -1;
        for (size_t k = 0; k < levels_.size(); ++k) {
          const double d = std::abs(level - levels_[k].height_m);
          if (d < options_.min_floor_change_m / 2 &&
              (nearest < 0 || d < std::abs(level - levels_[nearest].height_m))) {
            nearest = static_cast<int>(k);
          }
        }
        if (nearest >= 0) {
          current_ = nearest;
          levels_[current_].height_m = level;
        } else {
          levels_.push_back({level, 0});
          current_ = static_cast<int>(levels_.size()) - 1;
          Renumber();
        }
        ++floor_changes_;
      }
    }
  }
  // A known level is recognised without a dwell: the smoothed height within half the band of
  // it (the walker may walk straight on along a floor it has seen).
  if (current_ >= 0 && std::abs(height - levels_[current_].height_m) > options_.dwell_band_m) {
    for (size_t k = 0; k < levels_.size(); ++k) {
      if (static_cast<int>(k) != current_ &&
          std::abs(height - levels_[k].height_m) <= options_.dwell_band_m / 2) {
        current_ = static_cast<int>(k);
        ++floor_changes_;
        break;
      }
    }
  }
  FloorEstimate estimate;
  estimate.time_s = sample.time_s;
  estimate.height_m = height;
  estimate.floor = floor();
  estimate.in_transit =
      current_ >= 0 && std::abs(height - levels_[current_].height_m) > options_.dwell_band_m;
  estimate.level = current_;
  return estimate;
}

std::vector<int> BarometricFloorTracker::LevelFloors() const {
  std::vector<int> floors;
  floors.reserve(levels_.size());
  for (const Level& l : levels_) floors.push_back(l.floor);
  return floors;
}

void BarometricFloorTracker::Encode(ByteWriter* w) const {
  w->Count(window_.size());
  for (const PressureSample& s : window_) {
    w->Pod(s.time_s);
    w->Pod(s.pressure_hpa);
  }
  w->Pod(window_sum_);
  w->Pod(reference_hpa_);
  w->Bool(has_reference_);
  w->Count(recent_.size());
  for (const auto& [t, h] : recent_) {
    w->Pod(t);
    w->Pod(h);
  }
  w->Count(levels_.size());
  for (const Level& l : levels_) {
    w->Pod(l.height_m);
    w->Pod(static_cast<int32_t>(l.floor));
  }
  w->Pod(static_cast<int32_t>(current_));
  w->Pod(storey_m_);
  w->Pod(last_time_s_);
  w->Count(floor_changes_);
}

bool BarometricFloorTracker::Decode(ByteReader* r) {
  auto finite = [](double x) { return std::isfinite(x); };
  size_t n = 0;
  std::deque<PressureSample> window;
  if (!r->Count(16, &n)) return false;
  for (size_t i = 0; i < n; ++i) {
    PressureSample s;
    if (!(r->Pod(&s.time_s) && r->Pod(&s.pressure_hpa))) return false;
    if (!finite(s.time_s) || !(s.pressure_hpa >= 100 && s.pressure_hpa <= 1100)) {
      return r->Fail("barometer: a reading is not finite or out of range");
    }
    window.push_back(s);
  }
  double window_sum = 0.0, reference = 0.0, storey = 0.0, last_time = 0.0;
  bool has_reference = false;
  if (!(r->Pod(&window_sum) && r->Pod(&reference) && r->Bool(&has_reference))) return false;
  std::deque<std::pair<double, double>> recent;
  if (!r->Count(16, &n)) return false;
  for (size_t i = 0; i < n; ++i) {
    double t = 0.0, h = 0.0;
    if (!(r->Pod(&t) && r->Pod(&h))) return false;
    if (!finite(t) || !finite(h)) return r->Fail("barometer: a height is not finite");
    recent.emplace_back(t, h);
  }
  std::vector<Level> levels;
  if (!r->Count(12, &n)) return false;
  for (size_t i = 0; i < n; ++i) {
    double h = 0.0;
    int32_t floor = 0;
    if (!(r->Pod(&h) && r->Pod(&floor))) return false;
    if (!finite(h) || floor < -100000 || floor > 100000) {
      return r->Fail("barometer: a level's height or floor is out of range");
    }
    levels.push_back({h, floor});
  }
  int32_t current = 0;
  uint64_t changes = 0;
  if (!(r->Pod(&current) && r->Pod(&storey) && r->Pod(&last_time) && r->Pod(&changes))) {
    return false;
  }
  if (current < -1 || current >= static_cast<int64_t>(levels.size()) ||
      (current < 0) != levels.empty() || !finite(window_sum) || !(storey > 0 && storey <= 50) ||
      !(last_time == -1e300 || finite(last_time)) ||
      (has_reference && !(reference >= 100 && reference <= 1100)) ||
      (!has_reference && !window.empty())) {
    return r->Fail("barometer: state does not fit together");
  }
  window_ = std::move(window);
  window_sum_ = window_sum;
  reference_hpa_ = reference;
  has_reference_ = has_reference;
  recent_ = std::move(recent);
  levels_ = std::move(levels);
  current_ = current;
  storey_m_ = storey;
  last_time_s_ = last_time;
  floor_changes_ = static_cast<size_t>(changes);
  return true;
}

void BarometricFloorTracker::Renumber() {
  // The storey height: the smallest gap between two levels (all at least min_floor_change_m
  // apart when made). Floors count storeys from the first level.
  std::vector<double> heights;
  for (const Level& l : levels_) heights.push_back(l.height_m);
  std::sort(heights.begin(), heights.end());
  double smallest = std::numeric_limits<double>::infinity();
  for (size_t i = 1; i < heights.size(); ++i) {
    const double gap = heights[i] - heights[i - 1];
    if (gap >= options_.min_floor_change_m) smallest = std::min(smallest, gap);
  }
  if (std::isfinite(smallest)) storey_m_ = smallest;
  for (Level& l : levels_) {
    l.floor = static_cast<int>(std::lround((l.height_m - levels_[0].height_m) / storey_m_));
  }
}

StatusOr<std::vector<FloorEstimate>> EstimateFloors(const std::vector<PressureSample>& samples,
                                                    const BarometerOptions& options) {
  BarometricFloorTracker tracker(options);
  std::vector<FloorEstimate> out;
  out.reserve(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    StatusOr<FloorEstimate> e = tracker.Add(samples[i]);
    if (!e.ok()) return e.status().WithContext("reading " + std::to_string(i + 1));
    out.push_back(*e);
  }
  return out;
}

}  // namespace ratslam::sensors
