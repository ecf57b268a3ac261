#include "dataset/synthetic_dataset.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <opencv2/imgcodecs.hpp>

#include "common/circular.h"
#include "common/file_util.h"
#include "common/random.h"

namespace ratslam::dataset {
namespace {

constexpr double kPi = std::numbers::pi;

struct Pose {
  double x, y, theta;
};

// A rounded rectangle centred on the origin, driven counter-clockwise, parametrised by arc length.
class LoopPath {
 public:
  LoopPath(double length, double width, double radius)
      : straight_x_(length - 2 * radius), straight_y_(width - 2 * radius), radius_(radius) {}

  double Perimeter() const { return 2 * straight_x_ + 2 * straight_y_ + 2 * kPi * radius_; }

  // Pose at arc length s, pushed `offset` metres to the left of the direction of travel.
  Pose At(double s, double offset) const {
    s = WrapCoordinate(s, Perimeter());
    const double hx = straight_x_ / 2, hy = straight_y_ / 2;
    const double arc = kPi / 2 * radius_;
    // Segments: bottom edge (east), corner, right edge (north), corner, top (west), corner,
    // left edge (south), corner.
    const double lengths[8] = {straight_x_, arc, straight_y_, arc,
                               straight_x_, arc, straight_y_, arc};
    const double start_headings[4] = {0, kPi / 2, kPi, 3 * kPi / 2};
    const double corners[4][2] = {{hx, -hy}, {hx, hy}, {-hx, hy}, {-hx, -hy}};
    const double starts[4][2] = {
        {-hx, -hy - radius_}, {hx + radius_, -hy}, {hx, hy + radius_}, {-hx - radius_, hy}};
    Pose p{};
    for (int i = 0; i < 8; ++i) {
      if (s <= lengths[i] || i == 7) {
        const int side = i / 2;
        const double heading = start_headings[side];
        if (i % 2 == 0) {
          p = {starts[side][0] + s * std::cos(heading), starts[side][1] + s * std::sin(heading),
               heading};
        } else {
          const double angle = heading - kPi / 2 + s / radius_;  // angle around the corner
          p = {corners[side][0] + radius_ * std::cos(angle),
               corners[side][1] + radius_ * std::sin(angle), heading + s / radius_};
        }
        break;
      }
      s -= lengths[i];
    }
    p.x -= offset * std::sin(p.theta);
    p.y += offset * std::cos(p.theta);
    p.theta = WrapAngle(p.theta);
    return p;
  }

  // Distance from a point to the path (for keeping pillars off it).
  double DistanceTo(double x, double y) const {
    const double hx = straight_x_ / 2, hy = straight_y_ / 2;
    const double dx = std::max(std::abs(x) - hx, 0.0);
    const double dy = std::max(std::abs(y) - hy, 0.0);
    if (dx > 0 || dy > 0) return std::abs(std::hypot(dx, dy) - radius_);
    return std::min(hx + radius_ - std::abs(x), hy + radius_ - std::abs(y));
  }

 private:
  double straight_x_, straight_y_, radius_;
};

struct Pillar {
  double x, y, radius, height, brightness, stripes;
};

std::vector<Pillar> MakePillars(const SyntheticOptions& o, const LoopPath& path, Random& rng) {
  std::vector<Pillar> pillars;
  const double hx = o.loop_length_m / 2 + o.field_margin_m;
  const double hy = o.loop_width_m / 2 + o.field_margin_m;
  int attempts = 0;
  while (static_cast<int>(pillars.size()) < o.pillars && attempts++ < 100 * o.pillars) {
    Pillar p;
    p.x = rng.Uniform(-hx, hx);
    p.y = rng.Uniform(-hy, hy);
    p.radius = rng.Uniform(0.2, 0.8);
    p.height = rng.Uniform(1.0, 4.0);
    p.brightness = rng.Uniform(0.15, 0.95);
    p.stripes = std::floor(rng.Uniform(1.0, 7.0));
    if (path.DistanceTo(p.x, p.y) < o.pillar_clearance_m + p.radius) continue;
    pillars.push_back(p);
  }
  return pillars;
}

// Ray-casts the view from `pose` into `image` (8-bit grey, rows top to bottom).
void Render(const SyntheticOptions& o, const std::vector<Pillar>& pillars, const Pose& pose,
            Random& rng, cv::Mat& image) {
  const int w = o.image_width_px, h = o.image_height_px;
  const double horizon = 0.5 * h;
  const double focal_px = 0.5 * w / std::tan(0.5 * o.field_of_view_rad);
  const double camera_height_m = 0.5;
  for (int c = 0; c < w; ++c) {
    // Columns run clockwise: the left edge looks furthest to the left.
    const double bearing =
        pose.theta + 0.5 * o.field_of_view_rad - (c + 0.5) / w * o.field_of_view_rad;
    const double dx = std::cos(bearing), dy = std::sin(bearing);
    double nearest = 1e9;
    const Pillar* hit = nullptr;
    double hit_angle = 0.0;
    for (const Pillar& p : pillars) {
      const double px = p.x - pose.x, py = p.y - pose.y;
      const double along = px * dx + py * dy;
      if (along <= 0.0) continue;
      const double across2 = px * px + py * py - along * along;
      const double r2 = p.radius * p.radius;
      if (across2 > r2) continue;
      const double t = along - std::sqrt(r2 - across2);
      if (t > 0.0 && t < nearest) {
        nearest = t;
        hit = &p;
        hit_angle = std::atan2(pose.y + t * dy - p.y, pose.x + t * dx - p.x);
      }
    }
    for (int r = 0; r < h; ++r) {
      double value;
      if (r < horizon) {
        value = 0.55 + 0.25 * (horizon - r) / horizon;  // sky, brighter upwards
      } else {
        value = 0.30 - 0.15 * (r - horizon) / horizon;  // ground, darker towards the robot
      }
      if (hit) {
        const double top = horizon - focal_px * (hit->height - camera_height_m) / nearest;
        const double bottom = horizon + focal_px * camera_height_m / nearest;
        if (r + 0.5 >= top && r + 0.5 <= bottom) {
          const double texture = 0.5 + 0.5 * std::sin(hit->stripes * hit_angle);
          const double shade = 1.0 / (1.0 + 0.03 * nearest);
          value = (0.6 * hit->brightness + 0.4 * texture * hit->brightness) * shade;
        }
      }
      const double grey = value * 255.0 + rng.Gaussian(0.0, o.pixel_noise_grey);
      image.at<uint8_t>(r, c) = static_cast<uint8_t>(std::clamp(std::lround(grey), 0L, 255L));
    }
  }
}

}  // namespace

bool SyntheticOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (laps < 1) return fail("laps: must be at least 1");
  if (!(corner_radius_m > 0.0)) return fail("corner_radius_m: must be positive");
  if (!(loop_length_m > 2 * corner_radius_m) || !(loop_width_m > 2 * corner_radius_m)) {
    return fail("loop_length_m: loop must be larger than twice the corner radius");
  }
  if (!(speed_m_per_s > 0.0)) return fail("speed_m_per_s: must be positive");
  if (!(rate_hz > 0.0)) return fail("rate_hz: must be positive");
  if (image_width_px < 8 || image_height_px < 8) return fail("image_width_px: image too small");
  if (!(field_of_view_rad > 0.0 && field_of_view_rad < kPi)) {
    return fail("field_of_view_rad: must be in (0, pi)");
  }
  if (pillars < 0) return fail("pillars: must not be negative");
  if (!(start_m >= 0.0) || start_m > 1e6) return fail("start_m: must be in [0, 1e6]");
  return true;
}

StatusOr<Dataset> WriteSyntheticDataset(const SyntheticOptions& o, const std::string& folder) {
  std::string error;
  if (!o.IsValid(&error)) return Status::Error("synthetic data set: " + error);
  Random world_rng(o.seed);
  Random noise_rng(o.noise_seed != 0 ? o.noise_seed : o.seed ^ 0x5DEECE66DULL);
  const LoopPath path(o.loop_length_m, o.loop_width_m, o.corner_radius_m);
  const std::vector<Pillar> pillars = MakePillars(o, path, world_rng);

  Dataset d;
  d.name = "synthetic-loop-seed" + std::to_string(o.seed);
  if (o.noise_seed != 0) d.name += "-noise" + std::to_string(o.noise_seed);
  if (o.start_m != 0.0) d.name += "-from" + std::to_string(static_cast<long long>(o.start_m)) + "m";
  const double duration_s = o.laps * path.Perimeter() / o.speed_m_per_s;
  const int frames = static_cast<int>(std::floor(duration_s * o.rate_hz)) + 1;
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(folder) / d.image_folder, ec);
  if (ec) return Status::Error(folder + ": cannot create folder: " + ec.message());
  cv::Mat image(o.image_height_px, o.image_width_px, CV_8UC1);
  Pose previous{};
  for (int i = 0; i < frames; ++i) {
    const double t = i / o.rate_hz;
    const double s = o.start_m + t * o.speed_m_per_s;
    const int lap = static_cast<int>(s / path.Perimeter());
    // Blend the lateral offset smoothly between laps over the first 10 m of each lap.
    const double lap_start = lap * path.Perimeter();
    const double offset_now = (lap % 2 ? -1 : 1) * o.lap_offset_m;
    const double offset_before = lap == 0 ? offset_now : -offset_now;
    const double blend = std::clamp((s - lap_start) / 10.0, 0.0, 1.0);
    const Pose pose = path.At(s, offset_before + blend * (offset_now - offset_before));

    d.ground_truth.push_back({t, pose.x, pose.y, pose.theta, 0});
    OdometryRow odometry{t, 0.0, 0.0};
    if (i > 0) {
      const double dt = 1.0 / o.rate_hz;
      const double true_speed = std::hypot(pose.x - previous.x, pose.y - previous.y) / dt;
      const double true_turn = WrapAngle(pose.theta - previous.theta) / dt;
      odometry.forward_speed_m_per_s =
          true_speed * o.odometry_scale + noise_rng.Gaussian(0.0, o.speed_noise_m_per_s);
      odometry.turn_rate_rad_per_s = true_turn + o.turn_rate_bias_rad_per_s +
                                     noise_rng.Gaussian(0.0, o.turn_rate_noise_rad_per_s);
    }
    d.odometry.push_back(odometry);
    previous = pose;

    Render(o, pillars, pose, noise_rng, image);
    char name[32];
    std::snprintf(name, sizeof name, "%06d.png", i);
    const std::string path_out = (std::filesystem::path(folder) / d.image_folder / name).string();
    // Encoded in memory and written checked: a full disk is an error, never a 0-byte PNG.
    std::vector<uchar> png;
    if (!cv::imencode(".png", image, png)) return Status::Error(path_out + ": cannot encode image");
    RATSLAM_RETURN_IF_ERROR(WriteFileAtomically(path_out, std::string(png.begin(), png.end()),
                                                /*flush_to_disk=*/false));
    d.images.push_back({t, name, i + 2});
  }
  RATSLAM_RETURN_IF_ERROR(WriteDataset(d, folder));
  d.folder = folder;
  return d;
}

}  // namespace ratslam::dataset
