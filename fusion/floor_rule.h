// The floor rule of front_end.h ("Floors"), shared by the front ends that match Wi-Fi (fused and
// FABMAP): the current session's barometer (sensors/barometer.h) gives its level; each template
// keeps its session and level; a match needs the barometer to agree; a later session's floor
// offset to the first starts at 0 and follows Wi-Fi votes. Internal to the front ends. With
// use_barometer off every call does nothing (and the state holds nothing), so a front end calls
// it unconditionally.
#ifndef RATSLAM_FUSION_FLOOR_RULE_H_
#define RATSLAM_FUSION_FLOOR_RULE_H_

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "common/byte_buffer.h"
#include "common/status.h"
#include "fusion/front_end.h"
#include "sensors/barometer.h"

namespace ratslam::fusion::front_end_internal {

class FloorRule {
 public:
  // A vote must beat the best match on every other floor by this factor (else it abstains).
  static constexpr double kVoteRatio = 1.5;

  // `options` must be valid (FloorOptions::IsValid); throws std::invalid_argument otherwise.
  explicit FloorRule(const FloorOptions& options);

  bool enabled() const { return options_.use_barometer; }
  Status OnPressure(double time_s, double pressure_hpa);
  // A new session starting at `start_s` (repeats are no news).
  void OnSessionStart(double start_s);
  // Localisation on a saved map: the walk to localise is a session of its own.
  void SettleForLocalisation();

  // The barometer has spoken (a reading arrived): before that nothing is constrained.
  bool active() const { return enabled() && pressure_readings_ > 0; }
  // Before a frame is decided among `templates` stored: counts a frame on the stairs and returns
  // a flag per template, set where the barometer lets the current observation match it.
  std::vector<uint8_t> BeginFrame(uint32_t templates);
  // One vote on the current session's floor offset. `best(mask)` returns the best (template id,
  // score) among the templates whose flag is set (id -1 for none); a vote needs a score of at
  // least `threshold` that beats the best on every other floor by kVoteRatio.
  template <typename Best>
  void Vote(Best&& best, double threshold);
  // The template just stored belongs to the current session and level.
  void AddTemplate();
  // A frame that became a new template only because its best match was on another floor.
  void CountRefused() { ++refused_; }

  // A template's floor relative to the first session's first level, when known.
  std::optional<int> TemplateFloor(uint32_t id) const;
  // What the barometer said, once it has said anything.
  std::optional<FloorReport> Report() const;

  void Encode(ByteWriter* writer) const;
  // Reads what Encode wrote for a front end holding `templates` templates; on failure this rule
  // is unchanged and `reader` holds the error.
  bool Decode(ByteReader* reader, size_t templates);

 private:
  // kNoBarometer: no reading yet in the session (no constraint); kUnknown: on the stairs
  // (matches nothing with a floor); else a level index of the session's tracker.
  static constexpr int32_t kNoBarometer = -2;
  static constexpr int32_t kUnknown = -1;

  void NewSession();
  int MapFloor(uint32_t session, int32_t level) const {
    return level_floors_[session][level] + offsets_[session];
  }
  bool Agrees(uint32_t t) const;
  bool VoteCandidates(std::vector<uint8_t>* candidates) const;
  void CountVote(uint32_t template_id);

  FloorOptions options_;
  sensors::BarometricFloorTracker tracker_;
  uint64_t pressure_readings_ = 0;
  uint64_t floor_changes_before_ = 0;  // of the sessions before the current one
  int32_t level_ = kNoBarometer;
  uint32_t session_ = 0;
  std::optional<double> session_start_s_;
  std::vector<std::vector<int32_t>> level_floors_ = {{}};  // by session: each level's floor
  std::vector<int32_t> offsets_ = {0};  // by session: floor offset to the map's frame
  // The current session's votes, three numbers each: template session and level, our level.
  std::vector<int32_t> votes_;
  uint64_t offset_changes_ = 0;
  std::vector<uint32_t> template_session_;
  std::vector<int32_t> template_level_;
  uint64_t frames_unknown_ = 0;
  uint64_t refused_ = 0;
};

template <typename Best>
void FloorRule::Vote(Best&& best, double threshold) {
  if (!active()) return;
  std::vector<uint8_t> candidates;
  if (!VoteCandidates(&candidates)) return;
  const std::pair<int64_t, double> top = best(candidates);
  if (top.first < 0 || top.second < threshold) return;
  const int top_floor = MapFloor(template_session_[top.first], template_level_[top.first]);
  for (size_t t = 0; t < candidates.size(); ++t) {
    candidates[t] =
        candidates[t] && MapFloor(template_session_[t], template_level_[t]) != top_floor;
  }
  const std::pair<int64_t, double> other = best(candidates);
  if (other.first >= 0 && top.second < kVoteRatio * other.second) return;  // ambiguous
  CountVote(static_cast<uint32_t>(top.first));
}

}  // namespace ratslam::fusion::front_end_internal

#endif  // RATSLAM_FUSION_FLOOR_RULE_H_
