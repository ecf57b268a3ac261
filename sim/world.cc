#include "sim/world.h"

#include <toml++/toml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "common/text_file.h"
#include "common/toml_binder.h"
#include "sim/textures.h"

// World-only value types, read and printed by the common binder.
namespace ratslam::schema {
template <>
struct TomlCodec<sim::Point2> {
  static std::string Read(const toml::node& node, sim::Point2* out) {
    std::vector<double> v;
    if (!TomlCodec<std::vector<double>>::Read(node, &v).empty() || v.size() != 2) {
      return "expected [x, y] in metres";
    }
    *out = {v[0], v[1]};
    return "";
  }
  static std::string Write(const sim::Point2& p) {
    return "[" + TomlNumber(p.x_m) + ", " + TomlNumber(p.y_m) + "]";
  }
};
template <>
struct TomlCodec<sim::RoutePoint> {
  static std::string Read(const toml::node& node, sim::RoutePoint* out) {
    std::vector<double> v;
    if (!TomlCodec<std::vector<double>>::Read(node, &v).empty() || v.size() != 3 ||
        v[2] != std::floor(v[2]) || std::abs(v[2]) > 1000) {
      return "expected [x, y, floor] with an integer floor in -1000..1000";
    }
    *out = {{v[0], v[1]}, static_cast<int>(v[2])};
    return "";
  }
  static std::string Write(const sim::RoutePoint& p) {
    return "[" + TomlNumber(p.position.x_m) + ", " + TomlNumber(p.position.y_m) + ", " +
           std::to_string(p.floor) + "]";
  }
};
}  // namespace ratslam::schema

namespace ratslam::sim {

namespace {

// Calls `arrays(key, list)` for every [[array]] of tables of the world and `tables(key, settings)`
// for every [table] of settings, in file order; the items' own VisitFields list their keys.
template <typename W, typename Arrays, typename Tables>
void WorldSections(W& w, Arrays&& arrays, Tables&& tables) {
  tables("camera", w.camera);
  tables("wifi", w.wifi);
  tables("compass", w.compass);
  tables("odometry", w.odometry);
  tables("motion", w.motion);
  arrays("walls", w.walls);
  arrays("access_points", w.access_points);
  arrays("disturbances", w.disturbances);
  arrays("people", w.people);
  arrays("routes", w.routes);
  arrays("sessions", w.sessions);
}

}  // namespace

Status World::Validate() const {
  auto bad = [](const std::string& what) { return Status::Error("world: " + what); };
  // Each field against its declared rule (world.h), then the relations between fields.
  std::string error;
  auto check_list = [&error](const char* key, const auto& list) {
    for (size_t i = 0; i < list.size(); ++i) {
      if (!schema::CheckFields(list[i], &error)) {
        error = std::string(key) + "[" + std::to_string(i) + "]." + error;
        return false;
      }
    }
    return true;
  };
  auto check_table = [&error](const char* key, const auto& settings) {
    if (schema::CheckFields(settings, &error)) return true;
    error = std::string(key) + "." + error;
    return false;
  };
  bool fields_ok = true;
  WorldSections(
      *this,
      [&](const char* key, const auto& list) { fields_ok = fields_ok && check_list(key, list); },
      [&](const char* key, const auto& settings) {
        fields_ok = fields_ok && check_table(key, settings);
      });
  if (!fields_ok) return bad(error);
  if (walls.empty()) return bad("no walls");
  for (size_t i = 0; i < walls.size(); ++i) {
    const Wall& w = walls[i];
    const std::string which = "wall " + std::to_string(i) + ": ";
    if (!materials_db.count(w.material))
      return bad(which + "unknown material '" + w.material + "'");
    if (!IsTextureName(w.texture)) return bad(which + "unknown texture '" + w.texture + "'");
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
    if (s.lighting != "day" && s.lighting != "night") {
      return bad("session " + std::to_string(i) + ": lighting must be day or night");
    }
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

StatusOr<World> ParseWorld(const std::string& text, const std::string& source) {
  StatusOr<toml::table> parsed = schema::ParseToml(text, source);
  if (!parsed.ok()) return parsed.status();
  World world;
  Status status;
  auto keep_first = [&status](const Status& s) {
    if (status.ok() && !s.ok()) status = s;
  };
  schema::TableBinder top(*parsed, "the world", "", source);
  if (const toml::node* name = top.Take("name")) {
    if (const auto* text_value = name->as_string()) {
      world.name = text_value->get();
    } else {
      top.Fail(name, "name", "expected a string");
    }
  }
  if (const toml::table* m = top.Table("materials")) {
    for (const auto& [key, node] : *m) {
      double db = 0.0;
      if (!schema::TomlToDouble(node, &db) || db < 0.0) {
        top.FailAt(&node, "materials." + std::string(key.str()) +
                              ": expected an attenuation of zero or more dB");
      }
      world.materials_db[std::string(key.str())] = db;
    }
  }
  WorldSections(
      world,
      [&](const char* key, auto& list) {
        for (const toml::table* t : top.Tables(key)) {
          typename std::decay_t<decltype(list)>::value_type item;
          schema::TableBinder binder(*t, "[[" + std::string(key) + "]]",
                                     std::string(key) + "[" + std::to_string(list.size()) + "].",
                                     source);
          item.VisitFields(binder);
          keep_first(binder.Finish());
          list.push_back(item);
        }
      },
      [&](const char* key, auto& settings) {
        if (const toml::table* t = top.Table(key)) {
          schema::TableBinder binder(*t, "[" + std::string(key) + "]", std::string(key) + ".",
                                     source);
          settings.VisitFields(binder);
          keep_first(binder.Finish());
        }
      });
  keep_first(top.Finish());
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

std::string PrintWorld(const World& w) {
  std::ostringstream o;
  o << "name = " << TomlQuoted(w.name) << "\n\n[materials]\n";
  for (const auto& [name, db] : w.materials_db) {
    o << TomlQuoted(name) << " = " << schema::TomlNumber(db) << "\n";
  }
  schema::TablePrinter printer(o, false);
  World copy = w;  // VisitFields hands out mutable references
  WorldSections(
      copy,
      [&](const char* key, auto& list) {
        for (auto& item : list) {
          o << "\n[[" << key << "]]\n";
          item.VisitFields(printer);
        }
      },
      [&](const char* key, auto& settings) {
        o << "\n[" << key << "]\n";
        settings.VisitFields(printer);
      });
  return o.str();
}

}  // namespace ratslam::sim
