#include "fusion/fabmap/wifi_words.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "common/random.h"

namespace ratslam::fabmap {

std::string ToString(WifiEncoding encoding) {
  return encoding == WifiEncoding::kIncremental ? "incremental" : "exclusive";
}

StatusOr<WifiEncoding> WifiEncodingFromString(const std::string& name) {
  if (name == "exclusive") return WifiEncoding::kExclusive;
  if (name == "incremental") return WifiEncoding::kIncremental;
  return Status::Error("unknown Wi-Fi encoding '" + name + "' (expected exclusive or incremental)");
}

bool WifiWordOptions::IsValid(std::string* error) const {
  if (!schema::CheckFields(*this, error)) return false;
  if (!(min_rssi_dbm < max_rssi_dbm)) {
    if (error) *error = "min_rssi_dbm: must be below max_rssi_dbm";
    return false;
  }
  return true;
}

bool VirtualSampleOptions::IsValid(std::string* error) const {
  return schema::CheckFields(*this, error);
}

void WifiVocabulary::AddAccessPoints(const std::vector<WifiReading>& readings) {
  for (const WifiReading& r : readings) {
    if (index_.emplace(r.bssid, static_cast<uint32_t>(bssids_.size())).second) {
      bssids_.push_back(r.bssid);
    }
  }
}

std::optional<uint32_t> WifiVocabulary::IndexOf(const std::string& bssid) const {
  const auto it = index_.find(bssid);
  if (it == index_.end()) return std::nullopt;
  return it->second;
}

int WifiVocabulary::Bin(double rssi_dbm) const {
  if (!(rssi_dbm > options_.min_rssi_dbm)) return -1;  // also NaN
  const double width = (options_.max_rssi_dbm - options_.min_rssi_dbm) / options_.bins;
  const double bin = std::ceil((rssi_dbm - options_.min_rssi_dbm) / width) - 1.0;
  return static_cast<int>(std::clamp(bin, 0.0, options_.bins - 1.0));
}

void WifiVocabulary::AppendWords(uint32_t ap, double rssi_dbm, Observation* words) const {
  const int bin = Bin(rssi_dbm);
  if (bin < 0) return;
  const WordId first = ap * static_cast<uint32_t>(options_.bins);
  if (options_.encoding == WifiEncoding::kExclusive) {
    words->push_back(first + static_cast<uint32_t>(bin));
  } else {
    for (int k = 0; k <= bin; ++k) words->push_back(first + static_cast<uint32_t>(k));
  }
}

Observation WifiVocabulary::Encode(const std::vector<WifiReading>& readings) const {
  std::map<uint32_t, std::pair<double, int>> mean;  // ap -> (sum, count)
  for (const WifiReading& r : readings) {
    if (const auto ap = IndexOf(r.bssid)) {
      auto& m = mean[*ap];
      m.first += r.rssi_dbm;
      ++m.second;
    }
  }
  Observation words;
  for (const auto& [ap, m] : mean) AppendWords(ap, m.first / m.second, &words);
  std::sort(words.begin(), words.end());
  return words;
}

void CountStatistics(const std::vector<std::vector<WifiReading>>& scans, double* mean,
                     double* sigma) {
  *mean = 0.0;
  *sigma = 0.0;
  if (scans.empty()) return;
  double sum = 0.0, sum_sq = 0.0;
  for (const auto& s : scans) {
    std::vector<std::string> ids;
    for (const WifiReading& r : s) ids.push_back(r.bssid);
    std::sort(ids.begin(), ids.end());
    const double n = static_cast<double>(std::unique(ids.begin(), ids.end()) - ids.begin());
    sum += n;
    sum_sq += n * n;
  }
  const double count = static_cast<double>(scans.size());
  *mean = sum / count;
  *sigma = std::sqrt(std::max(0.0, sum_sq / count - *mean * *mean));
}

std::vector<Observation> VirtualWifiSamples(const WifiVocabulary& vocabulary, double mean_aps,
                                            double sigma_aps, const VirtualSampleOptions& options) {
  Random random(options.seed);
  const uint32_t known = vocabulary.access_points();
  std::vector<uint32_t> pool(known);
  std::vector<Observation> samples;
  samples.reserve(static_cast<size_t>(options.samples));
  const double lo = vocabulary.options().min_rssi_dbm, hi = vocabulary.options().max_rssi_dbm;
  for (int s = 0; s < options.samples; ++s) {
    const long drawn = std::lround(random.Gaussian(mean_aps, sigma_aps));
    const uint32_t count = static_cast<uint32_t>(std::max(0L, drawn));
    for (uint32_t i = 0; i < known; ++i) pool[i] = i;
    uint32_t left = known;
    Observation words;
    for (uint32_t i = 0; i < count; ++i) {
      const bool is_known = random.Uniform() < options.p_known;
      // RSSI uniform in ]lo, hi]: 1 - Uniform() is in (0, 1].
      const double rssi = lo + (hi - lo) * (1.0 - random.Uniform());
      if (!is_known || left == 0) continue;
      const uint32_t pick = static_cast<uint32_t>(random.NextU64() % left);
      const uint32_t ap = pool[pick];
      pool[pick] = pool[--left];
      vocabulary.AppendWords(ap, rssi, &words);
    }
    std::sort(words.begin(), words.end());
    samples.push_back(std::move(words));
  }
  return samples;
}

std::vector<size_t> SpacedIndices(const std::vector<double>& travelled_m,
                                  const std::vector<double>& time_s, double min_distance_m,
                                  double min_interval_s) {
  std::vector<size_t> kept;
  for (size_t i = 0; i < travelled_m.size() && i < time_s.size(); ++i) {
    if (kept.empty()) {
      kept.push_back(i);
      continue;
    }
    const double moved = travelled_m[i] - travelled_m[kept.back()];
    const double waited = time_s[i] - time_s[kept.back()];
    // Unknown travel (NaN at either end; fingerprint data sets record none) waives the distance
    // condition: spacing by travel applies only where travel exists.
    const bool far_enough = std::isnan(moved) || moved >= min_distance_m;
    // Travel or time going backwards starts a new session: keep its first observation.
    if (moved < 0.0 || waited < 0.0 || (far_enough && waited >= min_interval_s)) {
      kept.push_back(i);
    }
  }
  return kept;
}

}  // namespace ratslam::fabmap
