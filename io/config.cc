#include "io/config.h"

#include <toml++/toml.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "common/file_util.h"
#include "common/text_file.h"
#include "common/toml_binder.h"
#include "dataset/dataset_loader.h"

namespace ratslam::io {
namespace {

constexpr size_t kMaxConfigBytes = 1 << 20;  // a config is a few kB; a megabyte is not a config

using schema::TomlWhere;

}  // namespace
}  // namespace ratslam::io

// The enums of the configuration, read and printed by their names.
namespace ratslam::schema {
template <>
struct TomlCodec<fabmap::FabmapMode> : EnumCodec<fabmap::FabmapMode, fabmap::FabmapModeFromString> {
};
template <>
struct TomlCodec<fabmap::UnknownWorld>
    : EnumCodec<fabmap::UnknownWorld, fabmap::UnknownWorldFromString> {};
template <>
struct TomlCodec<fabmap::DescriptorKind>
    : EnumCodec<fabmap::DescriptorKind, fabmap::DescriptorKindFromString> {};
template <>
struct TomlCodec<fabmap::WifiEncoding>
    : EnumCodec<fabmap::WifiEncoding, fabmap::WifiEncodingFromString> {};
template <>
struct TomlCodec<fabmap::SplitUnit> : EnumCodec<fabmap::SplitUnit, fabmap::SplitUnitFromString> {};
template <>
struct TomlCodec<fabmap::AnswerRule> : EnumCodec<fabmap::AnswerRule, fabmap::AnswerRuleFromString> {
};
template <>
struct TomlCodec<fabmap::NewPlaceRule>
    : EnumCodec<fabmap::NewPlaceRule, fabmap::NewPlaceRuleFromString> {};
template <>
struct TomlCodec<fusion::WifiLearning>
    : EnumCodec<fusion::WifiLearning, fusion::WifiLearningFromString> {};
template <>
struct TomlCodec<RelaxationScheme> : EnumCodec<RelaxationScheme, RelaxationSchemeFromString> {};
template <>
struct TomlCodec<ViewMemory> : EnumCodec<ViewMemory, ViewMemoryFromString> {};
template <>
struct TomlCodec<fusion::FrontEndKind>
    : EnumCodec<fusion::FrontEndKind, fusion::FrontEndKindFromString> {};
template <>
struct TomlCodec<phone::ScanLikelihood>
    : EnumCodec<phone::ScanLikelihood, phone::ScanLikelihoodFromString> {};
}  // namespace ratslam::schema

namespace ratslam::io {
namespace {

// Line of `section.key` in the parsed file, for validity errors found after reading.
std::string LocateField(const toml::table& root, const std::string& source,
                        const std::string& dotted) {
  const auto dot = dotted.find('.');
  const auto colon = dotted.find(':');
  if (dot == std::string::npos || colon == std::string::npos) return source;
  const std::string section = dotted.substr(0, dot);
  const std::string key = dotted.substr(dot + 1, colon - dot - 1);
  const toml::table* table = root[section].as_table();
  if (!table) return source;
  const toml::node* node = table->get(key);
  return TomlWhere(source, node ? node : table);
}

}  // namespace

StatusOr<fusion::PipelineOptions> ParseConfig(const std::string& text,
                                              const std::string& source_name) {
  return ParseConfigOnto(text, source_name, fusion::PipelineOptions());
}

namespace {

// Reads the sections `Options::VisitSections` lists onto `base`: unknown sections and keys, wrong
// types and invalid values are errors naming the file and line.
template <typename Options>
StatusOr<Options> ParseSectionsOnto(const std::string& text, const std::string& source_name,
                                    const Options& base) {
  StatusOr<toml::table> parsed = schema::ParseToml(text, source_name);
  if (!parsed.ok()) return parsed.status();
  const toml::table& root = *parsed;
  Options options = base;
  std::set<std::string> sections;
  Status status;
  options.VisitSections([&](const char* name, auto& section) {
    sections.insert(name);
    if (!status.ok()) return;
    const toml::node* node = root.get(name);
    if (!node) return;
    const toml::table* table = node->as_table();
    if (!table) {
      status = Status::Error(TomlWhere(source_name, node) + ": [" + name + "] must be a table");
      return;
    }
    schema::TableBinder binder(*table, "[" + std::string(name) + "]", std::string(name) + ".",
                               source_name);
    section.VisitFields(binder);
    status = binder.Finish();
  });
  if (!status.ok()) return status;
  for (const auto& [key, node] : root) {
    const std::string name(key.str());
    if (!sections.count(name)) {
      return Status::Error(TomlWhere(source_name, &node) + ": unknown section '" + name + "'" +
                           schema::DidYouMean(name, sections));
    }
  }
  std::string error;
  if (!options.IsValid(&error)) {
    return Status::Error(LocateField(root, source_name, error) + ": " + error);
  }
  return options;
}

}  // namespace

StatusOr<fusion::PipelineOptions> ParseConfigOnto(const std::string& text,
                                                  const std::string& source_name,
                                                  const fusion::PipelineOptions& base) {
  return ParseSectionsOnto(text, source_name, base);
}

StatusOr<phone::LocateOptions> ParseLocateConfig(const std::string& text,
                                                 const std::string& source_name) {
  return ParseSectionsOnto(text, source_name, phone::LocateOptions());
}

StatusOr<phone::LocateOptions> LoadLocateConfigFile(const std::string& path) {
  StatusOr<std::string> text = ReadRegularFile(path, "config file", kMaxConfigBytes);
  if (!text.ok()) return text.status();
  return ParseLocateConfig(*text, path);
}

namespace {
// Whether a configuration that failed to parse is an OpenRatSLAM INI file: its [ratslam]
// section, or `key=value` lines with keys only OpenRatSLAM uses. Returns the evidence.
std::optional<std::string> OpenRatslamEvidence(const std::string& text) {
  static const char* const kKeys[] = {"topic_root",
                                      "pc_dim_xy",
                                      "pc_dim_th",
                                      "vt_match_threshold",
                                      "exp_delta_pc_threshold",
                                      "image_crop_x_min",
                                      "vtrans_image_x_min",
                                      "media_path"};
  std::istringstream in(text);
  std::string line;
  for (size_t number = 1; std::getline(in, line); ++number) {
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos) continue;
    const std::string trimmed = line.substr(first);
    if (trimmed.rfind("[ratslam]", 0) == 0 || trimmed.rfind("[general]", 0) == 0) {
      return "line " + std::to_string(number) + ": section " + trimmed.substr(0, 9);
    }
    for (const char* key : kKeys) {
      const std::string k = key;
      if (trimmed.rfind(k, 0) == 0 && trimmed.find('=') != std::string::npos &&
          trimmed.find_first_not_of(" \t", k.size()) == trimmed.find('=')) {
        return "line " + std::to_string(number) + ": key " + k;
      }
    }
  }
  return std::nullopt;
}
}  // namespace

StatusOr<fusion::PipelineOptions> LoadConfigFile(const std::string& path) {
  // A data set given where the configuration belongs (`--config LOG.txt --data x.toml`) is
  // named as such, instead of "larger than 1048576 bytes" or a TOML syntax error.
  // Asked only once reading or parsing failed: a good configuration is never sniffed.
  auto is_data_set = [&] { return IsRegularFile(path) && dataset::DetectDatasetFormat(path).ok(); };
  const auto data_set = [&] {
    return Status::Error(path +
                         " is a data set, not a configuration: give it as --data, and the "
                         "configuration (.toml) as --config");
  };
  StatusOr<std::string> text = ReadRegularFile(path, "config file", kMaxConfigBytes);
  if (!text.ok()) return is_data_set() ? data_set() : text.status();
  StatusOr<fusion::PipelineOptions> parsed = ParseConfig(*text, path);
  if (parsed.ok()) {
    // Paths inside a configuration are relative to its file (as a sweep file's are), not to the
    // folder the program runs in: the resolved configuration holds them absolute.
    const std::filesystem::path folder =
        std::filesystem::absolute(std::filesystem::path(path)).parent_path();
    for (std::string* p :
         {&parsed->sensors.fabmap.visual_model.file,
          &parsed->sensors.fabmap.visual_model.training_images, &parsed->video.odometry_log}) {
      if (!p->empty() && std::filesystem::path(*p).is_relative()) {
        *p = (folder / *p).lexically_normal().string();
      }
    }
  } else {
    if (is_data_set()) return data_set();
    if (const auto evidence = OpenRatslamEvidence(*text)) {
      return Status::Error(path + " is an OpenRatSLAM configuration (" + *evidence +
                           "), not ours: convert it with `ratslam import-openratslam " + path +
                           " > config.toml` and pass that (" + parsed.status().message() + ")");
    }
  }
  return parsed;
}

namespace {
template <typename Options>
std::string PrintSections(const Options& options, bool comments) {
  Options copy = options;
  std::ostringstream out;
  bool first = true;
  copy.VisitSections([&](const char* name, auto& section) {
    if (!first) out << "\n";
    first = false;
    out << "[" << name << "]\n";
    schema::TablePrinter printer(out, comments);
    section.VisitFields(printer);
  });
  return out.str();
}
}  // namespace

std::string PrintConfig(const fusion::PipelineOptions& options, bool comments) {
  return PrintSections(options, comments);
}

std::string PrintLocateConfig(const phone::LocateOptions& options, bool comments) {
  return PrintSections(options, comments);
}

namespace {

// A printed configuration with comments as markdown: a heading and a table per section.
std::string MarkdownTables(const std::string& printed) {
  std::ostringstream out;
  std::istringstream in(printed);
  std::string line, comment;
  auto cell = [](std::string text) {
    std::string escaped;
    for (char c : text) escaped += c == '|' ? std::string("\\|") : std::string(1, c);
    return escaped;
  };
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (line.front() == '[') {
      out << "\n### " << line << "\n\n| key | default | meaning (unit; range) |\n|---|---|---|\n";
      comment.clear();
      continue;
    }
    if (line.rfind("# ", 0) == 0) {
      comment += (comment.empty() ? "" : " ") + line.substr(2);
      continue;
    }
    const size_t eq = line.find(" = ");
    if (eq == std::string::npos) continue;
    out << "| `" << line.substr(0, eq) << "` | `" << cell(line.substr(eq + 3)) << "` | "
        << cell(comment) << " |\n";
    comment.clear();
  }
  return out.str();
}

}  // namespace

std::string ConfigReferenceMarkdown() {
  return "\n## Replay, evaluation and sweeps (`--config`)\n" +
         MarkdownTables(PrintConfig(fusion::PipelineOptions(), true)) +
         "\n## `ratslam locate` (`--config`)\n" +
         MarkdownTables(PrintLocateConfig(phone::LocateOptions(), true));
}

namespace {

uint64_t Fnv1a(const std::string& text) {
  uint64_t hash = 0xcbf29ce484222325ULL;
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

// Each line of a printed config (no comments) as ("section.key", "value"); headers skipped.
std::vector<std::pair<std::string, std::string>> KeyedLines(const std::string& printed) {
  std::vector<std::pair<std::string, std::string>> out;
  std::istringstream in(printed);
  std::string line, section;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (line.front() == '[') {
      section = line.substr(1, line.size() - 2);
      continue;
    }
    const size_t eq = line.find(" = ");
    if (eq == std::string::npos) continue;
    out.emplace_back(section + "." + line.substr(0, eq), line.substr(eq + 3));
  }
  return out;
}

// Keys added to the configuration after each map format version (the map fingerprint of that
// version was taken without them), with the value (as printed) the older program behaved as when
// that is not the new default.
struct AddedKey {
  uint32_t after_version;
  const char* key;
  const char* value_then = nullptr;
};
constexpr AddedKey kKeysAddedAfter[] = {
    {2, "fabmap_front_end.wifi_learning"},
    {2, "fabmap_front_end.online_first_scans"},
    {3, "experience_map.relaxation_scheme", "\"full\""},
    {3, "experience_map.relaxation_tolerance_m"},
    {3, "experience_map.relaxation_tolerance_rad"},
    {4, "pdr.orientation_window_s"},
    {4, "pdr.min_orientation_steadiness", "0.0"},
    {4, "local_view.memory"},
    {4, "local_view.decay_restore_per_s"},
    {4, "local_view.skip_recent_s"},
    {4, "wifi.offset_invariant"},
    {6, "experience_map.link_sigma_m"},
    {6, "experience_map.link_sigma_m_per_m"},
    {6, "experience_map.link_sigma_rad"},
    {7, "experience_map.initial_heading_rad"},
    {7, "experience_map.relaxation_max_region_links"},
    {7, "visual_odometry.model"},
    {7, "visual_odometry.translation_left_px"},
    {7, "visual_odometry.translation_right_px"},
    {7, "visual_odometry.translation_top_px"},
    {7, "visual_odometry.translation_bottom_px"},
    {7, "visual_odometry.rotation_left_px"},
    {7, "visual_odometry.rotation_right_px"},
    {7, "visual_odometry.rotation_top_px"},
    {7, "visual_odometry.rotation_bottom_px"},
    {7, "visual_odometry.camera_hz"},
    {7, "visual_odometry.translation_scaling"},
    {7, "visual_odometry.max_speed_m_per_s"},
    {7, "fused.online_rssi_offset"},
    {7, "fused.rssi_offset_min_common_aps"},
    {7, "fused.rssi_offset_min_estimates"},
    {7, "wifi.unmapped_aps_neutral"},
    {7, "fused.revisit_update_weight"},
    {7, "evaluation.near_place_m"},
    {7, "evaluation.far_place_m"},
    {7, "evaluation.calibrate_new_place"},
    {7, "evaluation.calibration_folds"},
    {7, "evaluation.new_place_rule"},
    {7, "evaluation.new_place_near_recall"},
    {7, "evaluation.online_rssi_offset"},
    {7, "evaluation.rssi_offset_min_common_aps"},
    {7, "evaluation.rssi_offset_min_estimates"},
    {7, "fabmap_front_end.decide_by_log_odds"},
    {7, "fabmap_front_end.match_log_odds"},
    {7, "fabmap_front_end.online_rssi_offset"},
    {7, "fabmap_front_end.rssi_offset_min_common_aps"},
    {7, "fabmap_front_end.rssi_offset_min_estimates"},
    {9, "evaluation.answer"},
    {9, "evaluation.answer_places"},
    {9, "evaluation.answer_temperature"},
    {9, "sequence.centred"},
    {9, "fused.rssi_offset_walking_only"},
    {9, "fabmap_front_end.earlier_sessions_apart"},
    {9, "fabmap_front_end.earlier_session_log_odds"},
    {9, "fabmap_front_end.learn_earlier_session_log_odds"},
    {9, "fabmap_front_end.learn_near_recall"},
    {9, "fabmap_front_end.learn_min_revisits"},
    {9, "fabmap_front_end.calibrate_earlier_session_log_odds"},
};

// Whole sections added after a map format version: older maps resume only with every key at its
// default, and their fingerprints were taken without the section.
struct AddedSection {
  uint32_t after_version;
  const char* name;
};
constexpr AddedSection kSectionsAddedAfter[] = {
    {5, "wifi_sequence"}, {7, "bag"},       {7, "video"},
    {7, "descriptors"},   {7, "barometer"}, {8, "sequence"},
};

}  // namespace

uint64_t ConfigFingerprint(const fusion::PipelineOptions& options) {
  return Fnv1a(PrintConfig(options, false));
}

std::vector<std::string> ConfigDifferences(const fusion::PipelineOptions& before,
                                           const fusion::PipelineOptions& now) {
  const auto a = KeyedLines(PrintConfig(before, false));
  const auto b = KeyedLines(PrintConfig(now, false));
  std::vector<std::string> out;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
    if (a[i].second != b[i].second) {
      out.push_back(a[i].first + ": " + a[i].second + " -> " + b[i].second);
    }
  }
  return out;
}

StatusOr<uint64_t> FingerprintAsOfMapVersion(const fusion::PipelineOptions& options,
                                             uint32_t map_version) {
  const std::string printed = PrintConfig(options, false);
  const auto defaults = KeyedLines(PrintConfig(fusion::PipelineOptions(), false));
  const auto lines = KeyedLines(printed);
  std::set<std::string> dropped;
  for (const AddedKey& added : kKeysAddedAfter) {
    if (map_version > added.after_version) continue;
    for (size_t i = 0; i < lines.size(); ++i) {
      if (lines[i].first != added.key) continue;
      const std::string then = added.value_then ? added.value_then : defaults[i].second;
      if (lines[i].second != then) {
        return Status::Error(std::string(added.key) + " is " + lines[i].second +
                             ", but maps of format " + std::to_string(map_version) +
                             " were made with " + then);
      }
    }
    dropped.insert(added.key);
  }
  std::set<std::string> dropped_sections;
  for (const AddedSection& added : kSectionsAddedAfter) {
    if (map_version > added.after_version) continue;
    const std::string prefix = std::string(added.name) + ".";
    for (size_t i = 0; i < lines.size(); ++i) {
      if (lines[i].first.compare(0, prefix.size(), prefix) != 0) continue;
      if (lines[i].second != defaults[i].second) {
        return Status::Error(lines[i].first + " is " + lines[i].second + ", but maps of format " +
                             std::to_string(map_version) + " were made without [" + added.name +
                             "]");
      }
    }
    dropped_sections.insert(added.name);
  }
  // Print again, leaving out the dropped keys' lines and sections (a section's lines run to the
  // blank line before the next header), keeping the layout otherwise.
  std::istringstream in(printed);
  std::string line, section, kept;
  while (std::getline(in, line)) {
    if (!line.empty() && line.front() == '[') section = line.substr(1, line.size() - 2);
    if (dropped_sections.count(section)) continue;
    const size_t eq = line.find(" = ");
    if (eq != std::string::npos && dropped.count(section + "." + line.substr(0, eq))) continue;
    kept += line + "\n";
  }
  // A dropped last section leaves the blank line that separated it from the one before.
  while (kept.size() >= 2 && kept.compare(kept.size() - 2, 2, "\n\n") == 0) kept.pop_back();
  return Fnv1a(kept);
}

StatusOr<fusion::PipelineOptions> ParseMapConfig(const std::string& text, uint32_t map_version) {
  std::string then;
  for (const AddedKey& added : kKeysAddedAfter) {
    if (map_version > added.after_version || !added.value_then) continue;
    const std::string_view key = added.key;
    const size_t dot = key.find('.');
    then.append("[").append(key.substr(0, dot)).append("]\n");
    then.append(key.substr(dot + 1)).append(" = ").append(added.value_then).append("\n");
  }
  StatusOr<fusion::PipelineOptions> base = ParseConfigOnto(
      then, "format " + std::to_string(map_version) + " defaults", fusion::PipelineOptions());
  if (!base.ok()) return base.status();
  return ParseConfigOnto(text, "the map's configuration", *base);
}

namespace {
// Keys OpenRatSLAM reads (or its shipped files carry) that have no equivalent here: the viewer's
// windows (../shared/reference/openratslam-facts.md, section 2, [draw]).
constexpr const char* kOpenRatslamKeysWithoutEquivalent[] = {
    "enable",     "vt_window_width", "vt_window_height", "media_path",
    "image_file", "exp_map_size",    "posecells_size"};

using IniSetter = std::function<Status(double)>;

// OpenRatSLAM key -> our field, the field's name in our validation messages, and
// OpenRatSLAM's own default, which an INI that leaves the key out gets (ratslam_ros branch;
// ../shared/reference/openratslam-facts.md, section 2). vt_shift_match 25 in steps of 5 is
// what New College, which sets neither, searches.
struct IniKey {
  const char* name;
  IniSetter set;
  const char* field;  // as PipelineOptions::IsValid names it
  double openratslam_default;
};

// The keys, each setting its field of `o` (which must outlive the setters).
std::vector<IniKey> OpenRatslamKeys(fusion::PipelineOptions& o) {
  auto whole = [](int& field) {
    return [&field](double v) {
      if (v != std::floor(v) || !(std::abs(v) <= std::numeric_limits<int>::max())) {
        return Status::Error("expected a whole number within the range of int");
      }
      field = static_cast<int>(v);
      return Status::Ok();
    };
  };
  auto real = [](double& field) {
    return [&field](double v) {
      field = v;
      return Status::Ok();
    };
  };
  // OpenRatSLAM uses pc_w_e_var and pc_w_i_var as the Gaussian's sigma (exp(-r^2 / (2 v^2))):
  // ours is the variance.
  auto sigma = [](double& variance) {
    return [&variance](double v) {
      variance = v * v;
      return Status::Ok();
    };
  };
  return {
      {"pc_dim_xy", whole(o.ratslam.pose_cells.dim_xy_cells), "pose_cells.dim_xy_cells", 21},
      {"pc_dim_th", whole(o.ratslam.pose_cells.dim_theta_cells), "pose_cells.dim_theta_cells", 36},
      {"pc_cell_x_size", real(o.ratslam.pose_cells.cell_size_m), "pose_cells.cell_size_m", 1.0},
      {"pc_w_e_dim", whole(o.ratslam.pose_cells.excitation_size_cells),
       "pose_cells.excitation_size_cells", 7},
      {"pc_w_i_dim", whole(o.ratslam.pose_cells.inhibition_size_cells),
       "pose_cells.inhibition_size_cells", 5},
      {"pc_w_e_var", sigma(o.ratslam.pose_cells.excitation_variance_cells2),
       "pose_cells.excitation_variance_cells2", 1},
      {"pc_w_i_var", sigma(o.ratslam.pose_cells.inhibition_variance_cells2),
       "pose_cells.inhibition_variance_cells2", 2},
      {"pc_global_inhib", real(o.ratslam.pose_cells.global_inhibition),
       "pose_cells.global_inhibition", 0.00002},
      {"pc_vt_inject_energy", real(o.ratslam.local_view.injection_gain),
       "local_view.injection_gain", 0.15},
      {"pc_vt_restore", real(o.ratslam.local_view.decay_restore_per_frame),
       "local_view.decay_restore_per_frame", 0.05},
      {"vt_active_decay",
       [&o](double v) {
         o.ratslam.local_view.decay_per_match = v;
         o.ratslam.local_view.decay_floor = v;
         return Status::Ok();
       },
       "local_view.decay_", 1.0},
      {"exp_delta_pc_threshold", real(o.ratslam.action.match_distance_cells),
       "action.match_distance_cells", 2.0},
      {"exp_loops", whole(o.ratslam.experience_map.relaxation_sweeps),
       "experience_map.relaxation_sweeps", 10},
      {"exp_correction", real(o.ratslam.experience_map.relaxation_correction),
       "experience_map.relaxation_correction", 0.5},
      {"exp_initial_em_deg",
       [&o](double v) {
         o.ratslam.experience_map.initial_heading_rad = v * M_PI / 180.0;
         return Status::Ok();
       },
       "experience_map.initial_heading_rad", 90.0},
      {"vt_match_threshold", real(o.sensors.classic_camera.match_threshold),
       "camera.match_threshold", 0.03},
      {"vt_shift_match", whole(o.sensors.classic_camera.shift_px), "camera.shift_px", 25},
      {"vt_step_match", whole(o.sensors.classic_camera.shift_step_px), "camera.shift_step_px", 5},
      {"vt_normalisation", real(o.sensors.classic_camera.global_normalisation_mean),
       "camera.global_normalisation_mean", 0},
      {"vt_patch_normalise", whole(o.sensors.classic_camera.patch_normalisation_radius_px),
       "camera.patch_normalisation_radius_px", 0},
      {"template_x_size", whole(o.sensors.classic_camera.template_width_px),
       "camera.template_width_px", 1},
      {"template_y_size", whole(o.sensors.classic_camera.template_height_px),
       "camera.template_height_px", 1},
      {"image_crop_x_min", whole(o.sensors.classic_camera.crop_left_px), "camera.crop_left_px", 0},
      {"image_crop_x_max", whole(o.sensors.classic_camera.crop_right_px), "camera.crop_right_px",
       -1},
      {"image_crop_y_min", whole(o.sensors.classic_camera.crop_top_px), "camera.crop_top_px", 0},
      {"image_crop_y_max", whole(o.sensors.classic_camera.crop_bottom_px), "camera.crop_bottom_px",
       -1},
      // [visual_odometry] (facts file, sections 2 and 4.2); the section turns the model on.
      {"vtrans_image_x_min", whole(o.visual_odometry.translation_left_px),
       "visual_odometry.translation_left_px", 0},
      {"vtrans_image_x_max", whole(o.visual_odometry.translation_right_px),
       "visual_odometry.translation_right_px", -1},
      {"vtrans_image_y_min", whole(o.visual_odometry.translation_top_px),
       "visual_odometry.translation_top_px", 0},
      {"vtrans_image_y_max", whole(o.visual_odometry.translation_bottom_px),
       "visual_odometry.translation_bottom_px", -1},
      {"vrot_image_x_min", whole(o.visual_odometry.rotation_left_px),
       "visual_odometry.rotation_left_px", 0},
      {"vrot_image_x_max", whole(o.visual_odometry.rotation_right_px),
       "visual_odometry.rotation_right_px", -1},
      {"vrot_image_y_min", whole(o.visual_odometry.rotation_top_px),
       "visual_odometry.rotation_top_px", 0},
      {"vrot_image_y_max", whole(o.visual_odometry.rotation_bottom_px),
       "visual_odometry.rotation_bottom_px", -1},
      {"camera_fov_deg",
       [&o](double v) {
         o.visual_odometry.field_of_view_rad = v * M_PI / 180.0;
         return Status::Ok();
       },
       "visual_odometry.field_of_view_rad", 50.0},
      {"camera_hz", real(o.visual_odometry.camera_hz), "visual_odometry.camera_hz", 10.0},
      {"vtrans_scaling", real(o.visual_odometry.translation_scaling),
       "visual_odometry.translation_scaling", 100.0},
      {"vtrans_max", real(o.visual_odometry.max_speed_m_per_s), "visual_odometry.max_speed_m_per_s",
       20.0},
      {"vt_panoramic",
       [&o](double v) {
         o.sensors.classic_camera.panoramic = v != 0.0;
         return Status::Ok();
       },
       "camera.panoramic", 0},
  };
}

// For a validation error of imported values: the INI lines that set the values the message is
// about, or that OpenRatSLAM's default was used for them ("; path:line: key = value, ...").
std::string IniLinesAbout(const std::string& error, const std::vector<IniKey>& keys,
                          const std::map<std::string, std::string>& set_at) {
  std::string about;
  for (const IniKey& k : keys) {
    const std::string field = k.field;
    const std::string short_field = field.substr(field.find('.') + 1);
    const bool named =
        error.rfind(field, 0) == 0 || error.find(" " + short_field) != std::string::npos;
    if (!named) continue;
    about += about.empty() ? "; " : ", ";
    if (auto at = set_at.find(k.name); at != set_at.end()) {
      about += at->second;
    } else {
      about += std::string(k.name) + " not set (OpenRatSLAM's default " +
               ShortestNumber(k.openratslam_default) + ")";
    }
  }
  return about;
}

// `s` without leading and trailing spaces and tabs.
std::string TrimBlanks(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  const auto e = s.find_last_not_of(" \t");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

}  // namespace

StatusOr<ImportedConfig> ImportOpenRatslamIni(const std::string& path) {
  StatusOr<std::string> text = ReadRegularFile(path, "INI file", kMaxConfigBytes);
  if (!text.ok()) return text.status();
  std::istringstream in(*text);
  ImportedConfig imported;
  fusion::PipelineOptions& o = imported.options;
  // OpenRatSLAM relaxes every link exp_loops times after each action.
  o.ratslam.experience_map.relaxation_scheme = RelaxationScheme::kFull;
  const std::vector<IniKey> keys = OpenRatslamKeys(o);
  std::map<std::string, IniSetter> setters;
  for (const IniKey& k : keys) {
    setters[k.name] = k.set;
    (void)k.set(k.openratslam_default);  // every default is valid for its setter
  }
  // An older spelling of vt_patch_normalise.
  setters["vt_patch_normalisation"] = setters.at("vt_patch_normalise");
  std::map<std::string, std::string> set_at;  // INI key -> "path:line: key = value"
  std::string line, section;
  std::optional<std::string> topic_root;
  std::string topic_root_at;
  size_t topic_root_note = 0;
  bool visual_odometry_section = false;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string where = path + ":" + std::to_string(number);
    const auto comment = line.find_first_of("#;");
    if (comment != std::string::npos) line.erase(comment);
    const auto begin = line.find_first_not_of(" \t\r");
    if (begin == std::string::npos) continue;
    line = line.substr(begin, line.find_last_not_of(" \t\r") - begin + 1);
    if (line.front() == '[') {
      if (line.back() != ']') return Status::Error(where + ": malformed section header");
      section = line.substr(1, line.size() - 2);
      if (section == "visual_odometry") visual_odometry_section = true;
      continue;
    }
    const auto eq = line.find('=');
    if (eq == std::string::npos) return Status::Error(where + ": expected key=value");
    const std::string key = TrimBlanks(line.substr(0, eq));
    const std::string value = TrimBlanks(line.substr(eq + 1));
    if (key == "topic_root") {
      topic_root = value;
      topic_root_at = where + ": [" + section + "] " + key + " = " + value;
      topic_root_note = imported.notes.size();  // in line order among the notes
      continue;
    }
    auto it = setters.find(key);
    if (it == setters.end()) {
      // OpenRatSLAM ignores a misspelt key and keeps its default: a key near one it reads is a
      // typo, and an error here (its value would otherwise be lost without a word).
      std::set<std::string> known = {std::begin(kOpenRatslamKeysWithoutEquivalent),
                                     std::end(kOpenRatslamKeysWithoutEquivalent)};
      for (const auto& [name, setter] : setters) known.insert(name);
      if (!known.count(key)) {
        const std::string suggestion = schema::DidYouMean(key, known);
        if (!suggestion.empty()) {
          return Status::Error(where + ": [" + section + "] unknown key '" + key + "'" +
                               suggestion);
        }
      }
      imported.notes.push_back(where + ": [" + section + "] " + key + " = " + value +
                               " (not used: no equivalent)");
      continue;
    }
    double number_value = 0.0;
    const auto parsed = std::from_chars(value.data(), value.data() + value.size(), number_value);
    if (value.empty() || parsed.ec != std::errc() || parsed.ptr != value.data() + value.size() ||
        !std::isfinite(number_value)) {
      return Status::Error(where + ": " + key + ": not a number: '" + value + "'");
    }
    Status s = it->second(number_value);
    if (!s.ok()) return Status::Error(where + ": " + key + ": " + s.message());
    set_at[key] = where + ": " + key + " = " + value;
  }
  if (visual_odometry_section) {
    // OpenRatSLAM's visual odometry node: its model, and its fixed search of 0..39 px.
    o.visual_odometry.enabled = true;
    o.visual_odometry.model = "openratslam";
    o.visual_odometry.max_shift_px = 39;
  }
  if (topic_root) {
    // Topics are topic_root plus fixed suffixes; odometry comes from the bag unless the file
    // configures OpenRatSLAM's visual odometry node (facts file, section 5). ROS resolves a
    // relative name under "/" and collapses "//".
    o.bag.image_topic = dataset::NormaliseRosTopic(*topic_root + "/camera/image");
    o.bag.odometry_topic =
        visual_odometry_section ? "" : dataset::NormaliseRosTopic(*topic_root + "/odom");
    imported.notes.insert(
        imported.notes.begin() + static_cast<std::ptrdiff_t>(topic_root_note),
        topic_root_at + " (-> [bag] image_topic = \"" + o.bag.image_topic + "\"" +
            (visual_odometry_section ? ", no odometry topic: the file runs visual odometry)"
                                     : ", odometry_topic = \"" + o.bag.odometry_topic + "\")"));
  }
  std::string error;
  if (!o.IsValid(&error)) {
    std::string about = IniLinesAbout(error, keys, set_at);
    if (error.rfind("bag.", 0) == 0) about += "; " + topic_root_at;
    return Status::Error(path + ": imported values are invalid: " + error + about);
  }
  return imported;
}

}  // namespace ratslam::io
