// Configuration files: TOML with one section per component (keys in docs/config.md). Unknown
// sections and keys, wrong types and out-of-range values are errors that name the file and line.
// Also an importer for OpenRatSLAM's INI configuration files.
#ifndef RATSLAM_IO_CONFIG_H_
#define RATSLAM_IO_CONFIG_H_

#include <string>
#include <vector>

#include "common/status.h"
#include "fusion/replay_pipeline.h"
#include "phone/locate_options.h"

namespace ratslam::io {

// Parses TOML text; `source_name` is used in error messages ("file:line: ...").
StatusOr<fusion::PipelineOptions> ParseConfig(const std::string& text,
                                              const std::string& source_name);
StatusOr<fusion::PipelineOptions> LoadConfigFile(const std::string& path);
// ParseConfig starting from `base` instead of the defaults: the keys in `text` override it (a
// sweep's parameters over its base configuration). The result is validated as a whole.
StatusOr<fusion::PipelineOptions> ParseConfigOnto(const std::string& text,
                                                  const std::string& source_name,
                                                  const fusion::PipelineOptions& base);

// The resolved configuration as TOML, every key present; with `comments`, each key is preceded
// by its documentation line. ParseConfig(PrintConfig(x)) == x.
std::string PrintConfig(const fusion::PipelineOptions& options, bool comments = true);
// Every section and key of the replay configuration and of `ratslam locate` with its default,
// unit, range and meaning, as markdown tables (docs/config.md): made from the same field lists
// that read and print configurations, so it cannot drift from them.
std::string ConfigReferenceMarkdown();

// The same for `ratslam wifi-map` and `ratslam locate` ([wifi_map], [particle_filter], [pdr]).
StatusOr<phone::LocateOptions> ParseLocateConfig(const std::string& text,
                                                 const std::string& source_name);
StatusOr<phone::LocateOptions> LoadLocateConfigFile(const std::string& path);
std::string PrintLocateConfig(const phone::LocateOptions& options, bool comments = true);

// A stable 64-bit fingerprint of the resolved configuration (FNV-1a of PrintConfig without
// comments), stored in map files so that a map is resumed only with the config that made it.
uint64_t ConfigFingerprint(const fusion::PipelineOptions& options);

// The keys whose values differ between two configurations, as "section.key: A -> B" (A from
// `before`, B from `now`), in file order; empty when they are the same.
std::vector<std::string> ConfigDifferences(const fusion::PipelineOptions& before,
                                           const fusion::PipelineOptions& now);

// The fingerprint a map of format `map_version` holds for `options`: the configuration printed
// without the keys added since that version. Fails, naming the key, when one of those keys is
// not at the value the old program behaved as (its default, or e.g. relaxation_scheme "full").
StatusOr<uint64_t> FingerprintAsOfMapVersion(const fusion::PipelineOptions& options,
                                             uint32_t map_version);

// Reads the configuration a map of format `map_version` carries: keys added after that version
// are absent from it and take the value the old program behaved as, not today's default.
StatusOr<fusion::PipelineOptions> ParseMapConfig(const std::string& text, uint32_t map_version);

struct ImportedConfig {
  fusion::PipelineOptions options;
  std::vector<std::string> notes;  // keys that were not mapped, with their lines
};
// Reads an OpenRatSLAM INI file (sections [general], [ratslam], [draw], ...), maps its RatSLAM
// keys onto our options (starting from our defaults) and reports every key it did not use.
StatusOr<ImportedConfig> ImportOpenRatslamIni(const std::string& path);

}  // namespace ratslam::io

#endif  // RATSLAM_IO_CONFIG_H_
