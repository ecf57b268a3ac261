// Floors from a phone's barometer, without a map and without a storey height per building.
//
// Air pressure falls by about 0.12 hPa per metre near the ground; a phone's barometer resolves a
// few centimetres after smoothing, but the weather moves the absolute pressure by a few hPa a
// day (tens of metres). So only changes count: the height relative to the first reading, by the
// hypsometric relation h = -(R T / g M) ln(p / p0) with an 8,434 m scale height (15 C; the
// temperature's share of error is a few per cent of a height change).
//
// A floor is a level the walker dwells on: the smoothed height staying within `dwell_band_m`
// for `dwell_s`. A dwell at least `min_floor_change_m` away from the current level is a floor
// change: to a known level when it lies within half that distance of one (a revisit), else to a
// new level. A known level is also recognised without a dwell, as soon as the smoothed height
// comes within half the band of it (a walker who goes straight on along a floor seen before).
// Floors are numbered from the first level (0) by height difference over the storey height, which
// is the smallest gap between two levels seen so far (so a building's own storey height is learnt
// from its first floor change), starting from `storey_m`. Half landings on stairs and a few
// seconds' pause are not floors: they are less than min_floor_change_m from a floor or shorter than
// dwell_s. A dwell within dwell_band_m of the current level re-measures its height, so slow weather
// drift is absorbed while the walker pauses now and then. Between dwells the walker is "in transit"
// when the height has left the current level's band: a caller that must not match across floors can
// treat those moments as unknown.
#ifndef RATSLAM_SENSORS_BAROMETER_H_
#define RATSLAM_SENSORS_BAROMETER_H_

#include <deque>
#include <string>
#include <vector>

#include "common/byte_buffer.h"
#include "common/schema.h"
#include "common/sensor_samples.h"
#include "common/status.h"

namespace ratslam::sensors {

struct BarometerOptions {
  double smoothing_s = 2.0;         // moving mean of pressure over this window
  double dwell_s = 8.0;             // a level: the smoothed height this long within the band
  double dwell_band_m = 0.8;        // spread of heights (max - min) a dwell may have
  double min_floor_change_m = 2.5;  // smaller level changes are landings, ramps or noise
  double storey_m = 4.0;            // storey height until two levels have been seen

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("smoothing_s", smoothing_s, "moving mean of the pressure over this window",
      schema::Unit("s").Above(0).AtMost(60));
    v("dwell_s", dwell_s, "a floor: the smoothed height stays this long within dwell_band_m",
      schema::Unit("s").Above(0).AtMost(600));
    v("dwell_band_m", dwell_band_m, "spread of heights (max - min) a dwell may have",
      schema::Unit("m").Above(0).AtMost(10));
    v("min_floor_change_m", min_floor_change_m,
      "smaller level changes are landings, ramps or noise (must exceed dwell_band_m)",
      schema::Unit("m").AtMost(50));
    v("storey_m", storey_m,
      "storey height until two floors have been seen (then their smallest gap; at least "
      "min_floor_change_m)",
      schema::Unit("m").AtMost(50));
  }
};

struct FloorEstimate {
  double time_s = 0.0;
  int floor = 0;            // relative to the first level (0); up is positive
  double height_m = 0.0;    // smoothed height relative to the first reading
  bool in_transit = false;  // the height has left the current level's band
  int level = -1;           // index of the current level (stable; -1 before the first dwell)
};

class BarometricFloorTracker {
 public:
  explicit BarometricFloorTracker(BarometerOptions options = {});

  // Adds a reading (times must not go backwards; pressure in hPa, 100 to 1,100) and returns the
  // estimate at its time.
  StatusOr<FloorEstimate> Add(const PressureSample& sample);

  int floor() const { return current_ < 0 ? 0 : levels_[current_].floor; }
  // Storey height in use (metres): storey_m until two levels have been seen.
  double storey_m() const { return storey_m_; }
  size_t levels() const { return levels_.size(); }
  size_t floor_changes() const { return floor_changes_; }
  // Floor of each level, by level index (levels keep their index; floors may be renumbered when
  // a smaller storey height is learnt).
  std::vector<int> LevelFloors() const;

  // The whole state, for saved maps and resumed runs; Decode checks what it reads (sizes,
  // finite numbers, indices) and fails with `reader`'s error.
  void Encode(ByteWriter* writer) const;
  bool Decode(ByteReader* reader);

 private:
  struct Level {
    double height_m;
    int floor;
  };
  void Renumber();

  BarometerOptions options_;
  std::string options_error_;          // empty when the options are valid (checked once)
  std::deque<PressureSample> window_;  // readings within smoothing_s
  double window_sum_ = 0.0;
  double reference_hpa_ = 0.0;  // first smoothed pressure
  bool has_reference_ = false;
  std::deque<std::pair<double, double>> recent_;  // (time, smoothed height) within dwell_s
  std::vector<Level> levels_;
  int current_ = -1;
  double storey_m_;
  double last_time_s_ = -1e300;
  size_t floor_changes_ = 0;
};

// Runs a tracker over a whole pressure series: one estimate per reading.
StatusOr<std::vector<FloorEstimate>> EstimateFloors(const std::vector<PressureSample>& samples,
                                                    const BarometerOptions& options = {});

}  // namespace ratslam::sensors

#endif  // RATSLAM_SENSORS_BAROMETER_H_
