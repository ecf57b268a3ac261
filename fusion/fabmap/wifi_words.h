// Wi-Fi words for FABMAP (the fusion paper's section 3).
//
// The vocabulary is the access points seen during exploration (section 3.1), each described by b
// words over the usable RSSI range ]min, max]: the range is split into b equal bins. `exclusive`
// sets the one word of the reading's bin; `incremental` (Wietrzykowski et al. 2017) sets every
// word up to it. b = 1 is presence only. Readings at or below `min` are not usable (left out);
// above `max` they fall in the top bin. Repeated readings of one AP in a scan are averaged first.
//
// Virtual Wi-Fi samples for the unknown world (section 3.3): the number of APs is drawn from
// N(mu, sigma) of the exploration scans' AP counts; each is a known AP (drawn without repeats)
// with probability p_known, else an unknown one, which adds no word; its RSSI is uniform in the
// usable range.
#ifndef RATSLAM_FUSION_FABMAP_WIFI_WORDS_H_
#define RATSLAM_FUSION_FABMAP_WIFI_WORDS_H_

#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "common/schema.h"
#include "common/sensor_samples.h"
#include "common/status.h"
#include "fusion/fabmap/chow_liu.h"

namespace ratslam::fabmap {

enum class WifiEncoding { kExclusive, kIncremental };
std::string ToString(WifiEncoding encoding);
StatusOr<WifiEncoding> WifiEncodingFromString(const std::string& name);

struct WifiWordOptions {
  int bins = 1;                                      // b: words per access point
  WifiEncoding encoding = WifiEncoding::kExclusive;  // exclusive or incremental
  double min_rssi_dbm = -90.0;  // usable range ]min, max] (the paper's ]-90, 0] dBm)
  double max_rssi_dbm = 0.0;

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("bins", bins, "b: words per access point (1 = presence only)",
      schema::Unit("words").Within(1, 256));
    v("encoding", encoding, "exclusive (one bin set) or incremental (all bins up to the level)",
      schema::Any());
    v("min_rssi_dbm", min_rssi_dbm, "usable RSSI range ]min, max], dBm", schema::Unit("dBm"));
    v("max_rssi_dbm", max_rssi_dbm, "usable RSSI range ]min, max], dBm", schema::Unit("dBm"));
  }
};

class WifiVocabulary {
 public:
  explicit WifiVocabulary(const WifiWordOptions& options) : options_(options) {}
  const WifiWordOptions& options() const { return options_; }

  // Adds the scan's access points not yet known, in order of first sighting.
  void AddAccessPoints(const std::vector<WifiReading>& readings);
  uint32_t access_points() const { return static_cast<uint32_t>(bssids_.size()); }
  uint32_t size() const { return access_points() * static_cast<uint32_t>(options_.bins); }
  std::optional<uint32_t> IndexOf(const std::string& bssid) const;
  const std::vector<std::string>& bssids() const { return bssids_; }

  // The bin of a reading, or -1 when it is at or below the usable range.
  int Bin(double rssi_dbm) const;
  // The words of one reading of access point `ap` (none when the reading is not usable).
  void AppendWords(uint32_t ap, double rssi_dbm, Observation* words) const;
  // The words of a scan; unknown access points are left out.
  Observation Encode(const std::vector<WifiReading>& readings) const;

 private:
  WifiWordOptions options_;
  std::vector<std::string> bssids_;
  std::unordered_map<std::string, uint32_t> index_;
};

struct VirtualSampleOptions {
  int samples = 500;     // n_s
  double p_known = 0.5;  // chance that a simulated AP is a known one
  uint64_t seed = 1;
  // Use the exploration scans themselves as the unknown world instead of virtual samples. In a
  // building whose scans all share one core of access points, virtual samples (random AP
  // subsets) make any mapped place explain a new scan better than the unknown world does.
  bool use_exploration_scans = false;

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("samples", samples, "n_s: virtual Wi-Fi samples for the unknown world (section 3.3)",
      schema::Unit("scans").AtLeast(1));
    v("p_known", p_known, "chance that a simulated access point is a known one",
      schema::Unit("").Within(0, 1));
    v("seed", seed, "seed of the virtual samples", schema::Any());
    v("use_exploration_scans", use_exploration_scans,
      "the unknown world is the exploration scans themselves, not virtual samples", schema::Any());
  }
};

// Mean and standard deviation of the number of access points per scan.
void CountStatistics(const std::vector<std::vector<WifiReading>>& scans, double* mean,
                     double* sigma);

std::vector<Observation> VirtualWifiSamples(const WifiVocabulary& vocabulary, double mean_aps,
                                            double sigma_aps, const VirtualSampleOptions& options);

// Indices of observations kept for learning the Wi-Fi tree (section 3.2): each kept one is at
// least `min_distance_m` of travel and `min_interval_s` after the previously kept one. Travel or
// time going backwards marks a new session, whose first observation is kept. A NaN travel means
// the data set records none (UJIIndoorLoc rows): only the time condition applies to it.
std::vector<size_t> SpacedIndices(const std::vector<double>& travelled_m,
                                  const std::vector<double>& time_s, double min_distance_m,
                                  double min_interval_s);

}  // namespace ratslam::fabmap

#endif  // RATSLAM_FUSION_FABMAP_WIFI_WORDS_H_
