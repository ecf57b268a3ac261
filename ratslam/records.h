// Plain records of what a run produced, shared by the pipeline that makes them, the outputs that
// write them and the viewer that draws them (which never sees the pipeline itself).
#ifndef RATSLAM_RATSLAM_RECORDS_H_
#define RATSLAM_RATSLAM_RECORDS_H_

#include <cstdint>
#include <string>
#include <vector>

#include "ratslam/experience_map.h"
#include "ratslam/pose_cell_network.h"

namespace ratslam {

// Which sensor decided a frame.
enum class DecisionSource : uint8_t { kCamera = 0, kWifi = 1, kNew = 2 };
std::string ToString(DecisionSource source);

// One odometry step's outcome: where the map puts the robot (by experience and offset, so that
// the final relaxed map gives the final trajectory) and where raw odometry puts it.
struct TrajectoryRecord {
  double time_s = 0.0;
  int64_t experience_id = -1;  // -1 before the first experience
  LocalOffset offset;
  double odometry_x_m = 0.0, odometry_y_m = 0.0, odometry_theta_rad = 0.0;
};

// One view frame's outcome, for template graphs.
struct FrameRecord {
  double time_s = 0.0;
  uint32_t template_id = 0;
  bool is_new = false;
  int64_t experience_id = -1;  // current experience after the frame
  DecisionSource source = DecisionSource::kNew;
  bool recent = false;  // re-used a recent template (no injection; not counted as a match)
};

// One view frame of a localisation run on a frozen map (ReplayPipeline::AdoptMap): where the map
// puts the robot.
struct LocalisationRecord {
  double time_s = 0.0;
  int64_t experience_id = -1;  // the experience recognised last; -1 before the first
  double x_m = 0.0, y_m = 0.0, theta_rad = 0.0;  // that experience composed with dead reckoning
  bool lost = true;  // no experience yet, or dead reckoned further than lost_after_m from it
};

// A read-only view of a run: the map, the pose cells and the records, wherever they live.
struct RunView {
  const ExperienceMap& map;
  const PoseCellNetwork& pose_cells;
  const std::vector<FrameRecord>& frames;
  const std::vector<TrajectoryRecord>& trajectory;
  // Localisation runs only: the map is another run's, frozen (its experiences were made on
  // another data set's clock).
  const std::vector<LocalisationRecord>* localisation = nullptr;
};

}  // namespace ratslam

#endif  // RATSLAM_RATSLAM_RECORDS_H_
