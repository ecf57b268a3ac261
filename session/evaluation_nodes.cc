#include "session/evaluation_nodes.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>
#include <system_error>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "dataset/dataset_loader.h"
#include "dataset/uji_long_term.h"
#include "dataset/ujiindoorloc.h"
#include "io/visual_model_file.h"
#include "sensors/rssi_offset.h"

namespace ratslam::session {

using fabmap::EvaluationNode;
using fabmap::EvaluationOptions;

namespace {

namespace fs = std::filesystem;

int FloorOfFolder(const std::string& name, int fallback) {
  std::string digits;
  for (char c : name) {
    if (std::isdigit(static_cast<unsigned char>(c)) || (c == '-' && digits.empty())) digits += c;
  }
  int value = 0;
  const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  // No digits, or too many for an int (a folder named by the user): the fallback.
  if (r.ec != std::errc() || r.ptr != digits.data() + digits.size()) return fallback;
  return value;
}

// Image folder: each sub-folder is a floor (the number in its name), frames along a line.
StatusOr<std::vector<EvaluationNode>> ImageFolderNodes(const std::string& path,
                                                       const EvaluationOptions& options) {
  std::vector<std::string> floors;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(path, ec)) {
    if (entry.is_directory(ec)) floors.push_back(entry.path().string());
  }
  std::sort(floors.begin(), floors.end());
  if (floors.empty()) floors.push_back(path);
  std::vector<EvaluationNode> nodes;
  for (size_t f = 0; f < floors.size(); ++f) {
    auto images = io::ListImages(floors[f]);
    if (!images.ok()) return images.status();
    const int floor = FloorOfFolder(fs::path(floors[f]).filename().string(), static_cast<int>(f));
    for (size_t i = 0; i < images->size(); ++i) {
      EvaluationNode n;
      n.x_m = options.frame_spacing_m * static_cast<double>(i);
      n.floor = floor;
      n.time_s = static_cast<double>(i);
      n.travelled_m = n.x_m;
      n.session = static_cast<int>(f);
      n.image = (*images)[i];
      nodes.push_back(std::move(n));
    }
  }
  return nodes;
}

// Labelled single captures (UJIIndoorLoc, long-term UJI library) as nodes, with the floor and
// session each reader defines, in time order, so that an interleaved split alternates captures.
// No travel between rows: the Wi-Fi tree spaces them by time only (every map row learns it by
// default).
template <typename FloorAndSession>
std::vector<EvaluationNode> CaptureNodes(const std::vector<dataset::LabelledScan>& rows,
                                         FloorAndSession floor_and_session) {
  std::vector<EvaluationNode> nodes;
  for (const dataset::LabelledScan& s : rows) {
    EvaluationNode n;
    n.x_m = s.x_m;
    n.y_m = s.y_m;
    std::tie(n.floor, n.session) = floor_and_session(s);
    n.time_s = s.time_s;
    n.travelled_m = std::numeric_limits<double>::quiet_NaN();
    n.wifi = s.readings;
    nodes.push_back(std::move(n));
  }
  std::stable_sort(
      nodes.begin(), nodes.end(),
      [](const EvaluationNode& a, const EvaluationNode& b) { return a.time_s < b.time_s; });
  return nodes;
}

// UJIIndoorLoc: another building counts as another floor; a session is a user and phone.
StatusOr<std::vector<EvaluationNode>> UjiNodes(const std::string& path, bool lenient) {
  auto rows = dataset::ReadUjiIndoorLoc(path, lenient);
  if (!rows.ok()) return rows.status();
  auto nodes = CaptureNodes(*rows, [](const dataset::LabelledScan& s) {
    return std::pair(s.building * 100 + s.floor, s.user * 100 + s.phone);
  });
  for (EvaluationNode& n : nodes) n.building = n.floor / 100;
  return nodes;
}

// A long-term UJI library set (db/<month>/<set>rss.csv and its siblings): the session is 100 x
// the month (the folder's number) + the set's number (tst03 -> 3; 0 to 99), so that sets of
// different months never share one.
StatusOr<std::vector<EvaluationNode>> LongTermNodes(const std::string& path, bool lenient) {
  auto rows = dataset::ReadUjiLongTermSet(path, lenient);
  if (!rows.ok()) return rows.status();
  const fs::path p(path);
  const int month = std::clamp(FloorOfFolder(p.parent_path().filename().string(), 0), 0, 1000000);
  const int set = std::clamp(FloorOfFolder(p.filename().string(), 0), 0, 99);
  return CaptureNodes(
      *rows, [&](const dataset::LabelledScan& s) { return std::pair(s.floor, month * 100 + set); });
}

std::vector<EvaluationNode> DatasetNodes(const dataset::Dataset& d, bool as_map, bool want_images,
                                         const EvaluationOptions& options) {
  std::vector<EvaluationNode> nodes;
  auto session_of = [&](double t) {
    int s = 0;
    for (size_t k = 1; k < d.session_start_times_s.size(); ++k) {
      if (t >= d.session_start_times_s[k]) s = static_cast<int>(k);
    }
    return s;
  };
  auto add = [&](double t, std::string image, std::optional<std::vector<WifiReading>> wifi) {
    const auto truth = dataset::GroundTruthAt(d, t);
    if (!truth) return;
    EvaluationNode n;
    n.x_m = truth->x_m;
    n.y_m = truth->y_m;
    n.floor = truth->floor;
    n.time_s = t;
    n.session = session_of(t);
    if (!nodes.empty() && nodes.back().session == n.session) {
      n.travelled_m =
          nodes.back().travelled_m + std::hypot(n.x_m - nodes.back().x_m, n.y_m - nodes.back().y_m);
    }
    n.image = std::move(image);
    n.wifi = std::move(wifi);
    nodes.push_back(std::move(n));
  };
  if (want_images && !d.images.empty()) {
    std::vector<double> scan_times;
    for (const WifiScan& s : d.wifi) scan_times.push_back(s.time_s);
    for (const ImageRow& row : d.images) {
      // Map: the temporally closest scan; queries: the last scan before the image (sec. 5.2).
      // Scans are in time order; of scans at one time the first counts.
      const WifiScan* best = nullptr;
      const size_t next = static_cast<size_t>(
          std::upper_bound(scan_times.begin(), scan_times.end(), row.time_s) - scan_times.begin());
      if (next > 0) {
        const double t = scan_times[next - 1];
        best =
            &d.wifi[std::lower_bound(scan_times.begin(), scan_times.end(), t) - scan_times.begin()];
      }
      if (as_map && next < d.wifi.size() &&
          (!best || scan_times[next] - row.time_s < row.time_s - best->time_s)) {
        best = &d.wifi[next];
      }
      std::optional<std::vector<WifiReading>> wifi;
      if (best && std::abs(best->time_s - row.time_s) <= options.image_wifi_max_gap_s) {
        wifi = best->readings;
      }
      add(row.time_s, d.ImagePath(row), std::move(wifi));
    }
  } else {
    for (const WifiScan& s : d.wifi) add(s.time_s, "", s.readings);
  }
  return nodes;
}

bool HasManifest(const std::string& path) {
  std::error_code ec;
  return fs::exists(fs::path(path) / "manifest.toml", ec);
}

}  // namespace

StatusOr<std::vector<EvaluationNode>> LoadEvaluationNodes(const std::string& path, bool as_map,
                                                          bool want_images,
                                                          const EvaluationOptions& options,
                                                          const dataset::PhoneLogOptions& phone,
                                                          const dataset::BagTopics& bag,
                                                          const dataset::VideoOptions& video) {
  std::string error;
  if (!options.IsValid(&error)) return Status::Error("[evaluation] " + error);
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::Error(path + ": no such file or folder");
  if (fs::is_regular_file(path, ec) && fs::path(path).extension() == ".csv") {
    if (dataset::IsUjiLongTermSet(path)) return LongTermNodes(path, phone.lenient);
    return UjiNodes(path, phone.lenient);
  }
  if (fs::is_directory(path, ec) && !HasManifest(path)) {
    // A folder of phone logs (recursively), or else of images.
    std::vector<std::string> logs;
    for (auto it = fs::recursive_directory_iterator(path, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
      if (it->is_regular_file(ec) && it->path().extension() == ".txt" &&
          dataset::DetectDatasetFormat(it->path().string()).ok()) {
        logs.push_back(it->path().string());
      }
    }
    std::sort(logs.begin(), logs.end());
    if (logs.empty()) return ImageFolderNodes(path, options);
    auto d = dataset::LoadSessions(logs, phone);
    if (!d.ok()) return d.status();
    return DatasetNodes(*d, as_map, want_images, options);
  }
  auto d = dataset::LoadDataset(path, phone, bag, video);
  if (!d.ok()) return d.status();
  return DatasetNodes(*d, as_map, want_images, options);
}

std::vector<SessionRssiOffset> RemoveQueryRssiOffsets(
    const std::vector<fabmap::EvaluationNode>& map, std::vector<fabmap::EvaluationNode>* queries,
    int min_common_aps, int min_estimates) {
  std::unordered_map<std::string, uint32_t> ap_ids;
  auto fingerprint = [&](const std::vector<WifiReading>& readings) {
    return sensors::InternedFingerprint(readings, &ap_ids);
  };
  std::vector<sensors::Fingerprint> references;
  references.reserve(map.size());
  for (const fabmap::EvaluationNode& n : map) {
    references.push_back(n.wifi ? fingerprint(*n.wifi) : sensors::Fingerprint());
  }
  std::vector<int> order;  // sessions by first appearance
  std::unordered_map<int, std::vector<size_t>> members;
  for (size_t i = 0; i < queries->size(); ++i) {
    auto [it, added] = members.try_emplace((*queries)[i].session);
    if (added) order.push_back((*queries)[i].session);
    it->second.push_back(i);
  }
  std::vector<SessionRssiOffset> offsets;
  for (int session : order) {
    std::vector<size_t>& nodes = members.at(session);
    std::stable_sort(nodes.begin(), nodes.end(), [&](size_t a, size_t b) {
      return (*queries)[a].time_s < (*queries)[b].time_s;
    });
    sensors::RssiOffsetTracker tracker(min_common_aps, min_estimates);
    tracker.OnSessionStart(0.0, 0);  // the map: the reference units
    for (size_t k = 0; k < references.size(); ++k) tracker.AddTemplate();
    tracker.OnSessionStart(1.0, static_cast<uint32_t>(references.size()));
    for (size_t i : nodes) {
      std::optional<std::vector<WifiReading>>& wifi = (*queries)[i].wifi;
      if (!wifi || wifi->empty()) continue;
      sensors::Fingerprint scan = fingerprint(*wifi);
      tracker.Calibrate(references, &scan);
      const double offset = tracker.CurrentOffset();
      for (WifiReading& r : *wifi) r.rssi_dbm -= offset;
    }
    offsets.push_back({session, tracker.CurrentOffset()});
  }
  return offsets;
}

}  // namespace ratslam::session
