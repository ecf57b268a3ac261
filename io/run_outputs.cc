#include "io/run_outputs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "common/circular.h"
#include "common/geometry.h"
#include "common/number_text.h"
#include "io/provenance_json.h"
#include "io/run_columns.h"

namespace ratslam::io {
namespace {

std::string Num(double value) { return ShortestNumber(value); }

// TUM files need strictly increasing stamps (evo_traj --full_check): of trajectory records at
// one time (odometry rows a data set repeats), only the last, the pose after all of them.
bool InTumFiles(const std::vector<TrajectoryRecord>& trajectory, size_t i) {
  return i + 1 == trajectory.size() || trajectory[i + 1].time_s > trajectory[i].time_s;
}

std::string TumLine(double t, double x, double y, double theta) {
  return Num(t) + " " + Num(x) + " " + Num(y) + " 0 0 0 " + Num(std::sin(theta / 2)) + " " +
         Num(std::cos(theta / 2)) + "\n";
}

}  // namespace

void RecordPose(const ExperienceMap& map, const TrajectoryRecord& record, double* x_m, double* y_m,
                double* theta_rad) {
  Pose2 base;
  if (record.experience_id >= 0) {
    const Experience& e = map.experience(static_cast<uint32_t>(record.experience_id));
    base = {e.x_m, e.y_m, e.theta_rad};
  }
  const LocalOffset& o = record.offset;
  const Pose2 pose = Compose(base, o.forward_m, o.left_m, o.facing_rad);
  *x_m = pose.x_m;
  *y_m = pose.y_m;
  *theta_rad = pose.theta_rad;
}

namespace {

// The share of distances within 2, 5, 10 and 20 m, keyed "2", "5", "10", "20" (0 when empty).
nlohmann::ordered_json RatesWithin(const std::vector<double>& distances_m) {
  nlohmann::ordered_json within;
  for (int d : {2, 5, 10, 20}) {
    size_t n = 0;
    for (double m : distances_m) n += m <= d;
    within[std::to_string(d)] =
        distances_m.empty() ? 0.0
                            : static_cast<double>(n) / static_cast<double>(distances_m.size());
  }
  return within;
}

// Mean, standard deviation and maximum (the paper's table I); empty input gives zeros.
nlohmann::ordered_json ErrorStatistics(const std::vector<double>& v) {
  double sum = 0.0, sum2 = 0.0, max = 0.0;
  for (double x : v) {
    sum += x;
    sum2 += x * x;
    max = std::max(max, x);
  }
  const double n = static_cast<double>(v.size());
  const double mean = v.empty() ? 0.0 : sum / n;
  const double variance = v.empty() ? 0.0 : std::max(sum2 / n - mean * mean, 0.0);
  return {{"count", v.size()}, {"mean", mean}, {"std", std::sqrt(variance)}, {"max", max}};
}

// Wi-Fi sequence loop closure: loops and, with ground truth, the correspondence errors of
// table I: in metres (true positions of the two scans) and in poses (how many poses the past
// pose is from the past pose truly nearest the current one, among the poses the past sequence
// spans). Verified: inliers of accepted loops; unverified: every DP pair of every loop matched.
nlohmann::ordered_json SequenceSummary(const wifi_sequence::WifiSequenceLoopCloser& closer,
                                       const ExperienceMap& map, const dataset::Dataset& dataset) {
  nlohmann::ordered_json j;
  size_t accepted = 0, linked = 0, links = 0, verified = 0;
  for (const wifi_sequence::SequenceLoop& l : closer.loops()) {
    accepted += l.accepted;
    linked += l.accepted && l.outcome.rfind(wifi_sequence::kNoLinkOutcome, 0) != 0;
    if (l.accepted) verified += l.inliers;
  }
  for (const Link& l : map.links()) links += l.wifi_sequence;
  j["poses"] = closer.size();
  j["loops_matched"] = closer.loops().size();
  j["loops_accepted"] = accepted;
  j["loops_linked"] = linked;
  j["verified_correspondences"] = verified;
  j["links"] = links;
  nlohmann::ordered_json loops = nlohmann::ordered_json::array();
  for (const wifi_sequence::SequenceLoop& l : closer.loops()) {
    loops.push_back({{"id", l.id},
                     {"matched_time_s", l.time_s},
                     {"current_poses", l.current_sequence.size()},
                     {"past_poses", l.past_sequence.size()},
                     {"inliers", l.inliers},
                     {"rotation_rad", l.transform.theta_rad},
                     {"reversed", l.reversed},
                     {"outcome", l.outcome}});
  }
  j["loops"] = loops;
  if (dataset.ground_truth.empty()) return j;
  std::vector<std::optional<GroundTruthRow>> truth(closer.size());
  for (size_t i = 0; i < closer.size(); ++i) {
    truth[i] = dataset::GroundTruthAt(dataset, closer.pose(i).time_s);
  }
  auto metres = [&](uint32_t a, uint32_t b) {
    if (!truth[a] || !truth[b]) return std::numeric_limits<double>::quiet_NaN();
    if (truth[a]->floor != truth[b]->floor) return std::numeric_limits<double>::infinity();
    return std::hypot(truth[a]->x_m - truth[b]->x_m, truth[a]->y_m - truth[b]->y_m);
  };
  std::vector<double> verified_m, verified_poses, unverified_m;
  size_t verified_floor_mistakes = 0, unverified_floor_mistakes = 0;
  for (const wifi_sequence::SequenceLoop& l : closer.loops()) {
    if (l.past_sequence.empty()) continue;
    const uint32_t lo = l.past_sequence.front(), hi = l.past_sequence.back();
    for (const wifi_sequence::SequenceCorrespondence& c : l.correspondences) {
      const double m = metres(c.current_pose, c.past_pose);
      if (std::isnan(m)) continue;
      const bool verified = l.accepted && c.inlier;
      if (std::isinf(m)) {  // the two scans are on different floors
        ++unverified_floor_mistakes;
        verified_floor_mistakes += verified;
        continue;
      }
      unverified_m.push_back(m);
      if (!verified) continue;
      verified_m.push_back(m);
      // The truly nearest pose of the same past visit: follow the past track from the matched
      // pose while the true distance falls (a past sequence may span several visits).
      uint32_t nearest = c.past_pose;
      for (int direction : {-1, 1}) {
        uint32_t p = c.past_pose;
        while (true) {
          const int64_t next = static_cast<int64_t>(p) + direction;
          if (next < lo || next > hi) break;
          if (!(metres(c.current_pose, static_cast<uint32_t>(next)) < metres(c.current_pose, p)))
            break;
          p = static_cast<uint32_t>(next);
        }
        if (metres(c.current_pose, p) < metres(c.current_pose, nearest)) nearest = p;
      }
      verified_poses.push_back(std::abs(static_cast<double>(nearest) - c.past_pose));
    }
  }
  j["verified_error_m"] = ErrorStatistics(verified_m);
  j["verified_error_poses"] = ErrorStatistics(verified_poses);
  j["unverified_error_m"] = ErrorStatistics(unverified_m);
  j["verified_floor_mistakes"] = verified_floor_mistakes;
  j["unverified_floor_mistakes"] = unverified_floor_mistakes;
  return j;
}

}  // namespace

CrossSessionPlaces ScoreCrossSessionPlaces(const std::vector<FrameRecord>& frames,
                                           const dataset::Dataset& dataset) {
  CrossSessionPlaces out;
  out.correct.assign(std::size(kPlaceTolerancesFrames), 0);
  const std::vector<double>& starts = dataset.session_start_times_s;
  if (starts.size() < 2 || dataset.images.empty()) return out;
  // By session: each image name's position among the session's images.
  std::vector<std::map<std::string, int64_t>> position(starts.size());
  std::vector<int64_t> count(starts.size(), 0);
  for (const ImageRow& row : dataset.images) {
    const size_t s = dataset.SessionAt(row.time_s);
    position[s].emplace(std::filesystem::path(row.file).filename().string(), count[s]++);
  }
  // Frames in time order pair with the image of the same time.
  struct Place {
    size_t session = 0;
    std::string name;
  };
  std::vector<std::optional<Place>> place_of(frames.size());
  for (size_t f = 0, i = 0; f < frames.size(); ++f) {
    while (i < dataset.images.size() && dataset.images[i].time_s < frames[f].time_s) ++i;
    if (i < dataset.images.size() && dataset.images[i].time_s == frames[f].time_s) {
      place_of[f] = Place{dataset.SessionAt(frames[f].time_s),
                          std::filesystem::path(dataset.images[i].file).filename().string()};
      ++i;
    }
  }
  // Every later image whose place an earlier session has counts, with a view or without one (a
  // blank frame gives none): a frame without a view is not matched.
  auto earlier_has = [&](size_t session, const std::string& name) {
    for (size_t s = 0; s < session; ++s) {
      if (position[s].count(name) > 0) return true;
    }
    return false;
  };
  for (const ImageRow& row : dataset.images) {
    const size_t s = dataset.SessionAt(row.time_s);
    out.frames += s > 0 && earlier_has(s, std::filesystem::path(row.file).filename().string());
  }
  std::map<uint32_t, size_t> made_by;  // template -> the frame that made it
  for (size_t f = 0; f < frames.size(); ++f) {
    if (frames[f].is_new) made_by.emplace(frames[f].template_id, f);
  }
  for (size_t f = 0; f < frames.size(); ++f) {
    if (!place_of[f] || place_of[f]->session == 0) continue;
    const Place& here = *place_of[f];
    if (!earlier_has(here.session, here.name)) continue;
    const auto made = made_by.find(frames[f].template_id);
    if (made == made_by.end() || !place_of[made->second]) continue;
    const Place& there = *place_of[made->second];
    if (there.session >= here.session) continue;
    ++out.matched;
    const auto namesake = position[there.session].find(here.name);
    if (namesake == position[there.session].end()) continue;
    const int64_t apart = std::abs(namesake->second - position[there.session].at(there.name));
    for (size_t k = 0; k < out.correct.size(); ++k) {
      out.correct[k] += apart <= kPlaceTolerancesFrames[k];
    }
  }
  return out;
}

std::vector<double> LocalisationErrors(const std::vector<LocalisationRecord>& records,
                                       const std::vector<GroundTruthRow>& ground_truth,
                                       std::vector<Point2>* truth,
                                       const std::vector<double>& session_starts) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> errors(records.size(), nan);
  std::vector<Point2> true_at(records.size(), {nan, nan});
  std::vector<Point2> estimate, paired_truth;
  for (size_t i = 0; i < records.size(); ++i) {
    const auto gt =
        dataset::InterpolateGroundTruth(ground_truth, records[i].time_s, session_starts);
    if (!gt) continue;
    true_at[i] = {gt->x_m, gt->y_m};
    if (records[i].lost) continue;
    estimate.push_back({records[i].x_m, records[i].y_m});
    paired_truth.push_back(true_at[i]);
  }
  // A rigid fit to a handful of frames fits them almost exactly whatever they are: no errors
  // from fewer than 10 (an IPIN log recognising 3 places would otherwise claim 0.09 m).
  constexpr size_t kLeastFramesToAlign = 10;
  if (estimate.size() < kLeastFramesToAlign) estimate.clear();
  if (const auto a = AlignRigid2D(estimate, paired_truth)) {
    for (size_t i = 0; i < records.size(); ++i) {
      if (records[i].lost || std::isnan(true_at[i].x)) continue;
      const Point2 p = Apply(*a, {records[i].x_m, records[i].y_m});
      errors[i] = std::hypot(p.x - true_at[i].x, p.y - true_at[i].y);
    }
  }
  if (truth) *truth = std::move(true_at);
  return errors;
}

namespace {

// What ground truth says about the run: the map's, trajectory's and odometry's ATE, and how far
// apart the true positions of every loop-closing template match are (a match to another floor
// infinitely far).
void ScoreAgainstGroundTruth(const fusion::ReplayPipeline& pipeline,
                             const dataset::Dataset& dataset, RunSummary* summary) {
  RunSummary& s = *summary;
  const fusion::ReplayPipeline::State& state = pipeline.state();
  const Ratslam& slam = pipeline.slam();
  const ExperienceMap& map = slam.experience_map();
  // The experience map: every experience against the true position at its creation.
  std::vector<Point2> estimate, truth;
  // (A localisation run's experiences were made on another data set's clock.)
  for (const Experience& e : map.experiences()) {
    if (pipeline.localising()) break;
    if (auto gt = dataset::GroundTruthAt(dataset, e.time_s)) {
      estimate.push_back({e.x_m, e.y_m});
      truth.push_back({gt->x_m, gt->y_m});
    }
  }
  if (auto a = AlignRigid2D(estimate, truth)) s.map_ate_m = a->rmse_m;
  // The corrected trajectory and raw odometry, at the times the TUM files hold (so evo on
  // trajectory_tum.txt and ground_truth_tum.txt reproduces these numbers).
  std::vector<Point2> corrected, odometry;
  truth.clear();
  for (size_t i = 0; i < state.trajectory.size(); ++i) {
    const TrajectoryRecord& r = state.trajectory[i];
    if (!InTumFiles(state.trajectory, i)) continue;
    if (auto gt = dataset::GroundTruthAt(dataset, r.time_s)) {
      double x, y, theta;
      RecordPose(map, r, &x, &y, &theta);
      corrected.push_back({x, y});
      odometry.push_back({r.odometry_x_m, r.odometry_y_m});
      truth.push_back({gt->x_m, gt->y_m});
    }
  }
  if (auto a = AlignRigid2D(corrected, truth)) s.trajectory_ate_m = a->rmse_m;
  if (auto a = AlignRigid2D(odometry, truth)) s.odometry_ate_m = a->rmse_m;
  s.ate_points = truth.size();

  // Every template match: how far is the true position now from the true position where the
  // matched template was stored? A match to another floor is a floor mistake, infinitely far
  // (a miss at every d, as in the localisation benchmark).
  const auto session_of = [&](double t) {
    size_t k = 0;
    while (k + 1 < dataset.session_start_times_s.size() &&
           t >= dataset.session_start_times_s[k + 1]) {
      ++k;
    }
    return k;
  };
  for (const FrameRecord& f : state.frames) {
    if (pipeline.localising()) break;    // templates stored on another data set's clock
    if (f.is_new || f.recent) continue;  // only matches that can close a loop
    const double created_s = slam.local_view().at(f.template_id).created_time_s;
    const auto now = dataset::GroundTruthAt(dataset, f.time_s);
    const auto then = dataset::GroundTruthAt(dataset, created_s);
    if (!now || !then) continue;
    ++s.evaluated_matches;
    // Floors are known only where the ground-truth points around a time agree. A match with
    // either end between points on different floors (on the stairs) cannot be judged: it is
    // counted as unverified and left out of the rates.
    const std::optional<int> floor_now = dataset::KnownFloorAt(dataset, f.time_s);
    const std::optional<int> floor_then = dataset::KnownFloorAt(dataset, created_s);
    if (!floor_now || !floor_then) {
      ++s.floor_unverified_matches;
      continue;
    }
    const bool other_floor = *floor_now != *floor_then;
    const double distance = other_floor ? std::numeric_limits<double>::infinity()
                                        : std::hypot(now->x_m - then->x_m, now->y_m - then->y_m);
    s.match_distances_m.push_back(distance);
    if (other_floor) ++s.floor_mistakes;
    if (session_of(f.time_s) != session_of(slam.local_view().at(f.template_id).created_time_s)) {
      s.cross_session_distances_m.push_back(distance);
    }
  }
}

// The front end's counts and reports: frames by decision source, FABMAP's Wi-Fi learning, RSSI
// offsets, revisit updates and the barometer.
void AddFrontEndReports(const fusion::ReplayPipeline& pipeline, nlohmann::ordered_json* json) {
  nlohmann::ordered_json& j = *json;
  const fusion::ReplayPipeline::State& state = pipeline.state();
  size_t by_source[3] = {0, 0, 0};
  size_t recent = 0;
  for (const FrameRecord& f : state.frames) {
    ++by_source[static_cast<int>(f.source)];
    recent += f.recent;
  }
  j["frames_by_source"] = {{"camera", by_source[0]},
                           {"wifi", by_source[1]},
                           {"new", by_source[2]},
                           {"recent_reuse", recent}};
  if (const auto learning = pipeline.fabmap_learning()) {
    // Whether the Wi-Fi model saw the future (whole data set) or only the past (online).
    j["fabmap_wifi_learning"] = ToString(learning->wifi_learning);
    j["fabmap_wifi_learned_from_scans"] = learning->wifi_learned_from_scans;
    j["fabmap_wifi_models_built"] = learning->wifi_relearnt;
    j["fabmap_wifi_tree_scans"] = learning->wifi_tree_scans;
    if (learning->earlier_session_log_odds) {
      j["fabmap_earlier_session_log_odds"] = *learning->earlier_session_log_odds;
    }
    if (learning->verified_revisits) {
      j["fabmap_verified_revisits"] = *learning->verified_revisits;
    }
    if (learning->calibrated) j["fabmap_calibrated"] = *learning->calibrated;
  }
  if (const std::vector<double> offsets = pipeline.rssi_offsets_db(); !offsets.empty()) {
    j["wifi_rssi_offsets_db"] = offsets;  // removed from each session's scans
  }
  if (const auto updates = pipeline.revisit_ap_updates()) {
    j["wifi_revisit_aps_added"] = updates->first;
    j["wifi_revisit_aps_dropped"] = updates->second;
  }
  if (const std::optional<fusion::FloorReport> floors = pipeline.floor_report()) {
    j["barometer"] = {{"pressure_readings", floors->pressure_readings},
                      {"floor_changes", floors->floor_changes},
                      {"frames_floor_unknown", floors->frames_floor_unknown},
                      {"new_templates_by_floor_rule", floors->new_templates_by_floor_rule},
                      {"templates_with_floor", floors->templates_with_floor},
                      {"floor_offset_changes", floors->floor_offset_changes},
                      {"session_floor_offsets", floors->session_floor_offsets}};
  }
}

// Cross-session place recognition scored by frame (absent when no frame can be scored).
void AddCrossSessionPlaces(const fusion::ReplayPipeline& pipeline, const dataset::Dataset& dataset,
                           nlohmann::ordered_json* json) {
  nlohmann::ordered_json& j = *json;
  const fusion::ReplayPipeline::State& state = pipeline.state();
  if (const CrossSessionPlaces places = ScoreCrossSessionPlaces(state.frames, dataset);
      places.frames > 0) {
    const auto share = [](size_t n, size_t of) {
      return of == 0 ? 0.0 : static_cast<double>(n) / static_cast<double>(of);
    };
    nlohmann::ordered_json p, correct, wrong, precision;
    p["frames"] = places.frames;
    p["matched"] = places.matched;
    p["matched_share"] = share(places.matched, places.frames);
    for (size_t k = 0; k < places.correct.size(); ++k) {
      const std::string n = std::to_string(kPlaceTolerancesFrames[k]);
      correct[n] = share(places.correct[k], places.frames);
      wrong[n] = share(places.matched - places.correct[k], places.frames);
      precision[n] = share(places.correct[k], places.matched);
    }
    p["correct_share_within_frames"] = correct;
    p["wrong_share_within_frames"] = wrong;
    p["precision_within_frames"] = precision;
    j["cross_session_places"] = p;
  }
}

// A localisation run on a saved map: lost frames, recognitions and, with ground truth, errors.
nlohmann::ordered_json LocalisationJson(const fusion::ReplayPipeline& pipeline,
                                        const dataset::Dataset& dataset, const RunInfo& info,
                                        RunSummary* summary) {
  RunSummary& s = *summary;
  const Ratslam& slam = pipeline.slam();
  const std::vector<LocalisationRecord>& records = pipeline.localisation();
  size_t lost = 0;
  std::vector<uint32_t> visited;
  for (const LocalisationRecord& r : records) {
    lost += r.lost;
    if (r.experience_id >= 0) visited.push_back(static_cast<uint32_t>(r.experience_id));
  }
  std::sort(visited.begin(), visited.end());
  visited.erase(std::unique(visited.begin(), visited.end()), visited.end());
  s.lost_fraction =
      records.empty() ? 1.0 : static_cast<double>(lost) / static_cast<double>(records.size());
  nlohmann::ordered_json l;
  l["map"] = info.localised_on;
  l["frames"] = records.size();
  l["lost_fraction"] = *s.lost_fraction;
  l["lost_after_m"] = info.lost_after_m;
  l["recognitions"] = slam.localisation_counters().recognitions;
  l["relocalisations"] = slam.localisation_counters().relocalisations;
  l["experiences_recognised"] = visited.size();
  l["unmapped_views"] = slam.localisation_counters().unmapped_views;
  if (!dataset.ground_truth.empty()) {
    s.localisation_errors_m =
        LocalisationErrors(records, dataset.ground_truth, nullptr, dataset.session_start_times_s);
    std::vector<double> known;
    for (double e : s.localisation_errors_m) {
      if (!std::isnan(e)) known.push_back(e);
    }
    l["error_points"] = known.size();
    if (!known.empty()) {
      std::nth_element(known.begin(), known.begin() + known.size() / 2, known.end());
      s.localisation_median_error_m = known[known.size() / 2];
      l["median_error_m"] = *s.localisation_median_error_m;
      l["error_alignment"] = "rigid least-squares fit of the frames not lost to ground truth";
    }
  }
  return l;
}

}  // namespace

RunSummary Summarise(const fusion::ReplayPipeline& pipeline, const dataset::Dataset& dataset,
                     const RunInfo& info) {
  const fusion::ReplayPipeline::State& state = pipeline.state();
  const Ratslam& slam = pipeline.slam();
  const ExperienceMap& map = slam.experience_map();
  RunSummary s;
  s.frames = state.frames.size();
  s.templates = slam.local_view().size();
  s.experiences = map.num_experiences();
  s.links = map.num_links();
  s.loop_closures = slam.counters().loop_closures;

  if (!dataset.ground_truth.empty()) ScoreAgainstGroundTruth(pipeline, dataset, &s);

  nlohmann::ordered_json j;
  j["dataset"] = dataset.name;
  if (!dataset.folder.empty()) j["data_folder"] = info.provenance.Recorded(dataset.folder);
  // Malformed phone-log lines that --lenient skipped (absent: none).
  if (dataset.skipped_malformed_lines > 0) {
    j["skipped_malformed_lines"] = dataset.skipped_malformed_lines;
  }
  j["frames"] = s.frames;
  j["templates"] = s.templates;
  j["experiences"] = s.experiences;
  // Where the robot is at the end (the experience map's current experience, after the last
  // odometry step; frames.csv's last row may predate it). Absent before the first experience.
  if (map.current()) j["current_experience"] = *map.current();
  j["links"] = s.links;
  j["loop_closures"] = s.loop_closures;
  if (map.options().relaxation_scheme == RelaxationScheme::kIncremental) {
    j["relaxation_capped_passes"] = map.relaxation_capped_passes();
  }
  if (map.options().relaxation_scheme != RelaxationScheme::kLeastSquares) {
    j["relaxation_link_updates"] = map.relaxation_link_updates();
  }
  j["odometry_steps"] = state.trajectory.size();
  j["view_injections"] = slam.counters().injections;
  j["refused_ambiguous_links"] = slam.counters().refused_ambiguous;
  j["wifi_scans"] = state.wifi_scans_seen;
  j["compass_readings"] = state.compass_readings_seen;
  j["images_unused"] = state.images_skipped;
  AddFrontEndReports(pipeline, &j);
  if (dataset.session_start_times_s.size() > 1) {
    j["sessions"] = dataset.session_start_times_s.size();
    std::vector<std::string> names;
    for (size_t i = 0; i < dataset.session_start_times_s.size(); ++i) {
      names.push_back(dataset.SessionName(i));
    }
    j["session_names"] = names;
  }
  if (pipeline.wifi_sequence().options().enabled) {
    j["wifi_sequence"] = SequenceSummary(pipeline.wifi_sequence(), map, dataset);
  }
  AddCrossSessionPlaces(pipeline, dataset, &j);
  j["events_done"] = state.next_event;
  j["events_total"] = state.events_total;
  j["finished"] = pipeline.finished();
  j["interrupted"] = info.interrupted;
  j["data_time_s"] = state.trajectory.empty() ? 0.0 : state.trajectory.back().time_s;
  j["wall_seconds"] = info.wall_seconds;
  if (info.calibration_wall_seconds) j["calibration_wall_seconds"] = *info.calibration_wall_seconds;
  j["frames_per_second"] =
      info.wall_seconds > 0 ? static_cast<double>(info.frames_this_run) / info.wall_seconds : 0.0;
  j["config"] = info.config_path.empty() ? "(defaults)" : info.config_path;
  j["config_fingerprint"] = FingerprintHex(info.config_fingerprint);
  if (!info.resumed_from.empty()) j["resumed_from"] = info.resumed_from;
  if (pipeline.localising()) j["localisation"] = LocalisationJson(pipeline, dataset, info, &s);
  // A replay draws no random number outside its configuration's own seeds.
  j["run"] = RunObject(info.provenance, info.inputs, std::nullopt, info.config_fingerprint);
  if (s.map_ate_m) j["map_ate_m"] = *s.map_ate_m;
  if (s.trajectory_ate_m) j["trajectory_ate_m"] = *s.trajectory_ate_m;
  if (s.odometry_ate_m) j["odometry_ate_m"] = *s.odometry_ate_m;
  if (s.ate_points) j["ate_points"] = s.ate_points;
  if (!dataset.ground_truth.empty() && !pipeline.localising()) {
    j["matches"] = s.evaluated_matches;
    j["match_rate_within_m"] = RatesWithin(s.match_distances_m);
    j["floor_mistakes"] = s.floor_mistakes;
    j["floor_unverified_matches"] = s.floor_unverified_matches;
    if (dataset.session_start_times_s.size() > 1) {
      j["cross_session_matches"] = s.cross_session_distances_m.size();
      j["cross_session_match_rate_within_m"] = RatesWithin(s.cross_session_distances_m);
    }
  }
  s.json = j.dump(2) + "\n";
  return s;
}

const std::vector<std::string>& SummaryKeys() {
  static const std::vector<std::string> keys = {"ate_points",
                                                "barometer",
                                                "calibration_wall_seconds",
                                                "compass_readings",
                                                "config",
                                                "config_fingerprint",
                                                "cross_session_match_rate_within_m",
                                                "cross_session_matches",
                                                "cross_session_places",
                                                "current_experience",
                                                "data_folder",
                                                "data_time_s",
                                                "dataset",
                                                "events_done",
                                                "events_total",
                                                "experiences",
                                                "fabmap_calibrated",
                                                "fabmap_earlier_session_log_odds",
                                                "fabmap_verified_revisits",
                                                "fabmap_wifi_learned_from_scans",
                                                "fabmap_wifi_learning",
                                                "fabmap_wifi_models_built",
                                                "fabmap_wifi_tree_scans",
                                                "finished",
                                                "floor_mistakes",
                                                "floor_unverified_matches",
                                                "frames",
                                                "frames_by_source",
                                                "frames_per_second",
                                                "images_unused",
                                                "interrupted",
                                                "links",
                                                "localisation",
                                                "loop_closures",
                                                "map_ate_m",
                                                "match_rate_within_m",
                                                "matches",
                                                "odometry_ate_m",
                                                "odometry_steps",
                                                "refused_ambiguous_links",
                                                "relaxation_capped_passes",
                                                "relaxation_link_updates",
                                                "resumed_from",
                                                "run",
                                                "session_names",
                                                "sessions",
                                                "skipped_malformed_lines",
                                                "templates",
                                                "trajectory_ate_m",
                                                "view_injections",
                                                "wall_seconds",
                                                "wifi_revisit_aps_added",
                                                "wifi_revisit_aps_dropped",
                                                "wifi_rssi_offsets_db",
                                                "wifi_scans",
                                                "wifi_sequence"};
  return keys;
}

StatusOr<RunSummary> WriteRunOutputs(OutputFolder& folder, const fusion::ReplayPipeline& pipeline,
                                     const dataset::Dataset& dataset, const RunInfo& info) {
  const ExperienceMap& map = pipeline.slam().experience_map();
  const fusion::ReplayPipeline::State& state = pipeline.state();
  std::vector<std::pair<std::string, std::string>> files;

  std::ostringstream experiences;
  experiences << kExperienceColumns.Header();
  for (const Experience& e : map.experiences()) {
    experiences << e.id << ',' << Num(e.x_m) << ',' << Num(e.y_m) << ',' << Num(e.theta_rad) << ','
                << e.template_id << ',' << Num(e.time_s) << ',' << Num(e.pose_cells.x) << ','
                << Num(e.pose_cells.y) << ',' << Num(e.pose_cells.theta) << ',';
    if (const std::optional<int> floor = pipeline.template_floor(e.template_id)) {
      experiences << *floor;
    }
    experiences << '\n';
  }
  files.emplace_back("experiences.csv", experiences.str());

  std::ostringstream links;
  links << kLinkColumns.Header();
  for (const Link& l : map.links()) {
    links << l.id << ',' << l.from << ',' << l.to << ',' << Num(l.distance_m) << ','
          << Num(l.heading_rad) << ',' << Num(l.facing_rad) << ',' << Num(l.duration_s) << ','
          << (l.loop_closure ? 1 : 0) << ',' << LinkKindName(l.loop_closure, l.wifi_sequence)
          << '\n';
  }
  files.emplace_back("links.csv", links.str());

  std::ostringstream trajectory, odometry, ground_truth;
  trajectory << "# timestamp tx ty tz qx qy qz qw (experience map, final relaxation)\n";
  odometry << "# timestamp tx ty tz qx qy qz qw (raw odometry)\n";
  ground_truth << "# timestamp tx ty tz qx qy qz qw (ground truth, interpolated at the "
                  "trajectory's stamps where it covers them; not aligned)\n";
  for (size_t i = 0; i < state.trajectory.size(); ++i) {
    const TrajectoryRecord& r = state.trajectory[i];
    if (!InTumFiles(state.trajectory, i)) continue;
    double x, y, theta;
    RecordPose(map, r, &x, &y, &theta);
    trajectory << TumLine(r.time_s, x, y, theta);
    odometry << TumLine(r.time_s, r.odometry_x_m, r.odometry_y_m, r.odometry_theta_rad);
    if (auto gt = dataset::GroundTruthAt(dataset, r.time_s)) {
      ground_truth << TumLine(r.time_s, gt->x_m, gt->y_m, gt->theta_rad);
    }
  }
  files.emplace_back("trajectory_tum.txt", trajectory.str());
  files.emplace_back("odometry_tum.txt", odometry.str());
  if (!dataset.ground_truth.empty()) {
    files.emplace_back("ground_truth_tum.txt", ground_truth.str());
  }

  // g2o: poses, the first one fixed (the gauge: without it an optimiser may move the whole map),
  // and each link as a relative pose in its source's frame, with the information matrix of the
  // configured link noise (experience_map.link_sigma_*), the one least_squares relaxation uses.
  std::ostringstream g2o;
  for (const Experience& e : map.experiences()) {
    g2o << "VERTEX_SE2 " << e.id << ' ' << Num(e.x_m) << ' ' << Num(e.y_m) << ' '
        << Num(e.theta_rad) << '\n';
  }
  if (!map.experiences().empty()) g2o << "FIX 0\n";
  const LinkNoise noise = map.options().Noise();
  for (const Link& l : map.links()) {
    // g2o skips comment lines; they say which edges closed loops (RatSLAM's own, or Wi-Fi
    // sequence loop closure's); the others are odometry.
    if (l.wifi_sequence) {
      g2o << "# wifi_sequence link " << l.id << '\n';
    } else if (l.loop_closure) {
      g2o << "# loop_closure link " << l.id << '\n';
    }
    g2o << "EDGE_SE2 " << l.from << ' ' << l.to << ' '
        << Num(l.distance_m * std::cos(l.heading_rad)) << ' '
        << Num(l.distance_m * std::sin(l.heading_rad)) << ' ' << Num(l.facing_rad);
    for (double v : noise.Information(l.distance_m)) g2o << ' ' << Num(v);
    g2o << '\n';
  }
  files.emplace_back("experience_map.g2o", g2o.str());

  std::ostringstream frames;
  frames << kFrameColumns.Header();
  for (const FrameRecord& f : state.frames) {
    frames << Num(f.time_s) << ',' << f.template_id << ',' << (f.is_new ? 1 : 0) << ','
           << f.experience_id << ',' << ToString(f.source) << ',' << (f.recent ? 1 : 0) << '\n';
  }
  files.emplace_back("frames.csv", frames.str());

  if (pipeline.wifi_sequence().options().enabled) {
    // Every correspondence of every loop matched, with the scans' times and map positions.
    const wifi_sequence::WifiSequenceLoopCloser& closer = pipeline.wifi_sequence();
    std::ostringstream loops;
    loops << "loop_id,matched_time_s,accepted,current_pose,past_pose,current_time_s,"
             "past_time_s,similarity,inlier,residual_m,current_x_m,current_y_m,past_x_m,past_y_m\n";
    for (const wifi_sequence::SequenceLoop& l : closer.loops()) {
      for (const wifi_sequence::SequenceCorrespondence& c : l.correspondences) {
        const Pose2 now = pipeline.MapPose(closer.pose(c.current_pose));
        const Pose2 then = pipeline.MapPose(closer.pose(c.past_pose));
        loops << l.id << ',' << Num(l.time_s) << ',' << (l.accepted ? 1 : 0) << ','
              << c.current_pose << ',' << c.past_pose << ','
              << Num(closer.pose(c.current_pose).time_s) << ','
              << Num(closer.pose(c.past_pose).time_s) << ',' << Num(c.similarity) << ','
              << (c.inlier ? 1 : 0) << ',' << Num(c.residual_m) << ',' << Num(now.x_m) << ','
              << Num(now.y_m) << ',' << Num(then.x_m) << ',' << Num(then.y_m) << '\n';
      }
    }
    files.emplace_back("wifi_sequence_loops.csv", loops.str());
  }

  RunSummary summary = Summarise(pipeline, dataset, info);
  if (pipeline.localising()) {
    std::vector<Point2> truth;
    const std::vector<LocalisationRecord>& records = pipeline.localisation();
    const std::vector<double> errors =
        LocalisationErrors(records, dataset.ground_truth, &truth, dataset.session_start_times_s);
    std::ostringstream localisation;
    localisation << kLocalisationColumns.Header();
    for (size_t i = 0; i < records.size(); ++i) {
      const LocalisationRecord& r = records[i];
      localisation << Num(r.time_s) << ',' << r.experience_id << ',' << (r.lost ? 1 : 0) << ','
                   << Num(r.x_m) << ',' << Num(r.y_m) << ',' << Num(r.theta_rad) << ',';
      if (!std::isnan(truth[i].x))
        localisation << Num(truth[i].x) << ',' << Num(truth[i].y);
      else
        localisation << ',';
      localisation << ',';
      if (!std::isnan(errors[i])) localisation << Num(errors[i]);
      localisation << '\n';
    }
    files.emplace_back("localisation.csv", localisation.str());
  }
  files.emplace_back("summary.json", summary.json);
  // All or nothing: a full disk leaves the previous run's complete set, not a mix.
  RATSLAM_RETURN_IF_ERROR(folder.Write(files));
  return summary;
}

}  // namespace ratslam::io
