// The experience map: a graph of experiences (x, y, theta) joined by links that carry the
// odometry between them, kept consistent by iterative graph relaxation (Milford and Wyeth 2008).
#ifndef RATSLAM_EXPERIENCE_MAP_H_
#define RATSLAM_EXPERIENCE_MAP_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/geometry.h"
#include "common/schema.h"
#include "common/status.h"
#include "ratslam/pose_cell_network.h"
#include "ratslam/pose_graph.h"

namespace ratslam {

// Largest magnitude a coordinate (m), angle (rad) or time (s) may have in a restored state: larger
// values, like non-finite ones, mean a corrupt file (data times are at most epoch seconds).
inline constexpr double kMaxCoordinate = 1e12;

// Which links a relaxation pass visits.
//  - kFull: every link, in link order, `relaxation_sweeps` times after each action (OpenRatSLAM's
//    scheme, Milford and Wyeth 2008; cost grows with the map).
//  - kIncremental: the same Gauss-Seidel passes in link order over a region of links that grows
//    from each new link: by the later links of an experience that one update moved by more than
//    the tolerances (the reach of a full pass), and by all links of an experience that a whole
//    pass moved on net by more. The region is relaxed, over as many actions as it takes, until a
//    pass moves nothing on net, then dropped. Net movement, because single updates in an
//    inconsistent loop swing for ever (cyclic projections reach a limit cycle) while the poses
//    after a pass over a fixed set of links converge. A frame that only extends the map costs
//    one link update; a loop closure costs passes over the loop and a fringe around it. The
//    rotation of each experience is read once per pass (sin/cos per experience, not per link).
//    The region stops growing at relaxation_max_region_links, and when new links take it past
//    the cap, the links whose ends the last pass moved least leave it: on a map whose loops are
//    larger, a closure's correction spreads over that many links around it and the rest of the
//    map stays as it is (a window in the graph that follows the unsettled part), so an action
//    costs at most relaxation_sweeps passes over the cap plus the links added since the last
//    action, however large the map grows. relaxation_capped_passes() counts when that happened.
//  - kLeastSquares: no relaxation passes; after an action that added a loop closure (the
//    spine's or Wi-Fi sequence loop closure's), the whole graph is optimised by sparse least
//    squares (ratslam/pose_graph.h) with the links' information from link_sigma_m,
//    link_sigma_m_per_m and link_sigma_rad. A new experience placed by odometry satisfies its
//    link exactly, so nothing else needs work; each closure costs a sparse solve over the map.
enum class RelaxationScheme { kFull, kIncremental, kLeastSquares };
std::string ToString(RelaxationScheme scheme);
StatusOr<RelaxationScheme> RelaxationSchemeFromString(const std::string& name);

struct ExperienceMapOptions {
  int relaxation_sweeps = 10;            // relaxation passes after each action
  double relaxation_correction = 0.5;    // share of a link's error each end absorbs per pass
  bool anchor_first_experience = false;  // keep experience 0 fixed during relaxation
  RelaxationScheme relaxation_scheme = RelaxationScheme::kIncremental;  // see RelaxationScheme
  double relaxation_tolerance_m = 1e-3;    // kIncremental: movement that grows the region
  double relaxation_tolerance_rad = 1e-4;  // kIncremental: rotation that grows the region
  // kIncremental: the region stops growing at this many links (0: no limit), so a loop closure
  // on a large map costs at most relaxation_sweeps passes over this many links per action.
  int relaxation_max_region_links = 5000;
  // A link's noise: the information matrix of kLeastSquares and of the g2o output.
  double link_sigma_m = 0.05;
  double link_sigma_m_per_m = 0.05;
  double link_sigma_rad = 0.05;
  // Heading of the map's frame at the start: the first experience faces this way (OpenRatSLAM's
  // exp_initial_em_deg, 90 degrees by its default). It rotates the whole map and nothing else.
  double initial_heading_rad = 0.0;

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("relaxation_sweeps", relaxation_sweeps,
      "relaxation passes after each action (over every link, or the links that need it)",
      schema::Unit("sweeps").NonNegative());
    v("relaxation_correction", relaxation_correction,
      "share of a link's error each end absorbs per pass (0.5 satisfies the link exactly)",
      schema::Unit("").Within(0, 0.5));
    v("anchor_first_experience", anchor_first_experience,
      "keep experience 0 fixed during relaxation", schema::Any());
    v("relaxation_scheme", relaxation_scheme,
      "full (every link in every pass, as OpenRatSLAM), incremental (only links whose ends "
      "moved) or least_squares (sparse least-squares optimisation of the graph at loop closures)",
      schema::Any());
    v("relaxation_tolerance_m", relaxation_tolerance_m,
      "incremental: movement of an experience that adds its links to the relaxed region",
      schema::Unit("m").Positive());
    v("relaxation_tolerance_rad", relaxation_tolerance_rad,
      "incremental: rotation of an experience that adds its links to the relaxed region",
      schema::Unit("rad").Positive());
    v("relaxation_max_region_links", relaxation_max_region_links,
      "incremental: the relaxed region stops growing at this many links (0: no limit); bounds an "
      "action's cost on large maps, leaving the map beyond the region as it is",
      schema::Unit("links").NonNegative());
    v("link_sigma_m", link_sigma_m,
      "translation noise of a link (plus link_sigma_m_per_m of its length): the information "
      "matrix of least_squares and of experience_map.g2o",
      schema::Unit("m").Positive());
    v("link_sigma_m_per_m", link_sigma_m_per_m,
      "translation noise of a link per metre of its length", schema::Unit("m/m").NonNegative());
    v("link_sigma_rad", link_sigma_rad, "rotation noise of a link", schema::Unit("rad").Positive());
    v("initial_heading_rad", initial_heading_rad,
      "heading of the start, so of the first experience (OpenRatSLAM's exp_initial_em_deg)",
      schema::Unit("rad").Within(-2 * M_PI, 2 * M_PI));
  }
  // The link noise model these options describe.
  LinkNoise Noise() const { return {link_sigma_m, link_sigma_m_per_m, link_sigma_rad}; }
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
  bool loop_closure = false;   // true when `to` existed before the link was made
  bool wifi_sequence = false;  // made by Wi-Fi sequence loop closure (AddConstraint)
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
    // Incremental relaxation's region, the links still being relaxed (ascending ids); empty
    // when settled. Saved so that a resumed run relaxes as an uninterrupted one.
    std::vector<uint32_t> relaxation_pending_links;
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
  // Makes `id` (which must exist) current with no link, dead reckoning restarting from it (facing
  // as in LinkTo): localisation on a frozen map recognising a place.
  void MoveTo(uint32_t id, double time_s, std::optional<double> compass_heading_rad = std::nullopt);
  // No current experience and no offset: a localisation run before it recognises a place.
  void Forget() {
    state_.current.reset();
    state_.offset = LocalOffset();
  }

  // Links existing experiences `from` and `to` with `to`'s pose in `from`'s frame measured by
  // something other than odometry (Wi-Fi sequence loop closure); the current experience does not
  // change. When both experiences carry a compass heading, the link's facing is their compass
  // difference, as for the spine's own links (a facing measured through odometry at a turn can be
  // off by half a turn, and one such link rotates a whole session). Returns false (adding nothing)
  // when the two are the same or already linked; fails on an unknown id or a non-finite pose.
  StatusOr<bool> AddConstraint(uint32_t from, uint32_t to, const Pose2& relative, double time_s);

  // `relaxation_sweeps` passes of relaxation (see RelaxationScheme).
  void Relax();
  // Link updates made by Relax since construction (not saved): a measure of relaxation cost.
  uint64_t relaxation_link_updates() const { return link_updates_; }
  // kLeastSquares: optimisations run and failed (not saved). A failed one leaves the map as it
  // was and is retried at the next action.
  uint64_t least_squares_runs() const { return least_squares_runs_; }
  uint64_t least_squares_failures() const { return least_squares_failures_; }
  // kIncremental: passes in which the region would have grown beyond relaxation_max_region_links
  // (not saved). Zero means the cap changed nothing.
  uint64_t relaxation_capped_passes() const { return capped_passes_; }

  // The pose of the current experience composed with the offset since it.
  void CurrentPose(double* x_m, double* y_m, double* theta_rad) const;

  // Experience ids along the shortest path (by link distance) from `from` to `to`, both
  // included; empty when they are not connected or an id does not exist.
  std::vector<uint32_t> ShortestPath(uint32_t from, uint32_t to) const;
  // Whether links other than Wi-Fi sequence closure's (odometry and the front end's loop
  // closures) join `from` and `to` by a path shorter than `within_m`; the search stays within
  // that distance of `from`. An id that does not exist is joined to nothing.
  bool JoinedWithin(uint32_t from, uint32_t to, double within_m) const;

  size_t num_experiences() const { return state_.experiences.size(); }
  size_t num_links() const { return state_.links.size(); }
  const Experience& experience(uint32_t id) const { return state_.experiences[id]; }
  const std::vector<Experience>& experiences() const { return state_.experiences; }
  const std::vector<Link>& links() const { return state_.links; }
  std::optional<uint32_t> current() const { return state_.current; }
  const LocalOffset& offset() const { return state_.offset; }
  const State& state() const { return state_; }
  const ExperienceMapOptions& options() const { return options_; }
  // Restores a state; fails, changing nothing, on an id that points nowhere (a link's ends, an
  // experience's links, the current experience) or a non-finite or out-of-range number.
  Status SetState(State state);
  // The checks of SetState alone: every reader of a saved map (map_file.h) runs them, so a map
  // that one command refuses is refused by all.
  static Status ValidateState(const State& state);

 private:
  void AddLink(uint32_t from, uint32_t to, double time_s, std::optional<double> facing_override,
               bool loop_closure);
  bool Linked(uint32_t a, uint32_t b) const;

  void RelaxFull();
  void RelaxIncremental();
  void RelaxLeastSquares();

  // Incremental relaxation works on a copy of what a link update reads and writes, laid out for
  // the scan: per link its ends and measurement with the cos and sin of heading_rad; per
  // experience its pose (loaded from the map at the first touch in a Relax call, written back at
  // its end), its rotation's cos and sin as the pass first read them, and its pose when a pass
  // first touched it.
  struct RelaxLink {
    uint32_t from, to;
    double distance_m, cos_heading, sin_heading, facing_rad;
  };
  struct RelaxPose {
    double x_m, y_m, theta_rad, cos_theta, sin_theta;
    double trig_theta_rad;  // the rotation cos_theta and sin_theta are of
    double start_x_m, start_y_m, start_theta_rad;
    uint64_t pass = 0;  // the pass that last touched it
    uint64_t call = 0;  // the Relax call that loaded it
  };
  static RelaxLink ToRelaxLink(const Link& l);
  // Movement of each end of a link by one update: metres (|dx| + |dy|) and radians.
  struct EndMotion {
    double a_m, a_rad, b_m, b_rad;
  };
  // Moves a and b (poses with x_m, y_m, theta_rad) towards agreement with a link of
  // `distance_m` and `facing_rad` whose direction has the given cosine and sine, each end by the
  // share `correction` of the error unless fixed: the one link update of both schemes.
  template <typename Pose>
  static EndMotion CorrectLink(Pose& a, Pose& b, double distance_m, double facing_rad,
                               double cos_direction, double sin_direction, double correction,
                               bool a_fixed, bool b_fixed);
  // The full scheme's update of link `l`, given the cosine and sine of its direction (from's
  // rotation plus heading_rad).
  void UpdateLink(const Link& l, double cos_direction, double sin_direction);
  // The incremental scheme's update of link `l` between a and b, its direction from a's cos and
  // sin as the pass first read them.
  EndMotion UpdateRelaxLink(const RelaxLink& l, RelaxPose& a, RelaxPose& b, bool a_fixed,
                            bool b_fixed) const;
  // Experience `id`'s working pose, loaded at its first touch in this call, with its pose at
  // its first touch in this pass recorded.
  RelaxPose& Touch(uint32_t id);
  // Copies experience `id`'s pose and its rotation's cos and sin into its RelaxPose.
  void LoadPose(uint32_t id);
  // Adds `id`'s links with ids from `above` that are not in the region yet to it (and, with
  // `this_pass`, to the links still ahead in this pass). Returns true when the region grew.
  bool GrowRegion(uint32_t id, uint32_t above, bool this_pass);
  void LeaveRegion(uint32_t link);
  // Shrinks the region to `cap` links after a pass, keeping those whose ends moved most.
  void TrimRegion(size_t cap);

  ExperienceMapOptions options_;
  State state_;
  // Scratch, rebuilt from state_ (see RelaxLink and RelaxPose).
  std::vector<RelaxLink> relax_links_;
  std::vector<RelaxPose> relax_poses_;
  // The cos and sin of an experience's rotation computed when it was last loaded, and that
  // rotation (NaN: never): an experience whose rotation the last actions left alone needs no new
  // sincos. Later passes of a call turn the working cos and sin by the rotation since.
  std::vector<double> experience_cos_, experience_sin_, experience_trig_rad_;
  std::vector<uint32_t> outside_;  // per experience: how many of its links are not in the region
  std::vector<uint32_t> ahead_, grown_, touched_, loaded_;
  std::vector<char> in_region_;  // per link: in relaxation_pending_links
  uint64_t call_ = 0;
  uint64_t pass_ = 0;
  uint64_t link_updates_ = 0;
  uint64_t least_squares_runs_ = 0;
  uint64_t least_squares_failures_ = 0;
  uint64_t capped_passes_ = 0;
  bool capped_this_pass_ = false;
};

}  // namespace ratslam

#endif  // RATSLAM_EXPERIENCE_MAP_H_
