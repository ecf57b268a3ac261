#include "sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/circular.h"
#include "common/file_util.h"
#include "common/random.h"
#include "sim/propagation.h"
#include "sim/textures.h"

namespace ratslam::sim {

namespace {

constexpr double kTextureWidthM = 2.0;           // one texture repeat spans this much wall
constexpr int kTilePx = 64, kTilesPerSide = 16;  // up to 256 textures per floor

// Waypoints of a session in travel order, `laps` times around (closed) or along (open).
std::vector<RoutePoint> SessionPath(const Route& route, const Session& session) {
  std::vector<RoutePoint> points = route.points;
  if (session.reverse) std::reverse(points.begin(), points.end());
  std::vector<RoutePoint> path;
  if (route.closed) {
    // The perimeter, then whole laps plus the fraction, cutting the last segment short.
    double perimeter = 0.0;
    for (size_t i = 0; i < points.size(); ++i) {
      const RoutePoint& a = points[i];
      const RoutePoint& b = points[(i + 1) % points.size()];
      perimeter += std::hypot(b.position.x_m - a.position.x_m, b.position.y_m - a.position.y_m);
    }
    double left = perimeter * session.laps;
    path.push_back(points[0]);
    for (size_t i = 0; left > 1e-9; i = (i + 1) % points.size()) {
      const RoutePoint& a = points[i];
      const RoutePoint& b = points[(i + 1) % points.size()];
      const double d = std::hypot(b.position.x_m - a.position.x_m, b.position.y_m - a.position.y_m);
      if (d <= left || d < 1e-9) {
        path.push_back(b);
        left -= d;
      } else {
        const double t = left / d;
        path.push_back({{a.position.x_m + t * (b.position.x_m - a.position.x_m),
                         a.position.y_m + t * (b.position.y_m - a.position.y_m)},
                        a.floor});
        left = 0.0;
      }
    }
  } else {
    // Open routes go there and back: laps counts one-way traversals.
    const int passes = std::max(1, static_cast<int>(std::lround(session.laps)));
    for (int p = 0; p < passes; ++p) {
      if (p % 2 == 0) {
        path.insert(path.end(), points.begin() + (p == 0 ? 0 : 1), points.end());
      } else {
        path.insert(path.end(), points.rbegin() + 1, points.rend());
      }
    }
  }
  return path;
}

}  // namespace

std::vector<TruePose> TrueTrajectory(const World& world, double step_s) {
  std::vector<TruePose> poses;
  const MotionSettings& m = world.motion;
  double t = 0.0;
  for (size_t s = 0; s < world.sessions.size(); ++s) {
    const Session& session = world.sessions[s];
    const Route* route = nullptr;
    for (const Route& r : world.routes) {
      if (r.name == session.route) route = &r;
    }
    if (!route) continue;
    const std::vector<RoutePoint> path = SessionPath(*route, session);
    if (s > 0) t += m.session_gap_s;
    TruePose pose;
    pose.time_s = t;
    pose.x_m = path[0].position.x_m;
    pose.y_m = path[0].position.y_m;
    pose.floor = path[0].floor;
    pose.session = static_cast<int>(s);
    for (size_t k = 1; k < path.size(); ++k) {
      if (path[k].position.x_m != path[0].position.x_m ||
          path[k].position.y_m != path[0].position.y_m) {
        pose.heading_rad = std::atan2(path[k].position.y_m - path[0].position.y_m,
                                      path[k].position.x_m - path[0].position.x_m);
        break;
      }
    }
    poses.push_back(pose);
    // Each phase moves the robot; it is sampled every step_s (the last step may be shorter).
    auto advance = [&](double duration, double speed, double turn_rate) {
      double done = 0.0;
      while (done < duration - 1e-9) {
        const double dt = std::min(step_s, duration - done);
        TruePose next = poses.back();
        next.time_s += dt;
        // Exact for straight segments and turns in place (never both at once here).
        next.heading_rad = WrapAngle(next.heading_rad + turn_rate * dt);
        next.x_m += speed * dt * std::cos(next.heading_rad);
        next.y_m += speed * dt * std::sin(next.heading_rad);
        next.speed_m_per_s = speed;
        next.turn_rate_rad_per_s = turn_rate;
        poses.push_back(next);
        done += dt;
      }
    };
    for (size_t k = 1; k < path.size(); ++k) {
      const RoutePoint& target = path[k];
      const TruePose& here = poses.back();
      if (target.floor != here.floor) {
        advance(m.lift_time_s / 2, 0.0, 0.0);
        poses.back().floor = target.floor;
        advance(m.lift_time_s / 2, 0.0, 0.0);
        continue;
      }
      const double dx = target.position.x_m - poses.back().x_m,
                   dy = target.position.y_m - poses.back().y_m;
      const double d = std::hypot(dx, dy);
      if (d < 1e-9) continue;
      const double turn = WrapAngle(std::atan2(dy, dx) - poses.back().heading_rad);
      if (std::abs(turn) > 1e-9) {
        advance(std::abs(turn) / m.turn_rate_rad_per_s, 0.0,
                std::copysign(m.turn_rate_rad_per_s, turn));
      }
      poses.back().heading_rad = std::atan2(dy, dx);  // no rounding drift
      advance(d / m.speed_m_per_s, m.speed_m_per_s, 0.0);
      poses.back().x_m = target.position.x_m;
      poses.back().y_m = target.position.y_m;
    }
    t = poses.back().time_s;
  }
  return poses;
}

namespace {

// One floor's static geometry and texture atlas; people are added per frame (PlacePeople).
struct FloorGeometry {
  render::ViewMesh mesh;
  std::map<std::string, int> tiles;  // texture name -> atlas tile
  size_t static_vertices = 0;
  uint64_t static_id = 0;
};

// Texture v runs top (0) to bottom (1) of the image; walls put v = 0 at their top.
void AddQuad(const render::ViewVertex& a, const render::ViewVertex& b, const render::ViewVertex& c,
             const render::ViewVertex& d, render::ViewMesh* mesh) {
  for (const render::ViewVertex* v : {&a, &b, &c, &a, &c, &d}) mesh->triangles.push_back(*v);
}

FloorGeometry BuildFloor(const World& world, int floor) {
  FloorGeometry g;
  // The texture atlas: every texture name used, in order of first use.
  auto tile_of = [&](const std::string& name) {
    auto it = g.tiles.find(name);
    if (it != g.tiles.end()) return it->second;
    const int index = static_cast<int>(g.tiles.size()) % (kTilesPerSide * kTilesPerSide);
    g.tiles[name] = index;
    return index;
  };
  tile_of("floor");
  tile_of("ceiling");
  for (const Wall& w : world.walls) {
    if (w.floor == floor) tile_of(w.texture);
  }
  for (const Person& p : world.people) {
    if (p.floor == floor) tile_of(p.texture);
  }
  render::ViewMesh& mesh = g.mesh;
  mesh.tile_px = kTilePx;
  mesh.tiles_per_side = kTilesPerSide;
  const int atlas_px = kTilePx * kTilesPerSide;
  mesh.atlas.assign(static_cast<size_t>(atlas_px) * atlas_px, 0);
  for (const auto& [name, index] : g.tiles) {
    const std::vector<uint8_t> texture = MakeTexture(name, kTilePx);
    const int col = index % kTilesPerSide, row = index / kTilesPerSide;
    for (int y = 0; y < kTilePx; ++y) {
      std::copy_n(&texture[static_cast<size_t>(y) * kTilePx], kTilePx,
                  &mesh.atlas[(static_cast<size_t>(row) * kTilePx + y) * atlas_px + col * kTilePx]);
    }
  }
  double min_x = 1e300, min_y = 1e300, max_x = -1e300, max_y = -1e300, top = 3.0;
  for (const Wall& w : world.walls) {
    if (w.floor != floor) continue;
    min_x = std::min({min_x, w.from.x_m, w.to.x_m});
    max_x = std::max({max_x, w.from.x_m, w.to.x_m});
    min_y = std::min({min_y, w.from.y_m, w.to.y_m});
    max_y = std::max({max_y, w.from.y_m, w.to.y_m});
    top = std::max(top, w.height_m);
    const float length =
        static_cast<float>(std::hypot(w.to.x_m - w.from.x_m, w.to.y_m - w.from.y_m));
    const float repeats = std::max(1.0f, std::round(length / static_cast<float>(kTextureWidthM)));
    // Light from the north-east: walls facing it are brighter.
    const double nx = -(w.to.y_m - w.from.y_m) / length, ny = (w.to.x_m - w.from.x_m) / length;
    const float shade = static_cast<float>(0.65 + 0.35 * std::abs(nx * 0.6 + ny * 0.8));
    const float t = static_cast<float>(tile_of(w.texture));
    const float h = static_cast<float>(w.height_m);
    const float x0 = static_cast<float>(w.from.x_m), y0 = static_cast<float>(w.from.y_m);
    const float x1 = static_cast<float>(w.to.x_m), y1 = static_cast<float>(w.to.y_m);
    AddQuad({x0, y0, 0, 0, 0.999f, t, shade}, {x1, y1, 0, repeats, 0.999f, t, shade},
            {x1, y1, h, repeats, 0.0f, t, shade}, {x0, y0, h, 0, 0.0f, t, shade}, &mesh);
  }
  if (min_x <= max_x) {
    const float x0 = static_cast<float>(min_x - 1), x1 = static_cast<float>(max_x + 1);
    const float y0 = static_cast<float>(min_y - 1), y1 = static_cast<float>(max_y + 1);
    const float ux = (x1 - x0) / 2.0f, uy = (y1 - y0) / 2.0f, z = static_cast<float>(top);
    const float f = static_cast<float>(tile_of("floor")),
                c = static_cast<float>(tile_of("ceiling"));
    AddQuad({x0, y0, 0, 0, 0, f, 0.8f}, {x1, y0, 0, ux, 0, f, 0.8f}, {x1, y1, 0, ux, uy, f, 0.8f},
            {x0, y1, 0, 0, uy, f, 0.8f}, &mesh);
    AddQuad({x0, y0, z, 0, 0, c, 0.9f}, {x1, y0, z, ux, 0, c, 0.9f}, {x1, y1, z, ux, uy, c, 0.9f},
            {x0, y1, z, 0, uy, c, 0.9f}, &mesh);
  }
  // Ids from the content (FNV-1a), so that a renderer reused across worlds never draws a stale
  // atlas or stale walls.
  auto fnv = [](uint64_t h, const void* data, size_t n) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ bytes[i]) * 1099511628211ULL;
    return h;
  };
  mesh.atlas_id = fnv(1469598103934665603ULL, mesh.atlas.data(), mesh.atlas.size());
  mesh.id =
      fnv(mesh.atlas_id, mesh.triangles.data(), mesh.triangles.size() * sizeof(render::ViewVertex));
  g.static_vertices = mesh.triangles.size();
  g.static_id = mesh.id;
  return g;
}

// Replaces the people of `g` by their panels at `time_s`; the geometry id follows them.
void PlacePeople(const World& world, int floor, double time_s, FloorGeometry* g) {
  render::ViewMesh& mesh = g->mesh;
  mesh.triangles.resize(g->static_vertices);
  // The static geometry's id, extended by each person's position.
  uint64_t id = g->static_id;
  // People walk back and forth; drawn as upright panels facing along their path's normal.
  for (const Person& p : world.people) {
    if (p.floor != floor) continue;
    const double length = std::hypot(p.to.x_m - p.from.x_m, p.to.y_m - p.from.y_m);
    if (length < 1e-6) continue;
    const double period = 2.0 * length / p.speed_m_per_s;
    const double phase = std::fmod(time_s, period) / period;
    const double s = phase < 0.5 ? 2.0 * phase : 2.0 - 2.0 * phase;
    const double cx = p.from.x_m + s * (p.to.x_m - p.from.x_m);
    const double cy = p.from.y_m + s * (p.to.y_m - p.from.y_m);
    const double ux = (p.to.x_m - p.from.x_m) / length * 0.3,
                 uy = (p.to.y_m - p.from.y_m) / length * 0.3;
    const float t = static_cast<float>(g->tiles.at(p.texture));
    const float ax = static_cast<float>(cx - ux), ay = static_cast<float>(cy - uy);
    const float bx = static_cast<float>(cx + ux), by = static_cast<float>(cy + uy);
    AddQuad({ax, ay, 0, 0, 0.999f, t, 1.0f}, {bx, by, 0, 0.999f, 0.999f, t, 1.0f},
            {bx, by, 1.75f, 0.999f, 0, t, 1.0f}, {ax, ay, 1.75f, 0, 0, t, 1.0f}, &mesh);
    id = id * 1099511628211ULL ^
         static_cast<uint64_t>(std::llround(cx * 1000) * 31 + std::llround(cy * 1000));
  }
  mesh.id = id;
}

// What a session is called in figures and summaries: its lighting, with its route when the
// world's sessions walk more than one, "reversed" when walked backwards, and its place among
// sessions that would otherwise share a name ("day, 2").
std::string SessionName(const World& world, int index) {
  auto base = [&](const Session& s) {
    bool one_route = true;
    for (const Session& other : world.sessions) one_route = one_route && other.route == s.route;
    std::string name = one_route ? s.lighting : s.route + ", " + s.lighting;
    if (s.reverse) name += ", reversed";
    return name;
  };
  const std::string name = base(world.sessions[index]);
  int same = 0, position = 0;
  for (size_t i = 0; i < world.sessions.size(); ++i) {
    if (base(world.sessions[i]) != name) continue;
    ++same;
    if (static_cast<int>(i) <= index) position = same;
  }
  return same > 1 ? name + ", " + std::to_string(position) : name;
}

}  // namespace

render::ViewMesh FloorMesh(const World& world, int floor, double time_s) {
  FloorGeometry g = BuildFloor(world, floor);
  PlacePeople(world, floor, time_s, &g);
  return std::move(g.mesh);
}

render::ViewCamera CameraAt(const World& world, const TruePose& pose) {
  render::ViewCamera c;
  c.x_m = pose.x_m;
  c.y_m = pose.y_m;
  c.z_m = world.camera.height_m;
  c.yaw_rad = pose.heading_rad;
  c.pitch_rad = world.camera.pitch_deg * M_PI / 180.0;
  c.horizontal_fov_deg = world.camera.horizontal_fov_deg;
  c.width_px = world.camera.width_px;
  c.height_px = world.camera.height_px;
  return c;
}

render::ViewLighting LightingOf(const World& world, int session) {
  render::ViewLighting l;
  if (world.sessions[session].lighting == "night") {
    l.ambient = 0.12;
    l.headlight_gain = 1.1;
    l.headlight_range_m = 3.0;
  }
  return l;
}

Status Simulate(const World& world, uint64_t seed, render::ViewRenderer* renderer,
                const std::string& image_folder, dataset::Dataset* dataset,
                SimulationReport* report, const std::function<void(double)>& progress) {
  RATSLAM_RETURN_IF_ERROR(world.Validate());
  const double step_s = 1.0 / world.odometry.rate_hz;
  const std::vector<TruePose> poses = TrueTrajectory(world, step_s);
  if (poses.size() < 2) return Status::Error("world: the routes give no motion");
  *dataset = dataset::Dataset();
  *report = SimulationReport();
  dataset->name = world.name.empty() ? "simulated" : world.name;
  if (renderer) {
    std::error_code ec;
    std::filesystem::create_directories(image_folder, ec);
    if (ec) return Status::Error(image_folder + ": cannot create: " + ec.message());
  }
  // One random stream per sensor: changing one sensor's settings leaves the others' data alone.
  Random odometry_noise(seed * 7 + 1), compass_noise(seed * 7 + 2), wifi_noise(seed * 7 + 3),
      camera_noise(seed * 7 + 4);
  const WifiPropagation wifi(world, seed);
  const OdometrySettings& o = world.odometry;
  int session = -1;
  double next_image = poses.front().time_s, next_scan = poses.front().time_s,
         next_compass = poses.front().time_s;
  // The floor's walls and atlas are built when the floor changes; only people move per frame.
  FloorGeometry geometry;
  int mesh_floor = std::numeric_limits<int>::min();
  const double end = poses.back().time_s;
  int last_decile = -1;
  for (size_t i = 0; i < poses.size(); ++i) {
    const TruePose& p = poses[i];
    if (p.session != session) {
      session = p.session;
      dataset->session_start_times_s.push_back(p.time_s);
      dataset->session_names.push_back(SessionName(world, session));
      dataset->odometry.push_back({p.time_s, 0.0, 0.0});  // no motion across the gap
      next_image = next_scan = next_compass = p.time_s;
    } else {
      OdometryRow row;
      row.time_s = p.time_s;
      row.forward_speed_m_per_s = p.speed_m_per_s * (1.0 + o.speed_scale_error) +
                                  odometry_noise.Gaussian(0.0, o.speed_noise_m_per_s);
      row.turn_rate_rad_per_s = p.turn_rate_rad_per_s + o.turn_bias_rad_per_s +
                                odometry_noise.Gaussian(0.0, o.turn_noise_rad_per_s);
      dataset->odometry.push_back(row);
    }
    dataset->ground_truth.push_back({p.time_s, p.x_m, p.y_m, p.heading_rad, p.floor});
    if (p.time_s >= next_compass - 1e-9) {
      double heading =
          p.heading_rad + compass_noise.Gaussian(0.0, world.compass.noise_sigma_deg * M_PI / 180.0);
      for (const Disturbance& d : world.disturbances) {
        if (d.floor != p.floor) continue;
        const double r2 = std::pow(p.x_m - d.position.x_m, 2) + std::pow(p.y_m - d.position.y_m, 2);
        heading += d.strength_deg * M_PI / 180.0 * std::exp(-r2 / (2.0 * d.radius_m * d.radius_m));
      }
      dataset->compass.push_back({p.time_s, WrapAngle(heading)});
      next_compass += 1.0 / world.compass.rate_hz;
    }
    if (p.time_s >= next_scan - 1e-9) {
      dataset->wifi.push_back(
          {p.time_s, wifi.Scan({p.x_m, p.y_m}, p.floor, p.session, &wifi_noise)});
      next_scan += world.wifi.scan_period_s;
    }
    if (renderer && p.time_s >= next_image - 1e-9) {
      if (p.floor != mesh_floor) {
        geometry = BuildFloor(world, p.floor);
        mesh_floor = p.floor;
      }
      PlacePeople(world, p.floor, p.time_s, &geometry);
      auto view = renderer->Render(geometry.mesh, CameraAt(world, p), LightingOf(world, p.session));
      if (!view.ok()) return view.status();
      cv::Mat image(view->height, view->width, CV_8UC1, view->pixels.data());
      if (world.camera.motion_blur && std::abs(p.turn_rate_rad_per_s) > 1e-6) {
        // The image sweeps turn_rate / rate_hz radians while exposed: a box blur that wide.
        const double px_per_rad =
            world.camera.width_px / (world.camera.horizontal_fov_deg * M_PI / 180.0);
        const int width = 1 + static_cast<int>(std::abs(p.turn_rate_rad_per_s) * 0.05 * px_per_rad);
        cv::blur(image, image, cv::Size(width, 1));
      }
      for (uint8_t& v : view->pixels) {
        v = static_cast<uint8_t>(
            std::clamp(v + camera_noise.Gaussian(0.0, world.camera.noise_sigma), 0.0, 255.0));
      }
      char name[32];
      std::snprintf(name, sizeof name, "frame_%06zu.png", report->images);
      const std::string path = (std::filesystem::path(image_folder) / name).string();
      // Encoded in memory and written checked: a full disk is an error, never a 0-byte PNG.
      std::vector<uchar> png;
      if (!cv::imencode(".png", image, png)) return Status::Error(path + ": cannot encode image");
      RATSLAM_RETURN_IF_ERROR(
          WriteFileAtomically(path, std::string(png.begin(), png.end()), /*flush_to_disk=*/false));
      dataset->images.push_back({p.time_s, name, 0});
      ++report->images;
      next_image += 1.0 / world.camera.rate_hz;
    }
    if (progress) {
      const int decile = static_cast<int>(10.0 * (p.time_s - poses.front().time_s) /
                                          std::max(1e-9, end - poses.front().time_s));
      if (decile != last_decile) {
        last_decile = decile;
        progress(decile / 10.0);
      }
    }
  }
  report->scans = dataset->wifi.size();
  report->odometry_rows = dataset->odometry.size();
  report->compass_rows = dataset->compass.size();
  report->duration_s = end - poses.front().time_s;
  return Status::Ok();
}

}  // namespace ratslam::sim
