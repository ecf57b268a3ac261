// Calling the robot to a phone (Kudo and Miura, section V) as a library session: the phone
// located in the Wi-Fi map up to the call's time, the particle filter's candidates served by the
// nearest experiences of the robot's map, and the robot's tour through them over the experience
// graph. `ratslam call` (which adds the figure) and Python drive it; `ratslam route` shares the
// robot's map.
#ifndef RATSLAM_SESSION_CALL_SESSION_H_
#define RATSLAM_SESSION_CALL_SESSION_H_

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/geometry.h"
#include "common/status.h"
#include "phone/particle_filter.h"
#include "phone/robot_call.h"
#include "ratslam/experience_map.h"
#include "session/locate_session.h"

namespace ratslam::session {

// A robot's map: a replay's run folder (experiences.csv, links.csv; the robot is at
// summary.json's current_experience, or else at the experience of frames.csv's last frame that
// had one) or a saved map file (its current experience).
struct RobotMap {
  std::vector<Experience> experiences;
  std::vector<Link> links;
  std::optional<uint32_t> current;
};
StatusOr<RobotMap> LoadRobotMap(const std::string& path);

// The paths the call was made from, as summary labels.
struct CallLabels {
  std::string data, map, wifi_map;
};

struct CallResult {
  size_t scans_used = 0;     // Wi-Fi scans the filter took, up to the call's time
  double last_scan_s = 0.0;  // the last of them
  phone::LocationEstimate estimate;
  std::vector<std::pair<Point2, double>> candidates;  // the filter's, best first, with weights
  std::vector<phone::Particle> particles;             // the filter's at the call
  phone::RouteGraph graph;                            // the robot's map as a graph
  phone::CallPlan plan;
  std::optional<Point2> truth_on_map;  // the phone's true place at the last scan, in the map
  // call.json of `ratslam call` without `run`.
  nlohmann::ordered_json summary;
  // route.csv: step, experience, position, and the candidates each stop serves.
  std::string RouteCsv() const;
};

// Locates the phone with the scans up to `at_s` and plans the robot's tour from its current
// experience. Fails when no scan comes at or before `at_s` or the filter cannot start.
StatusOr<CallResult> CallRobot(const PhoneSetup& setup, const RobotMap& robot, double at_s,
                               const CallLabels& labels);

}  // namespace ratslam::session

#endif  // RATSLAM_SESSION_CALL_SESSION_H_
