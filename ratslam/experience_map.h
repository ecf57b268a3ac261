// The experience map: a graph of experiences (x, y, theta) joined by links that carry the
// odometry between them, kept consistent by iterative graph relaxation (Milford and Wyeth 2008).
#ifndef RATSLAM_EXPERIENCE_MAP_H_
#define RATSLAM_EXPERIENCE_MAP_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/status.h"
#include "ratslam/pose_cell_network.h"

namespace ratslam {

// Largest magnitude a coordinate (m), angle (rad) or time (s) may have in a restored state: larger
// values, like non-finite ones, mean a corrupt file (data times are at most epoch seconds).
inline constexpr double kMaxCoordinate = 1e12;

struct ExperienceMapOptions {
  int relaxation_sweeps = 10;            // relaxation passes over all links after each action
  double relaxation_correction = 0.5;    // share of a link's error each end absorbs per pass
  bool anchor_first_experience = false;  // keep experience 0 fixed during relaxation

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("relaxation_sweeps", relaxation_sweeps, "relaxation passes over all links after each action",
      schema::Unit("sweeps").NonNegative());
    v("relaxation_correction", relaxation_correction,
      "share of a link's error each end absorbs per pass (0.5 satisfies the link exactly)",
      schema::Unit("").Within(0, 0.5));
    v("anchor_first_experience", anchor_first_experience,
      "keep experience 0 fixed during relaxation", schema::Any());
  }
};

struct Experience {
  uint32_t id = 0;
  double x_m = 0.0;
  double y_m = 0.0;
  double theta_rad = 0.0;
  uint32_t template_id = 0;
  PoseCellPosition pose_cells;                // pose-cell position at creation
  double time_s = 0.0;                        // creation time
  std::optional<double> compass_heading_rad;  // absolute heading at creation, if known
  std::vector<uint32_t> link_ids;             // links from or to this experience
};

struct Link {
  uint32_t id = 0;
  uint32_t from = 0;
  uint32_t to = 0;
  double distance_m = 0.0;
  double heading_rad = 0.0;  // direction of `to` seen from `from`, relative to from's facing
  double facing_rad = 0.0;   // to's facing minus from's facing
  double duration_s = 0.0;
  bool loop_closure = false;  // true when `to` existed before the link was made
};

// Odometry accumulated since the current experience, in that experience's frame.
struct LocalOffset {
  double forward_m = 0.0;
  double left_m = 0.0;
  double facing_rad = 0.0;
};

class ExperienceMap {
 public:
  struct State {
    std::vector<Experience> experiences;
    std::vector<Link> links;
    std::optional<uint32_t> current;  // none before the first experience
    LocalOffset offset;               // since `current` (or since the origin)
    double offset_start_time_s = 0.0;
  };

  // `options` must be valid; throws std::invalid_argument otherwise.
  explicit ExperienceMap(const ExperienceMapOptions& options);

  // Dead reckoning since the current experience (midpoint rule for the heading).
  void Integrate(double forward_m, double rotation_rad);

  // Creates an experience at the current pose (current experience plus offset) and links the
  // current experience to it. With a compass heading (here and at the current experience) the
  // link's facing change is the compass difference instead of the odometric one, which removes
  // rotational drift (Wi-Fi RatSLAM paper, section III-A). Returns its id.
  uint32_t CreateExperience(uint32_t template_id, const PoseCellPosition& pose_cells, double time_s,
                            std::optional<double> compass_heading_rad = std::nullopt);
  // Links the current experience to the existing experience `id` (unless a link between them
  // exists already) and makes it current. With a compass heading now, at `id` and at the current
  // experience, the link's facing is the compass difference (eq. 2) and dead reckoning continues
  // from `id` facing the current compass heading, not `id`'s facing: a place revisited in the
  // opposite direction. Returns true when a link was added.
  StatusOr<bool> LinkTo(uint32_t id, double time_s,
                        std::optional<double> compass_heading_rad = std::nullopt);

  // `relaxation_sweeps` passes of relaxation over every link.
  void Relax();

  // The pose of the current experience composed with the offset since it.
  void CurrentPose(double* x_m, double* y_m, double* theta_rad) const;

  // Experience ids along the shortest path (by link distance) from `from` to `to`, both
  // included; empty when they are not connected or an id does not exist.
  std::vector<uint32_t> ShortestPath(uint32_t from, uint32_t to) const;

  size_t num_experiences() const { return state_.experiences.size(); }
  size_t num_links() const { return state_.links.size(); }
  const Experience& experience(uint32_t id) const { return state_.experiences[id]; }
  const std::vector<Experience>& experiences() const { return state_.experiences; }
  const std::vector<Link>& links() const { return state_.links; }
  std::optional<uint32_t> current() const { return state_.current; }
  const LocalOffset& offset() const { return state_.offset; }
  const State& state() const { return state_; }
  // Restores a state; fails, changing nothing, on an id that points nowhere (a link's ends, an
  // experience's links, the current experience) or a non-finite or out-of-range number.
  Status SetState(State state);

 private:
  void AddLink(uint32_t from, uint32_t to, double time_s, std::optional<double> facing_override,
               bool loop_closure);

  ExperienceMapOptions options_;
  State state_;
};

}  // namespace ratslam

#endif  // RATSLAM_EXPERIENCE_MAP_H_
