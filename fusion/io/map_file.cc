#include "fusion/io/map_file.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <type_traits>

#include "fusion/io/file_util.h"
#include "ratslam/byte_buffer.h"

namespace ratslam {
namespace {

constexpr char kMagic[8] = {'R', 'S', 'L', 'M', 'A', 'P', '\0', '\1'};
constexpr uint32_t kVersion = 2;

// Field lists, shared by encoding and decoding through overloads on Writer / Reader.
void Field(ByteWriter& w, const PoseCellPosition& p) {
  w.Pod(p.x);
  w.Pod(p.y);
  w.Pod(p.theta);
}
bool Field(ByteReader& r, PoseCellPosition* p) {
  return r.Pod(&p->x) && r.Pod(&p->y) && r.Pod(&p->theta);
}

void Field(ByteWriter& w, const LocalOffset& o) {
  w.Pod(o.forward_m);
  w.Pod(o.left_m);
  w.Pod(o.facing_rad);
}
bool Field(ByteReader& r, LocalOffset* o) {
  return r.Pod(&o->forward_m) && r.Pod(&o->left_m) && r.Pod(&o->facing_rad);
}

void Encode(ByteWriter& w, const ReplayPipeline::State& s) {
  // Pose cells.
  const PoseCellNetwork::State& pc = s.ratslam.pose_cells;
  w.PodVector(pc.active_indices);
  w.PodVector(pc.active_values);
  w.PodVector(pc.residual_x_cells);
  w.PodVector(pc.residual_y_cells);
  w.Pod(pc.residual_theta_cells);
  // Local view cells.
  const LocalViewCells::State& lv = s.ratslam.local_view;
  w.Pod(lv.frame);
  w.Count(lv.templates.size());
  for (const ViewTemplate& t : lv.templates) {
    w.Pod(t.id);
    Field(w, t.pose_cells);
    w.Pod(t.created_time_s);
    w.Pod(t.decay);
    w.Pod(t.decay_frame);
    w.Pod(t.match_count);
    w.PodVector(t.experience_ids);
  }
  // Experience map.
  const ExperienceMap::State& em = s.ratslam.experience_map;
  w.Count(em.experiences.size());
  for (const Experience& e : em.experiences) {
    w.Pod(e.id);
    w.Pod(e.x_m);
    w.Pod(e.y_m);
    w.Pod(e.theta_rad);
    w.Pod(e.template_id);
    Field(w, e.pose_cells);
    w.Pod(e.time_s);
    w.Optional(e.compass_heading_rad);
    w.PodVector(e.link_ids);
  }
  w.Count(em.links.size());
  for (const Link& l : em.links) {
    w.Pod(l.id);
    w.Pod(l.from);
    w.Pod(l.to);
    w.Pod(l.distance_m);
    w.Pod(l.heading_rad);
    w.Pod(l.facing_rad);
    w.Pod(l.duration_s);
    w.Bool(l.loop_closure);
  }
  w.Bool(em.current.has_value());
  w.Pod(em.current.value_or(0));
  Field(w, em.offset);
  w.Pod(em.offset_start_time_s);
  // Spine.
  w.Bool(s.ratslam.current_template.has_value());
  w.Pod(s.ratslam.current_template.value_or(0));
  w.Pod(s.ratslam.counters);
  w.Optional(s.ratslam.compass_heading_rad);
  // The front end's own state.
  w.String(s.front_end);
  // Pipeline.
  w.Pod(s.next_event);
  w.Pod(s.events_total);
  w.Pod(s.last_odometry_time_s);
  w.Bool(s.have_odometry);
  w.Pod(s.odometry_x_m);
  w.Pod(s.odometry_y_m);
  w.Pod(s.odometry_theta_rad);
  w.Count(s.trajectory.size());
  for (const TrajectoryRecord& t : s.trajectory) {
    w.Pod(t.time_s);
    w.Pod(t.experience_id);
    Field(w, t.offset);
    w.Pod(t.odometry_x_m);
    w.Pod(t.odometry_y_m);
    w.Pod(t.odometry_theta_rad);
  }
  w.Count(s.frames.size());
  for (const FrameRecord& f : s.frames) {
    w.Pod(f.time_s);
    w.Pod(f.template_id);
    w.Bool(f.is_new);
    w.Pod(f.experience_id);
    w.Pod(f.source);
    w.Bool(f.recent);
  }
  w.Pod(s.wifi_scans_seen);
  w.Pod(s.compass_readings_seen);
  w.Pod(s.images_skipped);
}

bool Decode(ByteReader& r, ReplayPipeline::State* s) {
  PoseCellNetwork::State& pc = s->ratslam.pose_cells;
  if (!(r.PodVector(&pc.active_indices) && r.PodVector(&pc.active_values) &&
        r.PodVector(&pc.residual_x_cells) && r.PodVector(&pc.residual_y_cells) &&
        r.Pod(&pc.residual_theta_cells))) {
    return false;
  }
  LocalViewCells::State& lv = s->ratslam.local_view;
  size_t n = 0;
  if (!(r.Pod(&lv.frame) && r.Count(8, &n))) return false;
  lv.templates.resize(n);
  for (ViewTemplate& t : lv.templates) {
    if (!(r.Pod(&t.id) && Field(r, &t.pose_cells) && r.Pod(&t.created_time_s) && r.Pod(&t.decay) &&
          r.Pod(&t.decay_frame) && r.Pod(&t.match_count) && r.PodVector(&t.experience_ids))) {
      return false;
    }
  }
  ExperienceMap::State& em = s->ratslam.experience_map;
  if (!r.Count(8, &n)) return false;
  em.experiences.resize(n);
  for (Experience& e : em.experiences) {
    if (!(r.Pod(&e.id) && r.Pod(&e.x_m) && r.Pod(&e.y_m) && r.Pod(&e.theta_rad) &&
          r.Pod(&e.template_id) && Field(r, &e.pose_cells) && r.Pod(&e.time_s) &&
          r.Optional(&e.compass_heading_rad) && r.PodVector(&e.link_ids))) {
      return false;
    }
  }
  if (!r.Count(8, &n)) return false;
  em.links.resize(n);
  for (Link& l : em.links) {
    if (!(r.Pod(&l.id) && r.Pod(&l.from) && r.Pod(&l.to) && r.Pod(&l.distance_m) &&
          r.Pod(&l.heading_rad) && r.Pod(&l.facing_rad) && r.Pod(&l.duration_s) &&
          r.Bool(&l.loop_closure))) {
      return false;
    }
  }
  bool has = false;
  uint32_t id = 0;
  if (!(r.Bool(&has) && r.Pod(&id))) return false;
  if (has) em.current = id;
  if (!(Field(r, &em.offset) && r.Pod(&em.offset_start_time_s))) return false;
  if (!(r.Bool(&has) && r.Pod(&id))) return false;
  if (has) s->ratslam.current_template = id;
  if (!(r.Pod(&s->ratslam.counters) && r.Optional(&s->ratslam.compass_heading_rad) &&
        r.String(&s->front_end))) {
    return false;
  }
  if (!(r.Pod(&s->next_event) && r.Pod(&s->events_total) && r.Pod(&s->last_odometry_time_s) &&
        r.Bool(&s->have_odometry) && r.Pod(&s->odometry_x_m) && r.Pod(&s->odometry_y_m) &&
        r.Pod(&s->odometry_theta_rad) && r.Count(8, &n))) {
    return false;
  }
  s->trajectory.resize(n);
  for (TrajectoryRecord& t : s->trajectory) {
    if (!(r.Pod(&t.time_s) && r.Pod(&t.experience_id) && Field(r, &t.offset) &&
          r.Pod(&t.odometry_x_m) && r.Pod(&t.odometry_y_m) && r.Pod(&t.odometry_theta_rad))) {
      return false;
    }
  }
  if (!r.Count(8, &n)) return false;
  s->frames.resize(n);
  for (FrameRecord& f : s->frames) {
    if (!(r.Pod(&f.time_s) && r.Pod(&f.template_id) && r.Bool(&f.is_new) &&
          r.Pod(&f.experience_id) && r.Pod(&f.source) && r.Bool(&f.recent))) {
      return false;
    }
    if (static_cast<uint8_t>(f.source) > 2) return r.Fail("invalid decision source");
  }
  return r.Pod(&s->wifi_scans_seen) && r.Pod(&s->compass_readings_seen) &&
         r.Pod(&s->images_skipped);
}

}  // namespace

std::string EncodeMapFile(const MapFile& map) {
  ByteWriter w;
  w.bytes().append(kMagic, sizeof kMagic);
  w.Pod(kVersion);
  w.Pod(map.config_fingerprint);
  w.String(map.dataset_name);
  Encode(w, map.state);
  return std::move(w.bytes());
}

StatusOr<MapFile> DecodeMapFile(const std::string& bytes, const std::string& source) {
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) {
    return Status::Error(source + ": not a RatSLAM map file");
  }
  const std::string body = bytes.substr(sizeof kMagic);
  ByteReader r(body, source + ": corrupt map file");
  uint32_t version = 0;
  MapFile map;
  if (!r.Pod(&version)) return Status::Error(r.error());
  if (version != kVersion) {
    return Status::Error(source + ": map file version " + std::to_string(version) +
                         " (this program reads " + std::to_string(kVersion) + ")");
  }
  if (!(r.Pod(&map.config_fingerprint) && r.String(&map.dataset_name) && Decode(r, &map.state))) {
    return Status::Error(r.error());
  }
  if (!r.AtEnd()) return Status::Error(source + ": corrupt map file: trailing bytes");
  return map;
}

Status SaveMapFile(const MapFile& map, const std::string& path) {
  return WriteFileAtomically(path, EncodeMapFile(map));
}

StatusOr<MapFile> LoadMapFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open map file");
  std::stringstream bytes;
  bytes << in.rdbuf();
  return DecodeMapFile(bytes.str(), path);
}

}  // namespace ratslam
