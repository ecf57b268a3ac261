// `ratslam route`: the shortest path on a map's experience graph between two experiences (or
// from one to the experience nearest a point), printed and, with --out, written and drawn.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "apps/progress.h"
#include "common/number_text.h"
#include "common/output_folder.h"
#include "phone/robot_call.h"
#include "render/image.h"
#include "session/call_session.h"
#include "viewer/figures.h"

namespace ratslam::apps {
namespace {

// A route over a map's experience graph: its nodes' positions, the distances from the start,
// the experiences from start to end, and the point asked for (--to-xy).
struct Route {
  const phone::RouteGraph& graph;
  const std::vector<double>& distance_m;
  const std::vector<uint32_t>& path;
  std::optional<Point2> point;
};

// The map with the route drawn over it: a purple line, a green start, a ring at the end and an
// x at the point asked for (kept in view).
render::Scene RouteScene(const session::RobotMap& map, const Route& r, int width_px) {
  viewer::ExperienceMapImageData image;
  image.experiences = map.experiences;
  image.links = map.links;
  viewer::ExperienceMapImageOptions o;
  char title[160];
  std::snprintf(title, sizeof title, "route from experience %u to %u: %.1f m", r.path.front(),
                r.path.back(), r.distance_m[r.path.back()]);
  o.title = title;
  const std::optional<Point2>& point = r.point;
  if (point) {  // the point in view, with the map
    viewer::WorldBounds b{point->x - 2, point->y - 2, point->x + 2, point->y + 2};
    for (const Point2& p : r.graph.nodes) {
      b.min_x_m = std::min(b.min_x_m, p.x);
      b.min_y_m = std::min(b.min_y_m, p.y);
      b.max_x_m = std::max(b.max_x_m, p.x);
      b.max_y_m = std::max(b.max_y_m, p.y);
    }
    o.bounds = b;
  }
  if (width_px > 0) {
    o.width_px = width_px;
    o.height_px = width_px * 3 / 4;
  }
  viewer::WorldToImage to_image;
  render::Scene scene = viewer::ExperienceMapScene(image, o, &to_image);
  std::vector<render::ScenePoint> line_px;
  for (uint32_t e : r.path) line_px.push_back(to_image(r.graph.nodes[e].x, r.graph.nodes[e].y));
  scene.Polyline(line_px, 6.0f, {148, 103, 189, 230});  // purple: red marks loop closures
  scene.Disc(line_px.front(), 9.0f, {44, 160, 44, 255}, 20);
  scene.Ring(line_px.back(), 8.0f, 12.0f, 0.0f, 6.2832f, {148, 103, 189, 255}, 24);
  if (point) {
    const render::ScenePoint p = to_image(point->x, point->y);
    scene.Line({p.x - 9, p.y - 9}, {p.x + 9, p.y + 9}, 3.0f, viewer::kInk);
    scene.Line({p.x - 9, p.y + 9}, {p.x + 9, p.y - 9}, 3.0f, viewer::kInk);
  }
  std::string legend = "purple: route   green: start   ring: end";
  if (point) {
    const std::string full = legend + "   x: the point asked for";
    // A one-column page has no room for the long form.
    legend =
        render::TextWidthPx(full, 15.0f) <= o.width_px - 60.0f ? full : legend + "   x: --to-xy";
  }
  scene.Text({30, 75}, legend, 15.0f, viewer::kInk);
  return scene;
}

// route.csv, route.json and route.png into --out.
Status WriteRouteFiles(const Arguments& args, const session::RobotMap& map, const Route& r,
                       const std::string& json) {
  std::ostringstream csv;
  csv << "step,experience_id,x_m,y_m,distance_m\n";
  for (size_t k = 0; k < r.path.size(); ++k) {
    const Point2& p = r.graph.nodes[r.path[k]];
    csv << k << ',' << r.path[k] << ',' << ShortestNumber(p.x) << ',' << ShortestNumber(p.y) << ','
        << ShortestNumber(r.distance_m[r.path[k]]) << '\n';
  }
  StatusOr<std::unique_ptr<DiskFolder>> folder = DiskFolder::Open(args.values.at("--out"));
  if (!folder.ok()) return folder.status();
  RATSLAM_RETURN_IF_ERROR(folder.value()->Write({{"route.csv", csv.str()}, {"route.json", json}}));
  return WriteCommandFigure(args, folder.value()->Path("route.png"),
                            [&](int width_px) { return RouteScene(map, r, width_px); });
}

}  // namespace

int RouteCommand(const Arguments& args) {
  auto fail = [](const Status& s) {
    std::cerr << MessagePrefix() << s.message() << "\n";
    return kExitError;
  };
  const bool to_id = args.values.count("--to") > 0, to_xy = args.values.count("--to-xy") > 0;
  if (to_id == to_xy) {
    std::cerr << MessagePrefix() << "give exactly one of --to E and --to-xy X,Y\n"
              << "Run 'ratslam route --help' for the options.\n";
    return kExitUsage;
  }
  const std::string map_path = args.values.at("--map");
  StatusOr<session::RobotMap> map = session::LoadRobotMap(map_path);
  if (!map.ok()) return fail(map.status());
  const int64_t n = static_cast<int64_t>(map->experiences.size());
  auto experience = [&](const char* flag) -> std::optional<uint32_t> {
    const int64_t id = args.Whole(flag);  // >= 0 by the parser; below n by this check
    if (id >= n) {
      std::cerr << MessagePrefix() << flag << ": no experience " << id << " in " << map_path
                << " (it has 0.." << n - 1 << ")\n";
      return std::nullopt;
    }
    return static_cast<uint32_t>(id);
  };
  uint32_t from = *map->current;
  if (args.values.count("--from")) {
    const std::optional<uint32_t> id = experience("--from");
    if (!id) return kExitError;
    from = *id;
  }
  phone::RouteGraph graph;
  for (const Experience& e : map->experiences) graph.nodes.push_back({e.x_m, e.y_m});
  for (const Link& l : map->links) graph.edges.push_back({l.from, l.to});
  std::vector<double> distance;
  std::vector<uint32_t> previous;
  phone::ShortestPaths(graph, from, &distance, &previous);

  uint32_t to = 0;
  std::optional<Point2> point;
  if (to_id) {
    const std::optional<uint32_t> id = experience("--to");
    if (!id) return kExitError;
    to = *id;
    if (!std::isfinite(distance[to])) {
      return fail(Status::Error("experience " + std::to_string(to) + " cannot be reached from " +
                                std::to_string(from) + " over the links of " + map_path));
    }
  } else {
    const std::vector<double>& xy = args.number_lists.at("--to-xy");
    point = Point2{xy[0], xy[1]};
    // The nearest experience the robot can reach (ties: the lower id).
    double best = std::numeric_limits<double>::infinity();
    for (uint32_t k = 0; k < graph.nodes.size(); ++k) {
      if (!std::isfinite(distance[k])) continue;
      const double d = std::hypot(graph.nodes[k].x - point->x, graph.nodes[k].y - point->y);
      if (d < best) best = d, to = k;
    }
  }
  std::vector<uint32_t> path = {to};
  while (path.back() != from) path.push_back(previous[path.back()]);
  std::reverse(path.begin(), path.end());

  nlohmann::ordered_json j;
  j["map"] = map_path;
  j["from"] = from;
  j["to"] = to;
  if (point) {
    j["to_point"] = {{"x_m", point->x}, {"y_m", point->y}};
    j["to_point_distance_m"] =
        std::hypot(graph.nodes[to].x - point->x, graph.nodes[to].y - point->y);
  }
  j["length_m"] = distance[to];
  j["straight_line_m"] =
      std::hypot(graph.nodes[to].x - graph.nodes[from].x, graph.nodes[to].y - graph.nodes[from].y);
  j["experiences"] = path;
  const std::string json = j.dump(2) + "\n";

  char line[256];
  std::snprintf(line, sizeof line, "%.1f m from experience %u to %u through %zu experiences",
                distance[to], from, to, path.size());
  std::string human = MessagePrefix() + line + "\n";
  if (point) {
    std::snprintf(line, sizeof line, "experience %u is %.1f m from (%s, %s)\n", to,
                  j["to_point_distance_m"].get<double>(), ShortestNumber(point->x).c_str(),
                  ShortestNumber(point->y).c_str());
    human += MessagePrefix() + line;
  }
  std::string ids;
  for (size_t k = 0; k < path.size(); ++k) ids += (k ? " " : "") + std::to_string(path[k]);
  human += MessagePrefix() + "experiences: " + ids + "\n";

  if (args.values.count("--out")) {
    if (Status s = WriteRouteFiles(args, *map, {graph, distance, path, point}, json); !s.ok()) {
      return fail(s);
    }
    human += MessagePrefix() + "outputs in " + args.Shown(args.values.at("--out")) +
             " (route.json, route.csv, route.png)\n";
  }
  PrintOutcome(args.values.count("--json") > 0, args.quiet, json, human);
  return kExitOk;
}

}  // namespace ratslam::apps
