#include "dataset/dataset.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <utility>

#include "common/circular.h"
#include "common/file_util.h"
#include "common/number_text.h"
#include "common/text_file.h"
#include "common/toml_binder.h"
#include "dataset/csv.h"

namespace ratslam::dataset {
namespace fs = std::filesystem;
namespace {

constexpr int kFormatVersion = 1;

// The manifest's keys, bound by the common TOML binder (common/toml_binder.h). Streams are
// optional except odometry; a stream that is named must be a path inside the data-set folder.
struct ManifestStreams {
  std::string odometry, images, image_folder, ground_truth, wifi, compass, pressure;

  template <typename V>
  void VisitFields(V&& v) {
    const schema::Rule file = schema::Any().RelativePath();
    v("odometry", odometry, "odometry CSV: time_s, forward_speed_m_per_s, turn_rate_rad_per_s",
      file);
    v("images", images, "image list CSV: time_s, file", file);
    v("image_folder", image_folder, "folder the image list's files are in", file);
    v("ground_truth", ground_truth, "ground truth CSV: time_s, x_m, y_m, theta_rad, floor", file);
    v("wifi", wifi, "Wi-Fi CSV: time_s, bssid, rssi_dbm", file);
    v("compass", compass, "compass CSV: time_s, heading_rad", file);
    v("pressure", pressure, "barometer CSV: time_s, pressure_hpa", file);
  }
};

struct Manifest {
  std::string format;
  int format_version = 0;
  std::string name;
  std::vector<double> session_start_times_s;
  std::vector<std::string> session_names;

  template <typename V>
  void VisitFields(V&& v) {
    v("format", format, "always \"ratslam-replay\"", schema::Any());
    v("format_version", format_version, "version of this format", schema::Any());
    v("name", name, "the data set's name (default: its folder's)", schema::Any());
    v("session_start_times_s", session_start_times_s,
      "times at which the sessions of a multi-session data set start",
      schema::Unit("s").NonNegative().Increasing());
    v("session_names", session_names,
      "what figures and summaries call the sessions, one per session start", schema::Any());
  }
};

// Fails when a time is negative or goes backwards between consecutive rows.
Status CheckTimeOrder(const CsvTable& table, size_t row, double previous, double current) {
  if (current < 0.0) return table.ErrorAt(row, "time_s", "must not be negative");
  if (row > 0 && current < previous) {
    return table.ErrorAt(row, "time_s",
                         "time goes backwards (" + std::to_string(current) + " after " +
                             std::to_string(previous) + ")");
  }
  return Status::Ok();
}

#define ASSIGN_OR_RETURN_NUMBER(lhs, table, row, column)   \
  do {                                                     \
    StatusOr<double> value_ = (table).Number(row, column); \
    if (!value_.ok()) return value_.status();              \
    lhs = value_.value();                                  \
  } while (false)

Status ReadOdometry(const std::string& path, Dataset* d) {
  StatusOr<CsvTable> t =
      CsvTable::Read(path, {"time_s", "forward_speed_m_per_s", "turn_rate_rad_per_s"});
  if (!t.ok()) return t.status();
  for (size_t r = 0; r < t->rows(); ++r) {
    OdometryRow row;
    ASSIGN_OR_RETURN_NUMBER(row.time_s, *t, r, "time_s");
    ASSIGN_OR_RETURN_NUMBER(row.forward_speed_m_per_s, *t, r, "forward_speed_m_per_s");
    ASSIGN_OR_RETURN_NUMBER(row.turn_rate_rad_per_s, *t, r, "turn_rate_rad_per_s");
    RATSLAM_RETURN_IF_ERROR(CheckTimeOrder(*t, r, r ? d->odometry.back().time_s : 0.0, row.time_s));
    d->odometry.push_back(row);
  }
  return Status::Ok();
}

Status ReadImages(const std::string& path, Dataset* d) {
  StatusOr<CsvTable> t = CsvTable::Read(path, {"time_s", "file"});
  if (!t.ok()) return t.status();
  for (size_t r = 0; r < t->rows(); ++r) {
    ImageRow row;
    ASSIGN_OR_RETURN_NUMBER(row.time_s, *t, r, "time_s");
    StatusOr<std::string> file = t->Text(r, "file");
    if (!file.ok()) return file.status();
    if (fs::path(*file).is_absolute() || file->find("..") != std::string::npos) {
      return t->ErrorAt(r, "file", "must be a relative path inside the image folder");
    }
    row.file = *file;
    row.line = t->line(r);
    RATSLAM_RETURN_IF_ERROR(CheckTimeOrder(*t, r, r ? d->images.back().time_s : 0.0, row.time_s));
    d->images.push_back(row);
  }
  return Status::Ok();
}

Status ReadGroundTruth(const std::string& path, Dataset* d) {
  StatusOr<CsvTable> t = CsvTable::Read(path, {"time_s", "x_m", "y_m"}, {"theta_rad", "floor"});
  if (!t.ok()) return t.status();
  for (size_t r = 0; r < t->rows(); ++r) {
    GroundTruthRow row;
    ASSIGN_OR_RETURN_NUMBER(row.time_s, *t, r, "time_s");
    ASSIGN_OR_RETURN_NUMBER(row.x_m, *t, r, "x_m");
    ASSIGN_OR_RETURN_NUMBER(row.y_m, *t, r, "y_m");
    if (t->has_column("theta_rad")) ASSIGN_OR_RETURN_NUMBER(row.theta_rad, *t, r, "theta_rad");
    if (t->has_column("floor")) {
      double floor = 0.0;
      ASSIGN_OR_RETURN_NUMBER(floor, *t, r, "floor");
      if (floor != std::floor(floor) || std::abs(floor) > 1000) {
        return t->ErrorAt(r, "floor", "must be a whole number");
      }
      row.floor = static_cast<int>(floor);
    }
    RATSLAM_RETURN_IF_ERROR(
        CheckTimeOrder(*t, r, r ? d->ground_truth.back().time_s : 0.0, row.time_s));
    d->ground_truth.push_back(row);
  }
  return Status::Ok();
}

Status ReadWifi(const std::string& path, Dataset* d) {
  StatusOr<CsvTable> t = CsvTable::Read(path, {"time_s", "bssid", "rssi_dbm"});
  if (!t.ok()) return t.status();
  for (size_t r = 0; r < t->rows(); ++r) {
    double time_s = 0.0;
    WifiReading reading;
    ASSIGN_OR_RETURN_NUMBER(time_s, *t, r, "time_s");
    ASSIGN_OR_RETURN_NUMBER(reading.rssi_dbm, *t, r, "rssi_dbm");
    StatusOr<std::string> bssid = t->Text(r, "bssid");
    if (!bssid.ok()) return bssid.status();
    reading.bssid = *bssid;
    RATSLAM_RETURN_IF_ERROR(
        CheckTimeOrder(*t, r, d->wifi.empty() ? 0.0 : d->wifi.back().time_s, time_s));
    if (d->wifi.empty() || d->wifi.back().time_s != time_s) d->wifi.push_back({time_s, {}});
    d->wifi.back().readings.push_back(reading);
  }
  return Status::Ok();
}

Status ReadCompass(const std::string& path, Dataset* d) {
  StatusOr<CsvTable> t = CsvTable::Read(path, {"time_s", "heading_rad"});
  if (!t.ok()) return t.status();
  for (size_t r = 0; r < t->rows(); ++r) {
    CompassRow row;
    ASSIGN_OR_RETURN_NUMBER(row.time_s, *t, r, "time_s");
    ASSIGN_OR_RETURN_NUMBER(row.heading_rad, *t, r, "heading_rad");
    RATSLAM_RETURN_IF_ERROR(CheckTimeOrder(*t, r, r ? d->compass.back().time_s : 0.0, row.time_s));
    d->compass.push_back(row);
  }
  return Status::Ok();
}

Status ReadPressure(const std::string& path, Dataset* d) {
  StatusOr<CsvTable> t = CsvTable::Read(path, {"time_s", "pressure_hpa"});
  if (!t.ok()) return t.status();
  for (size_t r = 0; r < t->rows(); ++r) {
    PressureSample row;
    ASSIGN_OR_RETURN_NUMBER(row.time_s, *t, r, "time_s");
    ASSIGN_OR_RETURN_NUMBER(row.pressure_hpa, *t, r, "pressure_hpa");
    if (!(row.pressure_hpa >= 100 && row.pressure_hpa <= 1100)) {
      return t->ErrorAt(r, "pressure_hpa", "must be within [100, 1100] hPa");
    }
    RATSLAM_RETURN_IF_ERROR(CheckTimeOrder(*t, r, r ? d->pressure.back().time_s : 0.0, row.time_s));
    d->pressure.push_back(row);
  }
  return Status::Ok();
}

std::string Number(double value) { return ShortestNumber(value); }

}  // namespace

std::string Dataset::ImagePath(const ImageRow& row) const {
  if (fs::path(row.file).is_absolute()) return row.file;
  return (fs::path(folder) / image_folder / row.file).string();
}

std::string Dataset::SessionName(size_t index) const {
  if (index < session_names.size() && !session_names[index].empty()) return session_names[index];
  return "session " + std::to_string(index + 1);
}

size_t Dataset::SessionAt(double time_s) const {
  size_t session = 0;
  while (session + 1 < session_start_times_s.size() &&
         time_s >= session_start_times_s[session + 1]) {
    ++session;
  }
  return session;
}

StatusOr<Dataset> ReadDataset(const std::string& folder) {
  const std::string manifest_path = (fs::path(folder) / "manifest.toml").string();
  if (!IsDirectory(folder)) return Status::Error(folder + ": not a data-set folder");
  if (!PathExists(manifest_path)) return Status::Error(manifest_path + ": missing manifest");
  StatusOr<std::string> manifest_text = ReadRegularFile(manifest_path, "manifest", 1 << 20);
  if (!manifest_text.ok()) return manifest_text.status();
  StatusOr<toml::table> parsed = schema::ParseToml(*manifest_text, manifest_path);
  if (!parsed.ok()) return parsed.status();
  Manifest manifest;
  ManifestStreams streams;
  schema::TableBinder top(*parsed, "the manifest", "", manifest_path);
  manifest.VisitFields(top);
  const toml::table* streams_table = top.Table("streams");
  RATSLAM_RETURN_IF_ERROR(top.Finish());
  if (manifest.format != "ratslam-replay") {
    return Status::Error(schema::TomlWhere(manifest_path, parsed->get("format")) +
                         ": format must be \"ratslam-replay\"");
  }
  if (manifest.format_version != kFormatVersion) {
    return Status::Error(schema::TomlWhere(manifest_path, parsed->get("format_version")) +
                         ": unsupported format_version (this program reads " +
                         std::to_string(kFormatVersion) + ")");
  }
  if (!streams_table) return Status::Error(manifest_path + ": missing [streams] table");
  schema::TableBinder stream_binder(*streams_table, "[streams]", "streams.", manifest_path);
  streams.VisitFields(stream_binder);
  RATSLAM_RETURN_IF_ERROR(stream_binder.Finish());
  // Odometry may come from the images instead ([visual_odometry]; St Lucia 2007 has none).
  if (streams.odometry.empty() && streams.images.empty()) {
    return Status::Error(schema::TomlWhere(manifest_path, streams_table) +
                         ": streams.odometry is required (or streams.images, for visual "
                         "odometry)");
  }
  Dataset d;
  d.folder = folder;
  d.name = parsed->contains("name") ? manifest.name : fs::path(folder).filename().string();
  d.session_start_times_s = manifest.session_start_times_s;
  if (!manifest.session_names.empty() &&
      manifest.session_names.size() != std::max<size_t>(1, manifest.session_start_times_s.size())) {
    return Status::Error(
        schema::TomlWhere(manifest_path, parsed->get("session_names")) +
        ": session_names: " + std::to_string(manifest.session_names.size()) + " names for " +
        std::to_string(std::max<size_t>(1, manifest.session_start_times_s.size())) +
        " sessions (one per session_start_times_s entry)");
  }
  d.session_names = manifest.session_names;
  if (!streams.image_folder.empty()) d.image_folder = streams.image_folder;
  const std::map<std::string, std::string> files = {
      {"odometry", streams.odometry},         {"images", streams.images},
      {"ground_truth", streams.ground_truth}, {"wifi", streams.wifi},
      {"compass", streams.compass},           {"pressure", streams.pressure}};
  auto path_of = [&](const std::string& stream) {
    return (fs::path(folder) / files.at(stream)).string();
  };
  auto named = [&](const std::string& stream) { return !files.at(stream).empty(); };
  if (named("odometry")) RATSLAM_RETURN_IF_ERROR(ReadOdometry(path_of("odometry"), &d));
  if (named("images")) RATSLAM_RETURN_IF_ERROR(ReadImages(path_of("images"), &d));
  if (named("ground_truth")) RATSLAM_RETURN_IF_ERROR(ReadGroundTruth(path_of("ground_truth"), &d));
  if (named("wifi")) RATSLAM_RETURN_IF_ERROR(ReadWifi(path_of("wifi"), &d));
  if (named("compass")) RATSLAM_RETURN_IF_ERROR(ReadCompass(path_of("compass"), &d));
  if (named("pressure")) RATSLAM_RETURN_IF_ERROR(ReadPressure(path_of("pressure"), &d));
  return d;
}

namespace {

// A text field the CSV reader gives back unchanged: not empty, no separator, line break or
// comment start, no spaces at either end (the reader trims them).
bool CsvSafe(const std::string& text) {
  return !text.empty() && text.find_first_of(",\n\r") == std::string::npos && text.front() != '#' &&
         text.front() != ' ' && text.front() != '\t' && text.back() != ' ' && text.back() != '\t';
}

// Every number the reader will accept back (finite, within kMaxCsvMagnitude).
class Numbers {
 public:
  std::string operator()(double value, const char* what) {
    if (!std::isfinite(value) || std::abs(value) > kMaxCsvMagnitude) {
      if (error.empty()) error = std::string(what) + " " + Number(value) + " is not writable";
    }
    return Number(value);
  }
  std::string error;
};

}  // namespace

Status WriteDataset(const Dataset& d, const std::string& folder) {
  // Everything is checked and formatted before the first byte is written: a data set we write
  // must read back, so a value the reader would refuse is an error here, naming it.
  Numbers num;
  std::string odometry = "time_s,forward_speed_m_per_s,turn_rate_rad_per_s\n";
  for (const OdometryRow& r : d.odometry) {
    odometry += num(r.time_s, "odometry time") + ',' +
                num(r.forward_speed_m_per_s, "odometry speed") + ',' +
                num(r.turn_rate_rad_per_s, "odometry turn rate") + '\n';
  }
  std::string images = "time_s,file\n";
  for (const ImageRow& r : d.images) {
    if (!CsvSafe(r.file))
      return Status::Error(folder + ": image file name '" + r.file +
                           "' cannot be stored in images.csv");
    images += num(r.time_s, "image time") + ',' + r.file + '\n';
  }
  std::string ground_truth = "time_s,x_m,y_m,theta_rad,floor\n";
  for (const GroundTruthRow& r : d.ground_truth) {
    if (std::abs(r.floor) > 1000) {
      return Status::Error(folder + ": ground-truth floor " + std::to_string(r.floor) +
                           " is not writable (at most 1000 floors either way)");
    }
    ground_truth += num(r.time_s, "ground-truth time") + ',' + num(r.x_m, "ground-truth x") + ',' +
                    num(r.y_m, "ground-truth y") + ',' + num(r.theta_rad, "ground-truth heading") +
                    ',' + std::to_string(r.floor) + '\n';
  }
  std::string wifi = "time_s,bssid,rssi_dbm\n";
  for (const WifiScan& scan : d.wifi) {
    for (const WifiReading& r : scan.readings) {
      if (!CsvSafe(r.bssid)) {
        return Status::Error(folder + ": BSSID '" + r.bssid + "' cannot be stored in wifi.csv");
      }
      wifi += num(scan.time_s, "scan time") + ',' + r.bssid + ',' + num(r.rssi_dbm, "RSSI") + '\n';
    }
  }
  std::string compass = "time_s,heading_rad\n";
  for (const CompassRow& r : d.compass) {
    compass += num(r.time_s, "compass time") + ',' + num(r.heading_rad, "compass heading") + '\n';
  }
  std::string pressure = "time_s,pressure_hpa\n";
  for (const PressureSample& r : d.pressure) {
    if (!(r.pressure_hpa >= 100 && r.pressure_hpa <= 1100)) {
      return Status::Error(folder + ": pressure " + Number(r.pressure_hpa) +
                           " hPa is not writable (the reader takes 100 to 1100)");
    }
    pressure += num(r.time_s, "pressure time") + ',' + num(r.pressure_hpa, "pressure") + '\n';
  }
  std::string manifest =
      "format = \"ratslam-replay\"\nformat_version = " + std::to_string(kFormatVersion) +
      "\nname = " + TomlQuoted(d.name) + "\n";
  if (d.session_start_times_s.size() > 1) {
    manifest += "session_start_times_s = [";
    for (size_t i = 0; i < d.session_start_times_s.size(); ++i) {
      manifest += (i ? ", " : "") + num(d.session_start_times_s[i], "session start");
    }
    manifest += "]\n";
  }
  if (!d.session_names.empty()) {
    if (d.session_names.size() != std::max<size_t>(1, d.session_start_times_s.size())) {
      return Status::Error(
          folder + ": " + std::to_string(d.session_names.size()) + " session names for " +
          std::to_string(std::max<size_t>(1, d.session_start_times_s.size())) + " sessions");
    }
    manifest += "session_names = [";
    for (size_t i = 0; i < d.session_names.size(); ++i) {
      manifest += (i ? ", " : "") + TomlQuoted(d.session_names[i]);
    }
    manifest += "]\n";
  }
  if (!num.error.empty()) return Status::Error(folder + ": " + num.error);
  const fs::path image_folder(d.image_folder);
  if (d.image_folder.empty() || image_folder.is_absolute() ||
      std::any_of(image_folder.begin(), image_folder.end(),
                  [](const fs::path& p) { return p == ".."; })) {
    return Status::Error(folder + ": image folder '" + d.image_folder +
                         "' must be a relative path inside the data set");
  }
  // The image folder sits beside the files written here; one named like them could not be both.
  for (const char* name : {"manifest.toml", "odometry.csv", "images.csv", "ground_truth.csv",
                           "wifi.csv", "compass.csv", "pressure.csv"}) {
    if (*image_folder.begin() == name) {
      return Status::Error(folder + ": image folder '" + d.image_folder +
                           "' cannot be stored: it has the name of the data set's file " + name);
    }
  }
  manifest += "\n[streams]\nodometry = \"odometry.csv\"\n";
  if (!d.images.empty()) {
    manifest += "images = \"images.csv\"\nimage_folder = " + TomlQuoted(d.image_folder) + "\n";
  }
  if (!d.ground_truth.empty()) manifest += "ground_truth = \"ground_truth.csv\"\n";
  if (!d.wifi.empty()) manifest += "wifi = \"wifi.csv\"\n";
  if (!d.compass.empty()) manifest += "compass = \"compass.csv\"\n";
  if (!d.pressure.empty()) manifest += "pressure = \"pressure.csv\"\n";

  std::error_code ec;
  fs::create_directories(fs::path(folder) / d.image_folder, ec);
  if (ec) return Status::Error(folder + ": cannot create folder: " + ec.message());
  auto write = [&](const char* name, const std::string& text) {
    return WriteFileAtomically((fs::path(folder) / name).string(), text);
  };
  // Each file is complete or absent; the manifest comes last, so a data set cut short by a
  // failure has no manifest and never reads as complete.
  RATSLAM_RETURN_IF_ERROR(write("odometry.csv", odometry));
  if (!d.images.empty()) RATSLAM_RETURN_IF_ERROR(write("images.csv", images));
  if (!d.ground_truth.empty()) RATSLAM_RETURN_IF_ERROR(write("ground_truth.csv", ground_truth));
  if (!d.wifi.empty()) RATSLAM_RETURN_IF_ERROR(write("wifi.csv", wifi));
  if (!d.compass.empty()) RATSLAM_RETURN_IF_ERROR(write("compass.csv", compass));
  if (!d.pressure.empty()) RATSLAM_RETURN_IF_ERROR(write("pressure.csv", pressure));
  return write("manifest.toml", manifest);
}

std::vector<Event> MergeEvents(const Dataset& d) {
  std::vector<Event> events;
  events.reserve(d.odometry.size() + d.images.size() + d.wifi.size() + d.compass.size() +
                 d.pressure.size());
  for (uint32_t i = 0; i < d.compass.size(); ++i) {
    events.push_back({d.compass[i].time_s, EventType::kCompass, i});
  }
  for (uint32_t i = 0; i < d.pressure.size(); ++i) {
    events.push_back({d.pressure[i].time_s, EventType::kPressure, i});
  }
  for (uint32_t i = 0; i < d.wifi.size(); ++i) {
    events.push_back({d.wifi[i].time_s, EventType::kWifi, i});
  }
  for (uint32_t i = 0; i < d.images.size(); ++i) {
    events.push_back({d.images[i].time_s, EventType::kImage, i});
  }
  for (uint32_t i = 0; i < d.odometry.size(); ++i) {
    events.push_back({d.odometry[i].time_s, EventType::kOdometry, i});
  }
  // At equal times: compass, pressure, Wi-Fi, images, odometry.
  auto rank = [](EventType type) {
    return type == EventType::kPressure ? 1 : 2 * static_cast<int>(type);
  };
  std::stable_sort(events.begin(), events.end(), [&rank](const Event& a, const Event& b) {
    if (a.time_s != b.time_s) return a.time_s < b.time_s;
    return rank(a.type) < rank(b.type);
  });
  return events;
}

namespace {

// The rows either side of `time_s`: {row, row} on a row (or at the first row), {a, b} between
// two rows, nullopt outside the span or (with session starts) between two sessions.
std::optional<std::pair<const GroundTruthRow*, const GroundTruthRow*>> Bracket(
    const std::vector<GroundTruthRow>& rows, const std::vector<double>& session_starts,
    double time_s) {
  if (rows.empty() || time_s < rows.front().time_s || time_s > rows.back().time_s) {
    return std::nullopt;
  }
  auto after = std::lower_bound(rows.begin(), rows.end(), time_s,
                                [](const GroundTruthRow& r, double t) { return r.time_s < t; });
  if (after->time_s == time_s || after == rows.begin()) return std::make_pair(&*after, &*after);
  const GroundTruthRow* a = &*(after - 1);
  const GroundTruthRow* b = &*after;
  const auto session = [&](double t) {
    return std::upper_bound(session_starts.begin(), session_starts.end(), t) -
           session_starts.begin();
  };
  if (session(a->time_s) != session(b->time_s)) return std::nullopt;
  return std::make_pair(a, b);
}

}  // namespace

std::optional<GroundTruthRow> InterpolateGroundTruth(const std::vector<GroundTruthRow>& rows,
                                                     double time_s,
                                                     const std::vector<double>& session_starts) {
  const auto ab = Bracket(rows, session_starts, time_s);
  if (!ab) return std::nullopt;
  const GroundTruthRow& a = *ab->first;
  const GroundTruthRow& b = *ab->second;
  if (&a == &b) return a;
  const double f = (time_s - a.time_s) / (b.time_s - a.time_s);
  GroundTruthRow r;
  r.time_s = time_s;
  r.x_m = a.x_m + f * (b.x_m - a.x_m);
  r.y_m = a.y_m + f * (b.y_m - a.y_m);
  r.theta_rad = WrapAngle(a.theta_rad + f * WrapAngle(b.theta_rad - a.theta_rad));
  r.floor = f < 0.5 ? a.floor : b.floor;
  return r;
}

std::optional<int> KnownFloor(const std::vector<GroundTruthRow>& rows, double time_s,
                              const std::vector<double>& session_starts) {
  const auto ab = Bracket(rows, session_starts, time_s);
  if (!ab || ab->first->floor != ab->second->floor) return std::nullopt;
  return ab->second->floor;
}

std::optional<GroundTruthRow> GroundTruthAt(const Dataset& dataset, double time_s) {
  return InterpolateGroundTruth(dataset.ground_truth, time_s, dataset.session_start_times_s);
}

std::optional<int> KnownFloorAt(const Dataset& dataset, double time_s) {
  return KnownFloor(dataset.ground_truth, time_s, dataset.session_start_times_s);
}

}  // namespace ratslam::dataset
