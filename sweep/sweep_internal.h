// What the sweep's source files share (sweep.cc, sweep_runner.cc, sweep_slurm.cc,
// sweep_collect.cc); not installed.
#ifndef RATSLAM_SWEEP_SWEEP_INTERNAL_H_
#define RATSLAM_SWEEP_SWEEP_INTERNAL_H_

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "common/status.h"
#include "sweep/sweep.h"

namespace ratslam::sweep {

// Where a run's metrics are: replay's summary or the benchmark's evaluation.
std::string MetricsFile(const SweepSpec& spec);
// DIR/runs/NNNNN, the folder of run `index`.
std::string RunFolder(const std::string& dir, int index);
// A CSV field, quoted when it holds a separator, a quote or a line break.
std::string CsvField(const std::string& s);
// The value at a dotted path of a JSON object ("match_rate_within_m.5"), if it is a number;
// true and false count as 1 and 0.
std::optional<double> Metric(const nlohmann::json& summary, const std::string& dotted);
// The objective (a metric or an expression of metrics) of one run's summary.
std::optional<double> ObjectiveOf(const nlohmann::json& summary, const std::string& objective);
// How run `index` ended, from its status.json; "pending" when it has none or a torn one.
StatusOr<TaskOutcome> ReadOutcome(const std::string& dir, int index);

}  // namespace ratslam::sweep

#endif  // RATSLAM_SWEEP_SWEEP_INTERNAL_H_
