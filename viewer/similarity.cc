#include "viewer/similarity.h"

#include <algorithm>

namespace ratslam::viewer {

StatusOr<SimilarityMatrix> CameraSimilarityMatrix(const dataset::Dataset& dataset,
                                                  ImageLoader* images,
                                                  const sensors::ClassicCameraOptions& options,
                                                  int max_frames) {
  if (dataset.images.empty()) return Status::Error(dataset.name + ": the data set has no images");
  if (max_frames < 2) return Status::Error("max_frames must be at least 2");
  const size_t total = dataset.images.size();
  const size_t n = std::min(total, static_cast<size_t>(max_frames));
  sensors::ClassicCameraMatcher matcher(options);
  std::vector<std::vector<uint8_t>> templates;
  SimilarityMatrix m;
  for (size_t i = 0; i < n; ++i) {
    const ImageRow& row = dataset.images[i * (total - 1) / std::max<size_t>(n - 1, 1)];
    StatusOr<GrayImage> image = images->Load(dataset.ImagePath(row));
    if (!image.ok()) return image.status().WithContext("images.csv:" + std::to_string(row.line));
    StatusOr<std::vector<uint8_t>> t =
        matcher.MakeTemplate({image->width, image->height, image->width, image->pixels.data()});
    if (!t.ok()) return t.status().WithContext(row.file);
    matcher.Add(t.value());
    templates.push_back(std::move(t.value()));
    m.times_s.push_back(row.time_s);
  }
  std::vector<double> differences;
  differences.reserve(n * n);
  for (const std::vector<uint8_t>& t : templates) {
    const std::vector<double> row = matcher.Differences(t);
    differences.insert(differences.end(), row.begin(), row.end());
  }
  std::vector<double> sorted = differences;
  const size_t p95 = sorted.size() * 95 / 100;
  std::nth_element(sorted.begin(), sorted.begin() + p95, sorted.end());
  m.reference_difference = std::max(sorted[p95], 1e-9);
  m.values.reserve(differences.size());
  for (double d : differences) {
    m.values.push_back(static_cast<float>(std::clamp(1.0 - d / m.reference_difference, 0.0, 1.0)));
  }
  return m;
}

StatusOr<SimilarityMatrix> WifiSimilarityMatrix(const dataset::Dataset& dataset,
                                                const sensors::WifiMatcherOptions& options,
                                                int max_scans) {
  if (dataset.wifi.empty())
    return Status::Error(dataset.name + ": the data set has no Wi-Fi scans");
  if (max_scans < 2) return Status::Error("max_scans must be at least 2");
  const size_t total = dataset.wifi.size();
  const size_t n = std::min(total, static_cast<size_t>(max_scans));
  sensors::WifiFingerprintMatcher matcher(options);
  std::vector<sensors::Fingerprint> fingerprints;
  SimilarityMatrix m;
  for (size_t i = 0; i < n; ++i) {
    const WifiScan& scan = dataset.wifi[i * (total - 1) / std::max<size_t>(n - 1, 1)];
    std::vector<std::pair<std::string, double>> readings;
    for (const WifiReading& r : scan.readings) readings.emplace_back(r.bssid, r.rssi_dbm);
    fingerprints.push_back(matcher.MakeFingerprint(readings));
    matcher.Add(fingerprints.back());
    m.times_s.push_back(scan.time_s);
  }
  for (const sensors::Fingerprint& f : fingerprints) {
    for (double w : matcher.Weights(f)) m.values.push_back(static_cast<float>(w));
  }
  m.reference_difference = 0.0;
  return m;
}

}  // namespace ratslam::viewer
