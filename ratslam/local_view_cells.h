// Local view cells: the store of view templates, front-end agnostic. Each template remembers the
// pose-cell position at its creation; seeing it again injects energy there (Milford and Wyeth
// 2008), with a per-template decay that weakens repeated consecutive injections (the decay model
// of OpenRatSLAM, Ball et al. 2013: E = gain * (limit - exp(rate * decay)) / limit).
//
// Two memory models say how a template recovers from its matches and when it is too new to
// inject (ViewMemory):
//   frames  OpenRatSLAM's: the decay restores by decay_restore_per_frame per view frame and the
//           newest skip_recent_templates templates never inject. Made for cameras at 10-30
//           frames per second along a route that keeps making templates.
//   time    the decay restores by decay_restore_per_s per second of data time since the
//           template's last match, and templates made less than skip_recent_s ago never inject.
//           For sparse frames that revisit a small set of templates, such as Wi-Fi scans every
//           4 s: under `frames` a Wi-Fi template matched twice in a row stays exhausted for 40-80 s
//           (0.05 per 4 s frame), and in a run of 20-35 templates the 10 newest are a third of
//           the map, so on the IPIN logs 147 matches made 8 injections. The default rate, 0.5 per
//           second, is OpenRatSLAM's 0.05 per frame at 10 frames per second.
#ifndef RATSLAM_LOCAL_VIEW_CELLS_H_
#define RATSLAM_LOCAL_VIEW_CELLS_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/status.h"
#include "ratslam/pose_cell_network.h"

namespace ratslam {

enum class ViewMemory { kFrames, kTime };
std::string ToString(ViewMemory memory);
StatusOr<ViewMemory> ViewMemoryFromString(const std::string& name);

struct LocalViewOptions {
  double injection_gain = 0.15;             // energy injected by a fully rested template
  double decay_per_match = 1.0;             // added to a template's decay on each match
  double decay_restore_per_frame = 0.05;    // removed from every template's decay each frame
  double decay_floor = 1.0;                 // decay never falls below this
  double energy_limit = 30.0;               // "limit" in the energy formula above
  double energy_decay_rate = 1.2;           // "rate" in the energy formula above
  int skip_recent_templates = 10;           // the newest templates never inject
  ViewMemory memory = ViewMemory::kFrames;  // see ViewMemory
  double decay_restore_per_s = 0.5;         // time memory: removed from the decay per second
  double skip_recent_s = 10.0;              // time memory: templates this young never inject

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("injection_gain", injection_gain, "pose-cell energy injected by a rested template match",
      schema::Unit("").NonNegative());
    v("decay_per_match", decay_per_match, "added to a template's decay on each match",
      schema::Unit("").NonNegative());
    v("decay_restore_per_frame", decay_restore_per_frame,
      "removed from every template's decay each view frame", schema::Unit("").NonNegative());
    v("decay_floor", decay_floor, "lowest value of a template's decay", schema::Unit(""));
    v("energy_limit", energy_limit, "E = gain * (limit - exp(rate * decay)) / limit: limit",
      schema::Unit("").Positive());
    v("energy_decay_rate", energy_decay_rate,
      "E = gain * (limit - exp(rate * decay)) / limit: rate", schema::Unit("").NonNegative());
    v("skip_recent_templates", skip_recent_templates,
      "matches to this many newest templates inject no energy",
      schema::Unit("templates").NonNegative());
    v("memory", memory,
      "frames (OpenRatSLAM: decay restores per view frame, the newest skip_recent_templates never "
      "inject) or time (per second of data time; templates younger than skip_recent_s never "
      "inject): for sparse, often-repeated templates such as Wi-Fi scans",
      schema::Any());
    v("decay_restore_per_s", decay_restore_per_s,
      "time memory: removed from a template's decay per second since its last match",
      schema::Unit("1/s").NonNegative());
    v("skip_recent_s", skip_recent_s,
      "time memory: matches to templates made less than this long ago inject no energy",
      schema::Unit("s").NonNegative());
  }
};

// What a front end decided about the current view.
struct ViewDecision {
  double time_s = 0.0;
  uint32_t template_id = 0;  // for a new template: must equal the number of templates so far
  bool is_new = false;
  // Current heading minus the heading the template was stored with (panoramic camera or compass);
  // the injection lands at the stored theta plus this change.
  double heading_change_rad = 0.0;
  // False for a familiar view that is no evidence of a loop closure (a recent template seen
  // again): the template becomes current but injects no energy.
  bool allow_injection = true;
};

struct ViewTemplate {
  uint32_t id = 0;
  PoseCellPosition pose_cells;  // pose-cell position when the template was created
  double created_time_s = 0.0;
  double decay = 1.0;  // value after the restore of frame decay_frame
  uint64_t decay_frame = 0;
  double decay_time_s = 0.0;  // time memory: data time at which `decay` held
  uint32_t match_count = 0;
  std::vector<uint32_t> experience_ids;  // experiences created or linked with this template
};

// Energy to inject, and where.
struct Injection {
  PoseCellPosition position;
  double energy = 0.0;
};

class LocalViewCells {
 public:
  struct State {
    std::vector<ViewTemplate> templates;
    uint64_t frame = 0;  // view frames seen
  };

  // `options` must be valid; throws std::invalid_argument otherwise.
  LocalViewCells(const LocalViewOptions& options, int dim_theta_cells);

  // Processes one view frame. A new template is stored at `current_pose`; a repeat returns the
  // injection it causes (none for recent or exhausted templates). Fails on an id that does not
  // fit the store.
  StatusOr<std::optional<Injection>> Observe(const ViewDecision& decision,
                                             const PoseCellPosition& current_pose);

  size_t size() const { return state_.templates.size(); }
  const ViewTemplate& at(uint32_t id) const { return state_.templates[id]; }
  ViewTemplate& at(uint32_t id) { return state_.templates[id]; }
  const State& state() const { return state_; }
  // Restores a state; fails, changing nothing, on ids out of order, a decay or time that is not
  // finite, or a theta outside the ring (x and y are checked by Ratslam, which knows the grid).
  Status SetState(State state);
  // Localisation on a frozen map, from data time `start_time_s` on (another data set's clock):
  // every template now stored is rested (decay at the floor, as if last matched long ago) and
  // never counts as recent, whatever its creation time or how many templates come after it.
  void SettleForLocalisation(double start_time_s);

 private:
  double DecayAtStartOfFrame(const ViewTemplate& t, uint64_t frame) const;
  double DecayAtTime(const ViewTemplate& t, double time_s) const;

  LocalViewOptions options_;
  int dim_theta_cells_;
  State state_;
  size_t settled_templates_ = 0;  // SettleForLocalisation: ids below this are never recent
};

}  // namespace ratslam

#endif  // RATSLAM_LOCAL_VIEW_CELLS_H_
