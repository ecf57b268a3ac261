#include "sim/world.h"

#include <toml++/toml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "common/text_file.h"
#include "common/toml_string.h"
#include "sim/textures.h"

namespace ratslam::sim {

namespace {

std::string Where(const std::string& source, const toml::node* node) {
  return source + ":" + (node ? std::to_string(node->source().begin.line) : std::string("?"));
}

// Reads one TOML table's keys into fields; remembers the first error and unknown keys.
class TableReader {
 public:
  TableReader(const toml::table& table, std::string where, std::string source, Status* status)
      : table_(table), where_(std::move(where)), source_(std::move(source)), status_(status) {}

  void Number(const char* key, double* field) {
    const toml::node* n = Find(key);
    if (!n) return;
    if (const auto* f = n->as_floating_point()) {
      if (!std::isfinite(f->get())) return Fail(n, key, "must be a finite number");
      *field = f->get();
    } else if (const auto* i = n->as_integer()) {
      *field = static_cast<double>(i->get());
    } else {
      Fail(n, key, "expected a number");
    }
  }
  void Integer(const char* key, int* field) {
    const toml::node* n = Find(key);
    if (!n) return;
    const auto* i = n->as_integer();
    if (!i || i->get() < -1000000 || i->get() > 1000000) return Fail(n, key, "expected an integer");
    *field = static_cast<int>(i->get());
  }
  void Bool(const char* key, bool* field) {
    const toml::node* n = Find(key);
    if (!n) return;
    const auto* b = n->as_boolean();
    if (!b) return Fail(n, key, "expected true or false");
    *field = b->get();
  }
  void String(const char* key, std::string* field) {
    const toml::node* n = Find(key);
    if (!n) return;
    const auto* s = n->as_string();
    if (!s) return Fail(n, key, "expected a string");
    *field = s->get();
  }
  void Point(const char* key, Point2* field) {
    const toml::node* n = Find(key);
    if (!n) return;
    std::vector<double> v;
    if (!Numbers(*n, &v) || v.size() != 2) return Fail(n, key, "expected [x, y] in metres");
    *field = {v[0], v[1]};
  }
  void Integers(const char* key, std::vector<int>* field) {
    const toml::node* n = Find(key);
    if (!n) return;
    const auto* a = n->as_array();
    if (!a) return Fail(n, key, "expected a list of integers");
    field->clear();
    for (const auto& e : *a) {
      const auto* i = e.as_integer();
      if (!i || i->get() < -1000000 || i->get() > 1000000) {
        return Fail(n, key, "expected a list of integers");
      }
      field->push_back(static_cast<int>(i->get()));
    }
  }
  void RoutePoints(const char* key, std::vector<RoutePoint>* field) {
    const toml::node* n = Find(key);
    if (!n) return;
    const auto* a = n->as_array();
    if (!a) return Fail(n, key, "expected a list of [x, y, floor]");
    field->clear();
    for (const auto& e : *a) {
      std::vector<double> v;
      if (!Numbers(e, &v) || v.size() != 3 || v[2] != std::floor(v[2]) || std::abs(v[2]) > 1000) {
        return Fail(&e, key, "expected [x, y, floor] with an integer floor in -1000..1000");
      }
      field->push_back({{v[0], v[1]}, static_cast<int>(v[2])});
    }
  }
  // The sub-table `key`, or nullptr.
  const toml::table* Table(const char* key) {
    const toml::node* n = Find(key);
    if (!n) return nullptr;
    const auto* t = n->as_table();
    if (!t) Fail(n, key, "expected a table");
    return t;
  }
  // The array of tables `key` (empty when absent).
  std::vector<const toml::table*> Tables(const char* key) {
    std::vector<const toml::table*> out;
    const toml::node* n = Find(key);
    if (!n) return out;
    const auto* a = n->as_array();
    if (!a) {
      Fail(n, key, "expected [[" + std::string(key) + "]] tables");
      return out;
    }
    for (const auto& e : *a) {
      if (const auto* t = e.as_table()) {
        out.push_back(t);
      } else {
        Fail(&e, key, "expected [[" + std::string(key) + "]] tables");
      }
    }
    return out;
  }
  void Finish() {
    for (const auto& [key, node] : table_) {
      if (!used_.count(std::string(key.str())) && status_->ok()) {
        *status_ = Status::Error(Where(source_, &node) + ": unknown key '" +
                                 std::string(key.str()) + "' in " + where_);
      }
    }
  }
  // The visitor form of the readers above, for the field lists below.
  void operator()(const char* key, double& f) { Number(key, &f); }
  void operator()(const char* key, int& f) { Integer(key, &f); }
  void operator()(const char* key, bool& f) { Bool(key, &f); }
  void operator()(const char* key, std::string& f) { String(key, &f); }
  void operator()(const char* key, Point2& f) { Point(key, &f); }
  void operator()(const char* key, std::vector<int>& f) { Integers(key, &f); }
  void operator()(const char* key, std::vector<RoutePoint>& f) { RoutePoints(key, &f); }

 private:
  const toml::node* Find(const char* key) {
    used_.insert(key);
    return table_.get(key);
  }
  static bool Numbers(const toml::node& n, std::vector<double>* out) {
    const auto* a = n.as_array();
    if (!a) return false;
    for (const auto& e : *a) {
      if (const auto* f = e.as_floating_point()) {
        if (!std::isfinite(f->get())) return false;
        out->push_back(f->get());
      } else if (const auto* i = e.as_integer()) {
        out->push_back(static_cast<double>(i->get()));
      } else {
        return false;
      }
    }
    return true;
  }
  void Fail(const toml::node* n, const std::string& key, const std::string& message) {
    if (status_->ok()) {
      *status_ = Status::Error(Where(source_, n) + ": " + where_ + " " + key + ": " + message);
    }
  }

  const toml::table& table_;
  std::string where_, source_;
  Status* status_;
  std::set<std::string> used_;
};

}  // namespace

Status World::Validate() const {
  auto bad = [](const std::string& what) { return Status::Error("world: " + what); };
  if (walls.empty()) return bad("no walls");
  for (size_t i = 0; i < walls.size(); ++i) {
    const Wall& w = walls[i];
    const std::string which = "wall " + std::to_string(i) + ": ";
    if (!materials_db.count(w.material))
      return bad(which + "unknown material '" + w.material + "'");
    if (!IsTextureName(w.texture)) return bad(which + "unknown texture '" + w.texture + "'");
    if (!(w.height_m > 0.0)) return bad(which + "height_m must be positive");
    if (std::hypot(w.to.x_m - w.from.x_m, w.to.y_m - w.from.y_m) < 1e-6) {
      return bad(which + "has zero length");
    }
  }
  std::map<int, std::set<std::string>> textures_per_floor;
  for (const Wall& w : walls) textures_per_floor[w.floor].insert(w.texture);
  for (const auto& [floor, names] : textures_per_floor) {
    if (names.size() > 250) {
      return bad("floor " + std::to_string(floor) + " uses more than 250 textures");
    }
  }
  for (const auto& [name, db] : materials_db) {
    if (!(db >= 0.0)) return bad("material '" + name + "' has a negative attenuation");
  }
  std::set<std::string> ap_names;
  for (const AccessPoint& ap : access_points) {
    if (ap.name.empty() || !ap_names.insert(ap.name).second) {
      return bad("access point names must be unique and not empty ('" + ap.name + "')");
    }
    if (!((ap.channel >= 1 && ap.channel <= 14) || (ap.channel >= 32 && ap.channel <= 177))) {
      return bad("access point '" + ap.name + "': channel must be 1-14 or 32-177");
    }
  }
  for (const Person& p : people) {
    if (!IsTextureName(p.texture)) return bad("person: unknown texture '" + p.texture + "'");
    if (!(p.speed_m_per_s > 0.0)) return bad("person: speed_m_per_s must be positive");
  }
  std::set<std::string> route_names;
  for (const Route& r : routes) {
    if (!route_names.insert(r.name).second) return bad("two routes named '" + r.name + "'");
    if (r.points.size() < 2) return bad("route '" + r.name + "' needs at least two points");
  }
  // A route must not pass through a wall of its floor.
  auto crosses = [](Point2 p1, Point2 p2, Point2 q1, Point2 q2) {
    auto orient = [](Point2 a, Point2 b, Point2 c) {
      return (b.x_m - a.x_m) * (c.y_m - a.y_m) - (b.y_m - a.y_m) * (c.x_m - a.x_m);
    };
    return ((orient(q1, q2, p1) > 0) != (orient(q1, q2, p2) > 0)) &&
           ((orient(p1, p2, q1) > 0) != (orient(p1, p2, q2) > 0));
  };
  for (const Route& r : routes) {
    const size_t segments = r.closed ? r.points.size() : r.points.size() - 1;
    for (size_t i = 0; i < segments && r.points.size() >= 2; ++i) {
      const RoutePoint& a = r.points[i];
      const RoutePoint& b = r.points[(i + 1) % r.points.size()];
      if (a.floor != b.floor) continue;  // a lift
      for (size_t k = 0; k < walls.size(); ++k) {
        if (walls[k].floor == a.floor &&
            crosses(a.position, b.position, walls[k].from, walls[k].to)) {
          return bad("route '" + r.name + "' segment " + std::to_string(i) +
                     " passes through wall " + std::to_string(k));
        }
      }
    }
  }
  if (sessions.empty()) return bad("no sessions");
  for (size_t i = 0; i < sessions.size(); ++i) {
    const Session& s = sessions[i];
    if (!route_names.count(s.route))
      return bad("session " + std::to_string(i) + ": unknown route '" + s.route + "'");
    if (!(s.laps > 0.0 && s.laps <= 1000.0))
      return bad("session " + std::to_string(i) + ": laps must be in (0, 1000]");
    if (s.lighting != "day" && s.lighting != "night") {
      return bad("session " + std::to_string(i) + ": lighting must be day or night");
    }
  }
  const CameraSettings& c = camera;
  if (c.width_px < 8 || c.height_px < 8 || c.width_px > 1024 || c.height_px > 1024) {
    return bad("camera: width_px and height_px must be in 8..1024");
  }
  if (!(c.horizontal_fov_deg > 10.0 && c.horizontal_fov_deg < 170.0))
    return bad("camera: horizontal_fov_deg must be in (10, 170)");
  if (!(c.rate_hz > 0.0) || !(c.noise_sigma >= 0.0) || !(c.height_m > 0.0)) {
    return bad("camera: rate_hz and height_m must be positive, noise_sigma not negative");
  }
  const WifiSettings& w = wifi;
  // A correlation length below a centimetre would make the shadowing grid index of a point 100 km
  // away overflow an integer.
  if (!(w.path_loss_exponent > 0.0) || !(w.reference_distance_m > 0.0) ||
      !(w.scan_period_s > 0.0) || !(w.shadowing_correlation_m >= 0.01) ||
      !(w.shadowing_sigma_db >= 0.0) || !(w.fading_sigma_db >= 0.0) ||
      !(w.floor_attenuation_db >= 0.0) ||
      !(w.miss_probability >= 0.0 && w.miss_probability < 1.0)) {
    return bad("wifi: a setting is out of range");
  }
  if (!(compass.rate_hz > 0.0) || !(compass.noise_sigma_deg >= 0.0))
    return bad("compass: a setting is out of range");
  if (!(odometry.rate_hz > 0.0) || !(odometry.speed_noise_m_per_s >= 0.0) ||
      !(odometry.turn_noise_rad_per_s >= 0.0) || !(odometry.speed_scale_error > -1.0)) {
    return bad("odometry: a setting is out of range");
  }
  if (!(motion.speed_m_per_s >= 0.01) || !(motion.turn_rate_rad_per_s >= 0.01) ||
      !(motion.lift_time_s >= 0.0 && motion.lift_time_s <= 3600.0) ||
      !(motion.session_gap_s >= 0.0 && motion.session_gap_s <= 86400.0)) {
    return bad("motion: a setting is out of range");
  }
  if (odometry.rate_hz > 1000.0 || compass.rate_hz > 1000.0 || camera.rate_hz > 100.0 ||
      wifi.scan_period_s < 0.01) {
    return bad("sensor rates: odometry and compass at most 1000 Hz, camera 100 Hz, scans 0.01 s");
  }
  // Places within 100 km, and a simulation of at most ten million odometry steps.
  auto far = [](const Point2& p) { return !(std::abs(p.x_m) <= 1e5 && std::abs(p.y_m) <= 1e5); };
  for (const Wall& w : walls) {
    if (far(w.from) || far(w.to)) return bad("a wall is more than 100 km from the origin");
  }
  for (const AccessPoint& a : access_points) {
    if (far(a.position) || far(a.moved_to)) return bad("access point '" + a.name + "' is too far");
  }
  double seconds = 0.0;
  for (const Session& s : sessions) {
    for (const Route& r : routes) {
      if (r.name != s.route) continue;
      double length = 0.0;
      for (size_t i = 0; i < r.points.size(); ++i) {
        if (far(r.points[i].position)) return bad("route '" + r.name + "' goes too far");
        const RoutePoint& b = r.points[(i + 1) % r.points.size()];
        if (i + 1 < r.points.size() || r.closed) {
          length += std::hypot(b.position.x_m - r.points[i].position.x_m,
                               b.position.y_m - r.points[i].position.y_m);
        }
      }
      seconds +=
          (length * std::max(1.0, s.laps) / motion.speed_m_per_s +
           (r.points.size() + 1) * (motion.lift_time_s + 2 * M_PI / motion.turn_rate_rad_per_s)) +
          motion.session_gap_s;
    }
  }
  if (seconds * odometry.rate_hz > 1e7) {
    return bad("the sessions would take more than ten million odometry steps");
  }
  return Status::Ok();
}

namespace {

// Every key of every table, shared by the reader and the printer: (key, field) pairs in file
// order. `T` is the struct or its const version.
template <typename T, typename V>
void WallFields(T& w, V&& v) {
  v("floor", w.floor);
  v("from", w.from);
  v("to", w.to);
  v("material", w.material);
  v("texture", w.texture);
  v("height_m", w.height_m);
}
template <typename T, typename V>
void AccessPointFields(T& a, V&& v) {
  v("name", a.name);
  v("position", a.position);
  v("floor", a.floor);
  v("tx_power_dbm", a.tx_power_dbm);
  v("channel", a.channel);
  v("off_in_sessions", a.off_in_sessions);
  v("moved_in_sessions", a.moved_in_sessions);
  v("moved_to", a.moved_to);
}
template <typename T, typename V>
void DisturbanceFields(T& d, V&& v) {
  v("position", d.position);
  v("floor", d.floor);
  v("radius_m", d.radius_m);
  v("strength_deg", d.strength_deg);
}
template <typename T, typename V>
void PersonFields(T& p, V&& v) {
  v("floor", p.floor);
  v("from", p.from);
  v("to", p.to);
  v("speed_m_per_s", p.speed_m_per_s);
  v("texture", p.texture);
}
template <typename T, typename V>
void RouteFields(T& r, V&& v) {
  v("name", r.name);
  v("closed", r.closed);
  v("points", r.points);
}
template <typename T, typename V>
void SessionFields(T& s, V&& v) {
  v("route", s.route);
  v("laps", s.laps);
  v("reverse", s.reverse);
  v("lighting", s.lighting);
}
template <typename T, typename V>
void CameraFields(T& c, V&& v) {
  v("width_px", c.width_px);
  v("height_px", c.height_px);
  v("horizontal_fov_deg", c.horizontal_fov_deg);
  v("height_m", c.height_m);
  v("pitch_deg", c.pitch_deg);
  v("rate_hz", c.rate_hz);
  v("noise_sigma", c.noise_sigma);
  v("motion_blur", c.motion_blur);
}
template <typename T, typename V>
void WifiFields(T& w, V&& v) {
  v("path_loss_exponent", w.path_loss_exponent);
  v("reference_distance_m", w.reference_distance_m);
  v("floor_attenuation_db", w.floor_attenuation_db);
  v("shadowing_sigma_db", w.shadowing_sigma_db);
  v("shadowing_correlation_m", w.shadowing_correlation_m);
  v("fading_sigma_db", w.fading_sigma_db);
  v("sensitivity_dbm", w.sensitivity_dbm);
  v("scan_period_s", w.scan_period_s);
  v("miss_probability", w.miss_probability);
}
template <typename T, typename V>
void CompassFields(T& c, V&& v) {
  v("rate_hz", c.rate_hz);
  v("noise_sigma_deg", c.noise_sigma_deg);
}
template <typename T, typename V>
void OdometryFields(T& o, V&& v) {
  v("rate_hz", o.rate_hz);
  v("speed_scale_error", o.speed_scale_error);
  v("turn_bias_rad_per_s", o.turn_bias_rad_per_s);
  v("speed_noise_m_per_s", o.speed_noise_m_per_s);
  v("turn_noise_rad_per_s", o.turn_noise_rad_per_s);
}
template <typename T, typename V>
void MotionFields(T& m, V&& v) {
  v("speed_m_per_s", m.speed_m_per_s);
  v("turn_rate_rad_per_s", m.turn_rate_rad_per_s);
  v("lift_time_s", m.lift_time_s);
  v("session_gap_s", m.session_gap_s);
}

// Calls `f(key, table_fields, list)` for every [[array]] of the world, and
// `g(key, table_fields, settings)` for every [table] of settings.
template <typename W, typename Arrays, typename Tables>
void WorldSections(W& w, Arrays&& arrays, Tables&& tables) {
  tables(
      "camera", [](auto& x, auto&& v) { CameraFields(x, v); }, w.camera);
  tables(
      "wifi", [](auto& x, auto&& v) { WifiFields(x, v); }, w.wifi);
  tables(
      "compass", [](auto& x, auto&& v) { CompassFields(x, v); }, w.compass);
  tables(
      "odometry", [](auto& x, auto&& v) { OdometryFields(x, v); }, w.odometry);
  tables(
      "motion", [](auto& x, auto&& v) { MotionFields(x, v); }, w.motion);
  arrays(
      "walls", [](auto& x, auto&& v) { WallFields(x, v); }, w.walls);
  arrays(
      "access_points", [](auto& x, auto&& v) { AccessPointFields(x, v); }, w.access_points);
  arrays(
      "disturbances", [](auto& x, auto&& v) { DisturbanceFields(x, v); }, w.disturbances);
  arrays(
      "people", [](auto& x, auto&& v) { PersonFields(x, v); }, w.people);
  arrays(
      "routes", [](auto& x, auto&& v) { RouteFields(x, v); }, w.routes);
  arrays(
      "sessions", [](auto& x, auto&& v) { SessionFields(x, v); }, w.sessions);
}

}  // namespace

StatusOr<World> ParseWorld(const std::string& text, const std::string& source) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    return Status::Error(source + ":" + std::to_string(e.source().begin.line) + ": " +
                         std::string(e.description()));
  }
  World world;
  Status status;
  TableReader top(root, "the world", source, &status);
  top.String("name", &world.name);
  if (const toml::table* m = top.Table("materials")) {
    for (const auto& [key, node] : *m) {
      double db = 0.0;
      if (const auto* f = node.as_floating_point()) {
        db = f->get();
      } else if (const auto* i = node.as_integer()) {
        db = static_cast<double>(i->get());
      } else if (status.ok()) {
        status = Status::Error(Where(source, &node) + ": [materials] " + std::string(key.str()) +
                               ": expected an attenuation in dB");
      }
      world.materials_db[std::string(key.str())] = db;
    }
  }
  WorldSections(
      world,
      [&](const char* key, auto fields, auto& list) {
        for (const toml::table* t : top.Tables(key)) {
          typename std::decay_t<decltype(list)>::value_type item;
          TableReader r(*t, "[[" + std::string(key) + "]]", source, &status);
          fields(item, r);
          r.Finish();
          list.push_back(item);
        }
      },
      [&](const char* key, auto fields, auto& settings) {
        if (const toml::table* t = top.Table(key)) {
          TableReader r(*t, "[" + std::string(key) + "]", source, &status);
          fields(settings, r);
          r.Finish();
        }
      });
  top.Finish();
  if (!status.ok()) return status;
  Status valid = world.Validate();
  if (!valid.ok()) return Status::Error(source + ": " + valid.message());
  return world;
}

StatusOr<World> LoadWorldFile(const std::string& path) {
  StatusOr<std::string> text = ReadRegularFile(path, "world file", size_t{16} << 20);
  if (!text.ok()) return text.status();
  return ParseWorld(*text, path);
}

namespace {
std::string Num(double v) {
  std::ostringstream o;
  o.precision(17);
  o << v;
  std::string s = o.str();
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}
std::string Pt(const Point2& p) { return "[" + Num(p.x_m) + ", " + Num(p.y_m) + "]"; }
std::string Quote(const std::string& s) { return TomlQuoted(s); }
std::string Ints(const std::vector<int>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + std::to_string(v[i]);
  return s + "]";
}
}  // namespace

namespace {
// Writes `key = value` lines.
struct FieldPrinter {
  std::ostringstream& o;
  void operator()(const char* key, double v) { o << key << " = " << Num(v) << "\n"; }
  void operator()(const char* key, int v) { o << key << " = " << v << "\n"; }
  void operator()(const char* key, bool v) { o << key << " = " << (v ? "true" : "false") << "\n"; }
  void operator()(const char* key, const std::string& v) { o << key << " = " << Quote(v) << "\n"; }
  void operator()(const char* key, const Point2& v) { o << key << " = " << Pt(v) << "\n"; }
  void operator()(const char* key, const std::vector<int>& v) {
    o << key << " = " << Ints(v) << "\n";
  }
  void operator()(const char* key, const std::vector<RoutePoint>& v) {
    o << key << " = [";
    for (size_t i = 0; i < v.size(); ++i) {
      o << (i ? ", " : "") << "[" << Num(v[i].position.x_m) << ", " << Num(v[i].position.y_m)
        << ", " << v[i].floor << "]";
    }
    o << "]\n";
  }
};
}  // namespace

std::string PrintWorld(const World& w) {
  std::ostringstream o;
  o << "name = " << Quote(w.name) << "\n\n[materials]\n";
  for (const auto& [name, db] : w.materials_db) o << Quote(name) << " = " << Num(db) << "\n";
  FieldPrinter printer{o};
  WorldSections(
      w,
      [&](const char* key, auto fields, const auto& list) {
        for (const auto& item : list) {
          o << "\n[[" << key << "]]\n";
          fields(item, printer);
        }
      },
      [&](const char* key, auto fields, const auto& settings) {
        o << "\n[" << key << "]\n";
        fields(settings, printer);
      });
  return o.str();
}

}  // namespace ratslam::sim
