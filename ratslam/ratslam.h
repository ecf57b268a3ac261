// The RatSLAM spine: odometry drives the pose cells and the experience map; view decisions from
// any front end drive the local view cells; after each odometry step the action logic creates an
// experience or links to an existing one (Milford and Wyeth 2008, Ball et al. 2013).
#ifndef RATSLAM_RATSLAM_H_
#define RATSLAM_RATSLAM_H_

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "common/schema.h"
#include "common/status.h"
#include "ratslam/experience_map.h"
#include "ratslam/local_view_cells.h"
#include "ratslam/pose_cell_network.h"

namespace ratslam {

struct ActionOptions {
  double match_distance_cells = 2.0;    // experiences of the current template closer than this
                                        // (in pose cells) are candidates for a link
  bool refuse_ambiguous_links = false;  // no link when several candidates are in range
  bool match_heading = true;  // compare pose-cell theta too; off with a compass (a place seen
                              // facing the other way is the same place)

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("match_distance_cells", match_distance_cells,
      "pose-cell distance within which an experience of the current template is re-used",
      schema::Unit("cells").Positive());
    v("refuse_ambiguous_links", refuse_ambiguous_links,
      "make no link when several experiences are within match_distance_cells", schema::Any());
    v("match_heading", match_heading,
      "include pose-cell theta in that distance; false suits an absolute compass heading",
      schema::Any());
  }
};

struct RatslamOptions {
  PoseCellOptions pose_cells;
  LocalViewOptions local_view;
  ExperienceMapOptions experience_map;
  ActionOptions action;

  bool IsValid(std::string* error) const;
};

struct OdometryStep {
  double time_s = 0.0;
  double forward_m = 0.0;     // distance travelled along the heading during the step
  double rotation_rad = 0.0;  // heading change during the step (counter-clockwise positive)
};

enum class ActionKind {
  kNone,
  kCreatedExperience,
  kLinkedExisting,
  kRefusedAmbiguous,
  kRecognised  // frozen map: moved to an existing experience, no link made
};

// Seconds spent in each stage of a run, summed while attached (Ratslam::AttachStageTimes,
// ReplayPipeline::AttachStageTimes): where the time of a frame goes, for benchmarks and profiles.
// Nothing is timed while none is attached.
struct StageTimes {
  double front_end_s = 0.0;       // the front end deciding the view (template matching)
  double pose_cells_s = 0.0;      // pose-cell injection and path integration
  double experience_map_s = 0.0;  // experience-map integration, the action and relaxation
};

// Adds the seconds from its construction to its destruction to `*sum`; does nothing for null.
class StageTimer {
 public:
  explicit StageTimer(double* sum) : sum_(sum) {
    if (sum_) start_ = std::chrono::steady_clock::now();
  }
  ~StageTimer() {
    if (sum_)
      *sum_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  double* sum_;
  std::chrono::steady_clock::time_point start_;
};

class Ratslam {
 public:
  struct Counters {
    uint64_t odometry_steps = 0;
    uint64_t view_frames = 0;
    uint64_t injections = 0;
    uint64_t loop_closures = 0;  // links made to an experience that existed already
    uint64_t refused_ambiguous = 0;
  };
  // Of a frozen map (FreezeMap), not saved.
  struct LocalisationCounters {
    uint64_t recognitions = 0;     // moves to an experience the pose cells agree with
    uint64_t unmapped_views = 0;   // view frames of templates made after the freeze
    uint64_t relocalisations = 0;  // of the recognitions, those made while lost (FreezeMap)
  };

  // `options` must be valid (IsValid); throws std::invalid_argument otherwise.
  explicit Ratslam(const RatslamOptions& options);

  // One view frame from a front end.
  Status OnView(const ViewDecision& decision);
  // One odometry step followed by the action logic.
  StatusOr<ActionKind> OnOdometry(const OdometryStep& step);
  // A link between existing experiences measured outside the spine (Wi-Fi sequence loop
  // closure; see ExperienceMap::AddConstraint), relaxed with the next odometry step.
  StatusOr<bool> AddConstraint(uint32_t from, uint32_t to, const Pose2& relative, double time_s) {
    return experience_map_.AddConstraint(from, to, relative, time_s);
  }
  // One relaxation action on the experience map (after constraints added when no odometry step
  // follows).
  void RelaxExperienceMap() { experience_map_.Relax(); }
  // The latest absolute heading (compass), or none; used by the action logic and stored with new
  // experiences (see ExperienceMap).
  void SetCompassHeading(std::optional<double> heading_rad) { compass_heading_rad_ = heading_rad; }

  // Localisation on a frozen map (`replay --localise`): from now on the templates, experiences and
  // links stay as they are. A view of a template made after the freeze (a place the map does not
  // know; the front end still keeps it, so that its ids stay those of the local view cells)
  // injects no energy and leaves no current template. The action logic makes no experience and no
  // link: it moves the current experience to the current template's experience nearest the pose
  // cells, when within match_distance_cells (ActionKind::kRecognised), and otherwise dead reckons
  // on. The current experience is forgotten: the robot is lost until it recognises a place. The
  // templates are rested for data starting at `start_time_s`
  // (LocalViewCells::SettleForLocalisation). Not part of State: a frozen spine is never saved.
  // With `relocalise_after_m`, a robot that is lost (no current experience, or dead reckoned
  // further than that from it) and views a template of the map is put back there at once: the
  // pose cells reset to a single packet at the template's experience nearest them and that
  // experience becomes current (a recognition, counted as a relocalisation too). Without it the
  // pose cells must first be moved there by the view's injections.
  void FreezeMap(double start_time_s, std::optional<double> relocalise_after_m = std::nullopt);
  bool frozen() const { return frozen_templates_.has_value(); }
  // No current experience, or dead reckoned further than `after_m` from it.
  bool Lost(double after_m) const;

  // From now on, add the time of each stage to `times` (null: stop timing). `times` must outlive
  // the timing.
  void AttachStageTimes(StageTimes* times) { stage_times_ = times; }

  const PoseCellNetwork& pose_cells() const { return pose_cells_; }
  const LocalViewCells& local_view() const { return local_view_; }
  const ExperienceMap& experience_map() const { return experience_map_; }
  std::optional<uint32_t> current_template() const { return current_template_; }
  const Counters& counters() const { return counters_; }
  const LocalisationCounters& localisation_counters() const { return localisation_counters_; }
  const RatslamOptions& options() const { return options_; }

  struct State {
    PoseCellNetwork::State pose_cells;
    LocalViewCells::State local_view;
    ExperienceMap::State experience_map;
    std::optional<uint32_t> current_template;
    Counters counters;
    std::optional<double> compass_heading_rad;
  };
  State GetState() const;
  // Restores a state from GetState (of a spine with the same options). All or nothing: on an
  // error (ids out of range, sizes that do not fit the options) nothing changes.
  Status SetState(const State& state);

 private:
  StatusOr<ActionKind> Act(double time_s);

  RatslamOptions options_;
  PoseCellNetwork pose_cells_;
  LocalViewCells local_view_;
  ExperienceMap experience_map_;
  std::optional<uint32_t> current_template_;
  Counters counters_;
  std::optional<double> compass_heading_rad_;
  std::optional<size_t> frozen_templates_;    // templates of the frozen map
  std::optional<double> relocalise_after_m_;  // FreezeMap's
  StageTimes* stage_times_ = nullptr;
  LocalisationCounters localisation_counters_;
};

}  // namespace ratslam

#endif  // RATSLAM_RATSLAM_H_
