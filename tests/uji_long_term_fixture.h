// A small synthetic library in the long-term UJI data set's layout (db/<month>/<set>{rss,crd,tms,
// ids}.csv; dataset/uji_long_term.h), for tests: two floors (3 and 5) of a 69 m corridor,
// 24 places per floor 3 m apart, three scans per place. Twelve access points (six per floor, on
// the corridor every 14 m) follow a log-distance model with 18 dB per storey between floors and
// +-3 dB of seeded noise; below -100 dBm they are not detected (100).
//
// Month 01 holds the training set trn01 at the places and a test set tst01 1.5 m along the
// corridor from them (the nearest map place is 1.5 m away); month 12 a test set tst01 at those
// test places, and by then the access points in columns 2 and 9 are gone and four new ones
// (columns 13 to 16, never heard in month 01) are on.
#ifndef RATSLAM_TESTS_UJI_LONG_TERM_FIXTURE_H_
#define RATSLAM_TESTS_UJI_LONG_TERM_FIXTURE_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace ratslam::fixture {

struct LongTermAp {
  double x_m;
  int floor;
  bool in_month_01, in_month_12;
};

inline const LongTermAp* LongTermAps(int* count) {
  static const LongTermAp aps[] = {
      {0, 3, true, true},   {14, 3, true, false}, {28, 3, true, true},  {42, 3, true, true},
      {56, 3, true, true},  {70, 3, true, true},  {0, 5, true, true},   {14, 5, true, true},
      {28, 5, true, false}, {42, 5, true, true},  {56, 5, true, true},  {70, 5, true, true},
      {7, 3, false, true},  {35, 3, false, true}, {21, 5, false, true}, {49, 5, false, true},
  };
  *count = static_cast<int>(std::size(aps));
  return aps;
}

inline constexpr int kLongTermPlacesPerFloor = 24;
inline constexpr double kLongTermSpacingM = 3.0;
inline constexpr int kLongTermScansPerPlace = 3;

// Writes db/<month>/<set>*.csv under `root`; `offset_m` moves every place along the corridor.
inline void WriteLongTermSet(const std::filesystem::path& root, const std::string& month,
                             const std::string& set, double offset_m, bool month_12,
                             double start_time_s, uint32_t seed) {
  namespace fs = std::filesystem;
  const fs::path dir = root / "db" / month;
  fs::create_directories(dir);
  std::ofstream rss(dir / (set + "rss.csv")), crd(dir / (set + "crd.csv")),
      tms(dir / (set + "tms.csv")), ids(dir / (set + "ids.csv"));
  std::mt19937 random(seed);
  int count = 0;
  const LongTermAp* aps = LongTermAps(&count);
  int row = 0;
  for (int floor : {3, 5}) {
    for (int p = 0; p < kLongTermPlacesPerFloor; ++p) {
      const double x = p * kLongTermSpacingM + offset_m;
      for (int k = 0; k < kLongTermScansPerPlace; ++k, ++row) {
        for (int a = 0; a < count; ++a) {
          const bool on = month_12 ? aps[a].in_month_12 : aps[a].in_month_01;
          const double d = std::max(1.0, std::hypot(x - aps[a].x_m, 3.0));
          const double noise = static_cast<double>(random() % 601) / 100.0 - 3.0;
          const double rssi =
              -35.0 - 25.0 * std::log10(d) - 18.0 * std::abs(floor - aps[a].floor) / 2.0 + noise;
          rss << (a ? "," : "");
          if (!on || rssi < -100) {
            rss << 100;
          } else {
            rss << std::round(rssi);
          }
        }
        rss << "\n";
        crd << x << "," << 0.0 << "," << floor << "\n";
        tms << static_cast<int64_t>(start_time_s) + 10 * row << "\n";
        ids << row / kLongTermScansPerPlace + 1 << "\n";
      }
    }
  }
}

// db/01/trn01 (2016-06-01), db/01/tst01 (the same day, the same access points) and db/12/tst01
// (2017-05-01) under `root`.
inline void WriteLongTermLibrary(const std::filesystem::path& root) {
  WriteLongTermSet(root, "01", "trn01", 0.0, false, 1464739200.0, 1);
  WriteLongTermSet(root, "01", "tst01", 1.5, false, 1464768000.0, 3);
  WriteLongTermSet(root, "12", "tst01", 1.5, true, 1493596800.0, 2);
}

}  // namespace ratslam::fixture

#endif  // RATSLAM_TESTS_UJI_LONG_TERM_FIXTURE_H_
