// The columns of a run folder's CSV files, written by run_outputs.cc and read back by
// run_reader.cc: one list, so the two cannot drift apart. Optional columns were added after the
// first release; readers accept run folders without them.
#ifndef RATSLAM_IO_RUN_COLUMNS_H_
#define RATSLAM_IO_RUN_COLUMNS_H_

#include <string>
#include <vector>

namespace ratslam::io {

struct RunCsvColumns {
  std::vector<std::string> required;
  std::vector<std::string> optional;
  // The header line the writer prints: required then optional columns, comma-separated.
  std::string Header() const {
    std::string line;
    for (const auto* list : {&required, &optional}) {
      for (const std::string& c : *list) line += (line.empty() ? "" : ",") + c;
    }
    return line + "\n";
  }
};

// experiences.csv's `floor`: the floor of the experience's template relative to the first
// session's first level ([barometer] use_barometer), empty when unknown (no barometer, the stairs).
inline const RunCsvColumns kExperienceColumns = {
    {"id", "x_m", "y_m", "theta_rad", "template_id", "time_s"},
    {"pose_cell_x", "pose_cell_y", "pose_cell_theta", "floor"}};
inline const RunCsvColumns kLinkColumns = {{"id", "from_id", "to_id", "distance_m", "heading_rad",
                                            "facing_rad", "duration_s", "loop_closure"},
                                           {"kind"}};

// links.csv's `kind`: odometry (a new experience), loop_closure (RatSLAM re-used an experience)
// or wifi_sequence (Wi-Fi sequence loop closure).
inline const char* LinkKindName(bool loop_closure, bool wifi_sequence) {
  return wifi_sequence ? "wifi_sequence" : loop_closure ? "loop_closure" : "odometry";
}
// localisation.csv (replay --localise): one row per view frame; the errors are empty when the
// frame is lost or the data set has no ground truth.
inline const RunCsvColumns kLocalisationColumns = {
    {"time_s", "experience_id", "lost", "x_m", "y_m", "theta_rad"},
    {"true_x_m", "true_y_m", "error_m"}};
inline const RunCsvColumns kFrameColumns = {
    {"time_s", "template_id", "new_template", "experience_id"}, {"source", "recent"}};

}  // namespace ratslam::io

#endif  // RATSLAM_IO_RUN_COLUMNS_H_
