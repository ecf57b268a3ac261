// The built-in worlds (see world.h). Each is a plain World built in code; `ratslam simulate
// --world NAME` writes it as TOML beside its outputs, to be edited and reused.
#include <cmath>

#include "sim/world.h"

namespace ratslam::sim {

namespace {

const char* const kWallTextures[] = {"posters", "brick", "stripes", "door",   "wood",
                                     "checker", "tiles", "noise",   "plaster"};

// A varied texture for wall segment k: kinds cycle with a variant so that few repeat.
std::string Texture(int k, int salt) {
  const int kinds = sizeof(kWallTextures) / sizeof(kWallTextures[0]);
  return std::string(kWallTextures[(k * 7 + salt) % kinds]) + ":" + std::to_string(k + 13 * salt);
}

void AddWall(World* w, int floor, Point2 a, Point2 b, const std::string& material,
             const std::string& texture) {
  Wall wall;
  wall.floor = floor;
  wall.from = a;
  wall.to = b;
  wall.material = material;
  wall.texture = texture;
  w->walls.push_back(wall);
}

// A wall from a to b cut into segments about `segment_m` long, each with its own texture.
void AddTexturedWall(World* w, int floor, Point2 a, Point2 b, double segment_m, int salt,
                     const std::string& material, int* counter) {
  const double length = std::hypot(b.x_m - a.x_m, b.y_m - a.y_m);
  const int n = std::max(1, static_cast<int>(std::lround(length / segment_m)));
  for (int i = 0; i < n; ++i) {
    const double t0 = static_cast<double>(i) / n, t1 = static_cast<double>(i + 1) / n;
    AddWall(w, floor, {a.x_m + t0 * (b.x_m - a.x_m), a.y_m + t0 * (b.y_m - a.y_m)},
            {a.x_m + t1 * (b.x_m - a.x_m), a.y_m + t1 * (b.y_m - a.y_m)}, material,
            Texture((*counter)++, salt));
  }
}

void AddAccessPoint(World* w, const std::string& name, Point2 at, int floor, int channel) {
  AccessPoint ap;
  ap.name = name;
  ap.position = at;
  ap.floor = floor;
  ap.channel = channel;
  w->access_points.push_back(ap);
}

// A rectangular corridor loop: outer rectangle (x0,y0)-(x1,y1), corridor `width` wide inside.
void RectangularLoop(World* w, int floor, double x0, double y0, double x1, double y1, double width,
                     int salt) {
  int k = 0;
  const Point2 o[4] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  const Point2 i[4] = {{x0 + width, y0 + width},
                       {x1 - width, y0 + width},
                       {x1 - width, y1 - width},
                       {x0 + width, y1 - width}};
  for (int s = 0; s < 4; ++s) {
    AddTexturedWall(w, floor, o[s], o[(s + 1) % 4], 4.0, salt, "concrete", &k);
    AddTexturedWall(w, floor, i[s], i[(s + 1) % 4], 4.0, salt + 1, "drywall", &k);
  }
}

World Office() {
  World w;
  w.name = "office";
  // A 40 m corridor, 2.4 m wide, offices on both sides behind drywall, concrete outer walls.
  int k = 0;
  AddTexturedWall(&w, 0, {0, 0}, {40, 0}, 4.0, 1, "drywall", &k);
  AddTexturedWall(&w, 0, {0, 2.4}, {40, 2.4}, 4.0, 2, "drywall", &k);
  AddWall(&w, 0, {0, 0}, {0, 2.4}, "concrete", "posters:900");
  AddWall(&w, 0, {40, 0}, {40, 2.4}, "concrete", "brick:901");
  AddWall(&w, 0, {0, -6}, {40, -6}, "concrete", "plaster");
  AddWall(&w, 0, {0, 8.4}, {40, 8.4}, "concrete", "plaster");
  for (int x = 0; x <= 40; x += 8) {
    AddWall(&w, 0, {static_cast<double>(x), -6}, {static_cast<double>(x), 0}, "drywall", "plaster");
    AddWall(&w, 0, {static_cast<double>(x), 2.4}, {static_cast<double>(x), 8.4}, "drywall",
            "plaster");
  }
  for (int i = 0; i < 6; ++i) {
    AddAccessPoint(&w, "office-ap-" + std::to_string(i), {4.0 + 6.5 * i, i % 2 ? 5.0 : -3.0}, 0,
                   i % 3 == 0   ? 1
                   : i % 3 == 1 ? 6
                                : 11);
  }
  Disturbance d;
  d.position = {20, 0.5};
  d.radius_m = 1.5;
  d.strength_deg = 25;
  w.disturbances.push_back(d);
  Person p;
  p.from = {5, 1.6};
  p.to = {30, 1.6};
  w.people.push_back(p);
  w.routes.push_back({"corridor", {{{1.0, 1.2}, 0}, {{39.0, 1.2}, 0}}, false});
  Session s;
  s.route = "corridor";
  s.laps = 6;  // up and down three times
  w.sessions.push_back(s);
  return w;
}

World Circular() {
  World w;
  w.name = "circular";
  // A ring corridor between radii 10 m and 13 m (24-sided), rooms outside it.
  const int n = 24;
  int k = 0;
  auto at = [](double r, int i) {
    const double a = 2 * M_PI * i / 24;
    return Point2{r * std::cos(a), r * std::sin(a)};
  };
  for (int i = 0; i < n; ++i) {
    AddWall(&w, 0, at(10, i), at(10, i + 1), "drywall", Texture(k++, 3));
    AddWall(&w, 0, at(13, i), at(13, i + 1), "drywall", Texture(k++, 4));
    if (i % 4 == 0) AddWall(&w, 0, at(13, i), at(19, i), "concrete", "plaster");
  }
  for (int i = 0; i < 8; ++i) {
    AddAccessPoint(&w, "ring-ap-" + std::to_string(i), at(i % 2 ? 16 : 7, 3 * i + 1), 0,
                   1 + 5 * (i % 3));
  }
  Route r;
  r.name = "there-and-back";
  // 2.5 laps counter-clockwise, then 2.5 laps clockwise back to the start.
  const int steps = static_cast<int>(2.5 * n);
  for (int i = 0; i <= steps; ++i) r.points.push_back({at(11.5, i), 0});
  for (int i = steps - 1; i >= 0; --i) r.points.push_back({at(11.5, i), 0});
  w.routes.push_back(r);
  Session s;
  s.route = r.name;
  w.sessions.push_back(s);
  return w;
}

World DayNight() {
  World w;
  w.name = "day_night";
  RectangularLoop(&w, 0, 0, 0, 60, 30, 3.0, 5);
  for (int i = 0; i < 10; ++i) {
    const Point2 p = i < 5 ? Point2{6.0 + 12 * i, i % 2 ? -3.0 : 6.0}
                           : Point2{6.0 + 12 * (i - 5), i % 2 ? 24.0 : 33.0};
    AddAccessPoint(&w, "loop-ap-" + std::to_string(i), p, 0, 1 + 5 * (i % 3));
  }
  w.routes.push_back(
      {"loop", {{{1.5, 1.5}, 0}, {{58.5, 1.5}, 0}, {{58.5, 28.5}, 0}, {{1.5, 28.5}, 0}}, true});
  Session day, night;
  day.route = night.route = "loop";
  day.laps = night.laps = 1.0;
  night.lighting = "night";
  w.sessions = {day, night};
  return w;
}

World AliasedFloors() {
  World w;
  w.name = "aliased_floors";
  // Two floors built from the same walls and textures; each has its own access points.
  for (int floor = 0; floor < 2; ++floor) {
    RectangularLoop(&w, floor, 0, 0, 30, 16, 3.0, 7);
    for (int i = 0; i < 5; ++i) {
      AddAccessPoint(&w, "floor" + std::to_string(floor) + "-ap-" + std::to_string(i),
                     {3.0 + 6 * i, i % 2 ? 8.0 : -2.0}, floor, 1 + 5 * (i % 3));
    }
  }
  Route r;
  r.name = "both-floors";
  const Point2 corners[4] = {{1.5, 1.5}, {28.5, 1.5}, {28.5, 14.5}, {1.5, 14.5}};
  // Floor 0 round, lift up, floor 1 round, lift down; two sessions (map and query).
  for (int floor : {0, 1}) {
    for (int c = 0; c < 4; ++c) r.points.push_back({corners[c], floor});
    r.points.push_back({corners[0], floor});
  }
  r.points.push_back({corners[0], 0});
  w.routes.push_back(r);
  Session s;
  s.route = r.name;
  w.sessions = {s, s};
  return w;
}

World Apartment() {
  World w;
  w.name = "apartment";
  // 12 m x 8 m, four rooms: walls at y = 4 and x = 6 with 1 m doorways.
  int k = 0;
  AddTexturedWall(&w, 0, {0, 0}, {12, 0}, 3.0, 9, "concrete", &k);
  AddTexturedWall(&w, 0, {12, 0}, {12, 8}, 3.0, 9, "concrete", &k);
  AddTexturedWall(&w, 0, {12, 8}, {0, 8}, 3.0, 9, "concrete", &k);
  AddTexturedWall(&w, 0, {0, 8}, {0, 0}, 3.0, 9, "concrete", &k);
  AddWall(&w, 0, {0, 4}, {2.5, 4}, "drywall", "posters:31");
  AddWall(&w, 0, {3.5, 4}, {6, 4}, "drywall", "stripes:32");
  AddWall(&w, 0, {6, 4}, {8.5, 4}, "drywall", "checker:33");
  AddWall(&w, 0, {9.5, 4}, {12, 4}, "drywall", "tiles:34");
  AddWall(&w, 0, {6, 0}, {6, 1}, "drywall", "wood:1");
  AddWall(&w, 0, {6, 2}, {6, 6}, "drywall", "wood:2");
  AddWall(&w, 0, {6, 7}, {6, 8}, "drywall", "wood:3");
  AddAccessPoint(&w, "home-router", {3, 2}, 0, 6);
  AddAccessPoint(&w, "home-extender", {10, 6}, 0, 44);
  AddAccessPoint(&w, "neighbour-west", {-6, 4}, 0, 1);
  AddAccessPoint(&w, "neighbour-east", {18, 3}, 0, 11);
  AddAccessPoint(&w, "neighbour-above", {6, 4}, 1, 6);
  // Through all four rooms by their doorways.
  w.routes.push_back({"rooms",
                      {{{1.5, 1.5}, 0},
                       {{4.5, 1.5}, 0},
                       {{7.5, 1.5}, 0},
                       {{10.5, 1.5}, 0},
                       {{10.5, 3}, 0},
                       {{9, 3}, 0},
                       {{9, 5}, 0},
                       {{10.5, 6.5}, 0},
                       {{4.5, 6.5}, 0},
                       {{3, 5}, 0},
                       {{3, 3}, 0}},
                      true});
  w.wifi.path_loss_exponent = 2.5;
  Session s;  // three visits: one to map, two to query (FABMAP evaluation by session)
  s.route = "rooms";
  w.sessions = {s, s, s};
  return w;
}

}  // namespace

std::vector<std::string> BuiltInWorldNames() {
  return {"office", "circular", "day_night", "aliased_floors", "apartment"};
}

StatusOr<World> BuiltInWorld(const std::string& name) {
  World w;
  if (name == "office") {
    w = Office();
  } else if (name == "circular") {
    w = Circular();
  } else if (name == "day_night") {
    w = DayNight();
  } else if (name == "aliased_floors") {
    w = AliasedFloors();
  } else if (name == "apartment") {
    w = Apartment();
  } else {
    std::string names;
    for (const std::string& n : BuiltInWorldNames()) names += (names.empty() ? "" : ", ") + n;
    return Status::Error("unknown built-in world '" + name + "' (built in: " + names + ")");
  }
  RATSLAM_RETURN_IF_ERROR(w.Validate());
  return w;
}

}  // namespace ratslam::sim
