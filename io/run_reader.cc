#include "io/run_reader.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/output_guard.h"
#include "common/text_file.h"
#include "dataset/csv.h"
#include "io/run_columns.h"

namespace ratslam::io {
namespace {
namespace fs = std::filesystem;

#define READ_NUMBER(lhs, table, row, column)               \
  do {                                                     \
    StatusOr<double> value_ = (table).Number(row, column); \
    if (!value_.ok()) return value_.status();              \
    lhs = value_.value();                                  \
  } while (false)

Status ReadId(const dataset::CsvTable& t, size_t row, const std::string& column, int64_t min,
              int64_t* out) {
  double v = 0;
  READ_NUMBER(v, t, row, column);
  if (v != std::floor(v) || v < static_cast<double>(min) || v > 4e9) {
    return t.ErrorAt(row, column, "not a valid id");
  }
  *out = static_cast<int64_t>(v);
  return Status::Ok();
}

}  // namespace

StatusOr<RunFolder> ReadRunFolder(const std::string& folder) {
  // A run killed while moving its outputs into place left them half moved: finish first, so
  // that what is read is one run's outputs.
  RATSLAM_RETURN_IF_ERROR(RecoverOutputFolder(folder));
  RunFolder run;
  StatusOr<dataset::CsvTable> ex =
      dataset::CsvTable::Read((fs::path(folder) / "experiences.csv").string(),
                              kExperienceColumns.required, kExperienceColumns.optional);
  if (!ex.ok()) return ex.status();
  for (size_t r = 0; r < ex->rows(); ++r) {
    Experience e;
    int64_t id = 0, template_id = 0;
    RATSLAM_RETURN_IF_ERROR(ReadId(*ex, r, "id", 0, &id));
    if (id != static_cast<int64_t>(r)) return ex->ErrorAt(r, "id", "ids must be 0, 1, 2, ...");
    RATSLAM_RETURN_IF_ERROR(ReadId(*ex, r, "template_id", 0, &template_id));
    e.id = static_cast<uint32_t>(id);
    e.template_id = static_cast<uint32_t>(template_id);
    READ_NUMBER(e.x_m, *ex, r, "x_m");
    READ_NUMBER(e.y_m, *ex, r, "y_m");
    READ_NUMBER(e.theta_rad, *ex, r, "theta_rad");
    READ_NUMBER(e.time_s, *ex, r, "time_s");
    run.experiences.push_back(e);
  }
  StatusOr<dataset::CsvTable> li = dataset::CsvTable::Read(
      (fs::path(folder) / "links.csv").string(), kLinkColumns.required, kLinkColumns.optional);
  if (!li.ok()) return li.status();
  const int64_t n = static_cast<int64_t>(run.experiences.size());
  for (size_t r = 0; r < li->rows(); ++r) {
    Link l;
    int64_t id = 0, from = 0, to = 0, loop = 0;
    RATSLAM_RETURN_IF_ERROR(ReadId(*li, r, "id", 0, &id));
    RATSLAM_RETURN_IF_ERROR(ReadId(*li, r, "from_id", 0, &from));
    RATSLAM_RETURN_IF_ERROR(ReadId(*li, r, "to_id", 0, &to));
    RATSLAM_RETURN_IF_ERROR(ReadId(*li, r, "loop_closure", 0, &loop));
    if (from >= n) return li->ErrorAt(r, "from_id", "no such experience");
    if (to >= n) return li->ErrorAt(r, "to_id", "no such experience");
    l.id = static_cast<uint32_t>(id);
    l.from = static_cast<uint32_t>(from);
    l.to = static_cast<uint32_t>(to);
    l.loop_closure = loop != 0;
    READ_NUMBER(l.distance_m, *li, r, "distance_m");
    READ_NUMBER(l.heading_rad, *li, r, "heading_rad");
    READ_NUMBER(l.facing_rad, *li, r, "facing_rad");
    READ_NUMBER(l.duration_s, *li, r, "duration_s");
    if (li->has_column("kind")) {
      StatusOr<std::string> kind = li->Text(r, "kind");
      if (!kind.ok()) return kind.status();
      l.wifi_sequence = *kind == "wifi_sequence";
      if (*kind != LinkKindName(l.loop_closure, l.wifi_sequence)) {
        return li->ErrorAt(r, "kind",
                           "'" + *kind +
                               "' does not fit loop_closure (odometry, loop_closure "
                               "or wifi_sequence)");
      }
    }
    run.links.push_back(l);
  }
  StatusOr<dataset::CsvTable> fr = dataset::CsvTable::Read(
      (fs::path(folder) / "frames.csv").string(), kFrameColumns.required, kFrameColumns.optional);
  if (!fr.ok()) return fr.status();
  for (size_t r = 0; r < fr->rows(); ++r) {
    FrameRecord f;
    int64_t template_id = 0, is_new = 0, experience = 0;
    READ_NUMBER(f.time_s, *fr, r, "time_s");
    RATSLAM_RETURN_IF_ERROR(ReadId(*fr, r, "template_id", 0, &template_id));
    RATSLAM_RETURN_IF_ERROR(ReadId(*fr, r, "new_template", 0, &is_new));
    RATSLAM_RETURN_IF_ERROR(ReadId(*fr, r, "experience_id", -1, &experience));
    f.template_id = static_cast<uint32_t>(template_id);
    f.is_new = is_new != 0;
    f.experience_id = experience;
    f.source = f.is_new ? DecisionSource::kNew : DecisionSource::kCamera;
    if (fr->has_column("source")) {
      StatusOr<std::string> source = fr->Text(r, "source");
      if (!source.ok()) return source.status();
      if (*source == "camera") {
        f.source = DecisionSource::kCamera;
      } else if (*source == "wifi") {
        f.source = DecisionSource::kWifi;
      } else if (*source == "new") {
        f.source = DecisionSource::kNew;
      } else {
        return fr->ErrorAt(r, "source", "must be camera, wifi or new, not '" + *source + "'");
      }
    }
    if (fr->has_column("recent")) {
      int64_t recent = 0;
      RATSLAM_RETURN_IF_ERROR(ReadId(*fr, r, "recent", 0, &recent));
      f.recent = recent != 0;
    }
    run.frames.push_back(f);
  }
  std::ifstream summary(fs::path(folder) / "summary.json");
  if (summary) {
    const nlohmann::json j = nlohmann::json::parse(summary, nullptr, /*allow_exceptions=*/false);
    if (j.is_object() && j.contains("data_folder") && j["data_folder"].is_string()) {
      run.dataset_folder = j["data_folder"].get<std::string>();
    }
    if (j.is_object() && j.contains("run") && j["run"].is_object() && j["run"].contains("inputs") &&
        j["run"]["inputs"].is_array()) {
      for (const nlohmann::json& input : j["run"]["inputs"]) {
        if (input.is_object() && input.contains("path") && input["path"].is_string()) {
          run.inputs.push_back(input["path"].get<std::string>());
        }
      }
    }
    if (j.is_object() && j.contains("current_experience") &&
        j["current_experience"].is_number_unsigned() &&
        j["current_experience"].get<uint64_t>() < run.experiences.size()) {
      run.current_experience = j["current_experience"].get<uint32_t>();
    }
    if (j.is_object() && j.contains("dataset") && j["dataset"].is_string()) {
      run.dataset_name = j["dataset"].get<std::string>();
    }
  }
  return run;
}

StatusOr<std::vector<GroundTruthRow>> ReadTumTrajectory(const std::string& path) {
  std::ifstream in;
  RATSLAM_RETURN_IF_ERROR(OpenRegularFile(path, "TUM trajectory", &in));
  static const char* const kFields[] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  std::vector<GroundTruthRow> rows;
  std::string line;
  for (size_t number = 1;; ++number) {
    const LineResult got = ReadLine(in, &line);
    if (got == LineResult::kEnd) break;
    const std::string where = path + ":" + std::to_string(number);
    if (got == LineResult::kTooLong) return Status::Error(where + ": line too long");
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    double v[8];
    for (int k = 0; k < 8; ++k) {
      std::string text;
      if (!(fields >> text)) return Status::Error(where + ": field '" + kFields[k] + "' missing");
      char* end = nullptr;
      v[k] = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0' || !std::isfinite(v[k])) {
        return Status::Error(where + ": field '" + kFields[k] + "' is not a finite number: '" +
                             text + "'");
      }
    }
    std::string extra;
    if (fields >> extra) return Status::Error(where + ": more than 8 fields");
    if (!rows.empty() && !(v[0] > rows.back().time_s)) {
      return Status::Error(where + ": field 'timestamp' is not after the previous line's");
    }
    GroundTruthRow r;
    r.time_s = v[0];
    r.x_m = v[1];
    r.y_m = v[2];
    const double qx = v[4], qy = v[5], qz = v[6], qw = v[7];
    r.theta_rad = std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz));
    rows.push_back(r);
  }
  if (rows.empty()) return Status::Error(path + ": no pose (a TUM trajectory needs at least one)");
  return rows;
}

}  // namespace ratslam::io
