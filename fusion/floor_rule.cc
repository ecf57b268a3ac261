#include "fusion/floor_rule.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ratslam::fusion::front_end_internal {

FloorRule::FloorRule(const FloorOptions& options) : options_(options), tracker_(options.tracker) {
  std::string error;
  if (!options_.IsValid(&error)) throw std::invalid_argument("[barometer] " + error);
}

Status FloorRule::OnPressure(double time_s, double pressure_hpa) {
  if (!enabled()) return Status::Ok();
  StatusOr<sensors::FloorEstimate> e = tracker_.Add({time_s, pressure_hpa});
  if (!e.ok()) return e.status();
  ++pressure_readings_;
  // Before the first dwell a session is on its first level (level 0): walks start standing.
  level_ = e->in_transit ? kUnknown : std::max(e->level, 0);
  // Level floors, renumbered only when a level is added (level 0, floor 0, from the start).
  std::vector<int32_t>& floors = level_floors_[session_];
  if (floors.size() != std::max<size_t>(tracker_.levels(), 1)) {
    const std::vector<int> now = tracker_.LevelFloors();
    floors.assign(now.begin(), now.end());
    if (floors.empty()) floors.push_back(0);
  }
  return Status::Ok();
}

void FloorRule::OnSessionStart(double start_s) {
  if (!enabled() || session_start_s_ == start_s) return;
  if (session_start_s_) NewSession();
  session_start_s_ = start_s;
}

void FloorRule::SettleForLocalisation() {
  if (!enabled()) return;
  NewSession();
  session_start_s_.reset();
}

void FloorRule::NewSession() {
  floor_changes_before_ += tracker_.floor_changes();
  tracker_ = sensors::BarometricFloorTracker(options_.tracker);
  ++session_;
  level_floors_.emplace_back();
  offsets_.push_back(0);
  votes_.clear();
  level_ = kNoBarometer;
}

bool FloorRule::Agrees(uint32_t t) const {
  const int32_t level = template_level_[t];
  if (level_ == kNoBarometer || level == kNoBarometer) return true;
  if (level_ == kUnknown || level == kUnknown) return false;
  const uint32_t session = template_session_[t];
  if (session == session_) return level == level_;
  return MapFloor(session, level) == MapFloor(session_, level_);
}

std::vector<uint8_t> FloorRule::BeginFrame(uint32_t templates) {
  if (level_ == kUnknown) ++frames_unknown_;
  std::vector<uint8_t> agrees(templates, 1);
  for (uint32_t t = 0; t < templates && t < template_level_.size(); ++t) agrees[t] = Agrees(t);
  return agrees;
}

bool FloorRule::VoteCandidates(std::vector<uint8_t>* candidates) const {
  if (level_ < 0) return false;
  candidates->assign(template_level_.size(), 0);
  bool any = false;
  for (size_t t = 0; t < candidates->size(); ++t) {
    (*candidates)[t] = template_level_[t] >= 0 && template_session_[t] != session_;
    any |= (*candidates)[t] != 0;
  }
  return any;
}

void FloorRule::CountVote(uint32_t template_id) {
  votes_.insert(votes_.end(), {static_cast<int32_t>(template_session_[template_id]),
                               template_level_[template_id], level_});
  // This session's votes under today's offsets and level numbers (levels may be renumbered):
  // the matched template's floor minus ours.
  std::vector<std::pair<int, int>> counts = {{0, 0}};  // (value, votes)
  for (size_t v = 0; v < votes_.size(); v += 3) {
    const int value = MapFloor(static_cast<uint32_t>(votes_[v]), votes_[v + 1]) -
                      MapFloor(session_, votes_[v + 2]);
    auto it = std::find_if(counts.begin(), counts.end(),
                           [value](const auto& c) { return c.first == value; });
    if (it == counts.end()) {
      counts.emplace_back(value, 1);
    } else {
      ++it->second;
    }
  }
  std::sort(counts.begin(), counts.end(), [](const auto& a, const auto& b) {
    return a.second != b.second ? a.second > b.second : a.first < b.first;
  });
  const int runner_up = counts.size() > 1 ? counts[1].second : 0;
  if (counts[0].first != 0 && counts[0].second - runner_up >= options_.floor_offset_min_votes) {
    offsets_[session_] += counts[0].first;
    ++offset_changes_;
  }
}

void FloorRule::AddTemplate() {
  if (!enabled()) return;
  template_session_.push_back(session_);
  template_level_.push_back(level_);
}

std::optional<int> FloorRule::TemplateFloor(uint32_t id) const {
  if (id >= template_level_.size() || template_level_[id] < 0) return std::nullopt;
  return MapFloor(template_session_[id], template_level_[id]);
}

std::optional<FloorReport> FloorRule::Report() const {
  if (!active()) return std::nullopt;
  FloorReport r;
  r.pressure_readings = pressure_readings_;
  r.floor_changes = floor_changes_before_ + tracker_.floor_changes();
  r.frames_floor_unknown = frames_unknown_;
  r.new_templates_by_floor_rule = refused_;
  r.templates_with_floor = static_cast<uint64_t>(std::count_if(
      template_level_.begin(), template_level_.end(), [](int32_t l) { return l >= 0; }));
  r.session_floor_offsets.assign(offsets_.begin(), offsets_.end());
  r.floor_offset_changes = offset_changes_;
  return r;
}

void FloorRule::Encode(ByteWriter* w) const {
  if (!enabled()) return;  // states without floors keep the format of earlier releases
  tracker_.Encode(w);
  w->Pod(pressure_readings_);
  w->Pod(floor_changes_before_);
  w->Pod(level_);
  w->Pod(session_);
  w->Optional(session_start_s_);
  w->Count(level_floors_.size());
  for (const auto& floors : level_floors_) w->PodVector(floors);
  w->PodVector(offsets_);
  w->PodVector(votes_);
  w->Pod(offset_changes_);
  w->PodVector(template_session_);
  w->PodVector(template_level_);
  w->Pod(frames_unknown_);
  w->Pod(refused_);
}

bool FloorRule::Decode(ByteReader* r, size_t templates) {
  if (!enabled()) return true;
  FloorRule f(options_);
  size_t n = 0;
  if (!(f.tracker_.Decode(r) && r->Pod(&f.pressure_readings_) && r->Pod(&f.floor_changes_before_) &&
        r->Pod(&f.level_) && r->Pod(&f.session_) && r->Optional(&f.session_start_s_) &&
        r->Count(8, &n))) {
    return false;
  }
  f.level_floors_.resize(n);
  for (auto& floors : f.level_floors_) {
    if (!r->PodVector(&floors)) return false;
  }
  if (!(r->PodVector(&f.offsets_) && r->PodVector(&f.votes_) && r->Pod(&f.offset_changes_) &&
        r->PodVector(&f.template_session_) && r->PodVector(&f.template_level_) &&
        r->Pod(&f.frames_unknown_) && r->Pod(&f.refused_))) {
    return false;
  }
  // Every index within what it indexes; the current session the last; the first at offset 0.
  auto level_ok = [&](uint32_t session, int32_t level) {
    return level == kNoBarometer || level == kUnknown ||
           (level >= 0 && static_cast<size_t>(level) < f.level_floors_[session].size());
  };
  if (n == 0 || f.session_ != n - 1 || f.offsets_.size() != n || f.offsets_[0] != 0 ||
      f.votes_.size() % 3 != 0 || f.template_session_.size() != templates ||
      f.template_level_.size() != templates || !level_ok(f.session_, f.level_) ||
      (f.session_start_s_ && !std::isfinite(*f.session_start_s_)) ||
      (f.tracker_.levels() > 0 ? f.level_floors_[f.session_].size() != f.tracker_.levels()
                               : f.level_floors_[f.session_].size() > 1)) {
    return r->Fail("floors do not fit together");
  }
  for (size_t t = 0; t < templates; ++t) {
    if (f.template_session_[t] >= n || !level_ok(f.template_session_[t], f.template_level_[t])) {
      return r->Fail("a template's floor names an unknown session or level");
    }
  }
  for (size_t v = 0; v < f.votes_.size(); v += 3) {
    const int32_t session = f.votes_[v], level = f.votes_[v + 1], ours = f.votes_[v + 2];
    if (session < 0 || static_cast<uint32_t>(session) >= f.session_ || level < 0 ||
        !level_ok(static_cast<uint32_t>(session), level) || ours < 0 ||
        !level_ok(f.session_, ours)) {
      return r->Fail("a floor vote names no level");
    }
  }
  for (const auto& floors : f.level_floors_) {
    for (int32_t floor : floors) {
      if (floor < -100000 || floor > 100000) return r->Fail("a floor number is out of range");
    }
  }
  for (int32_t o : f.offsets_) {
    if (o < -100000 || o > 100000) return r->Fail("a floor offset is out of range");
  }
  *this = std::move(f);
  return true;
}

}  // namespace ratslam::fusion::front_end_internal
