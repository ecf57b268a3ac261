#include "apps/demo_config.h"

namespace ratslam::apps {

fusion::PipelineOptions DemoPipelineOptions() {
  // As configs/sim-fused.toml (see the comments there).
  fusion::PipelineOptions o;
  o.sensors.front_end.kind = fusion::FrontEndKind::kFused;
  o.sensors.fused.use_camera = true;
  o.sensors.fused.use_wifi = true;
  o.sensors.fused.use_compass = true;
  o.sensors.fused.recency_s = 20.0;
  o.sensors.fused.max_wifi_age_s = 3.0;
  o.sensors.camera_12x9.match_threshold = 0.99;
  o.sensors.wifi.match_threshold = 0.25;
  o.ratslam.pose_cells.cell_size_m = 1.0;
  o.ratslam.local_view.injection_gain = 0.3;
  return o;
}

std::string DemoWorldName() { return "day_night"; }

fusion::PipelineOptions SyntheticPipelineOptions() {
  fusion::PipelineOptions o;
  // The synthetic camera is 120x40 px with the horizon at row 20: keep the band where the
  // pillars are, drop most of the featureless sky and ground.
  o.sensors.classic_camera.crop_top_px = 8;
  o.sensors.classic_camera.crop_bottom_px = 32;
  o.sensors.classic_camera.template_width_px = 60;
  o.sensors.classic_camera.template_height_px = 10;
  o.sensors.classic_camera.shift_px = 5;
  o.sensors.classic_camera.match_threshold = 0.03;
  // The loop is 40 m x 24 m: 30 cells of 1.5 m wrap every 45 m.
  o.ratslam.pose_cells.dim_xy_cells = 30;
  o.ratslam.pose_cells.cell_size_m = 1.5;
  return o;
}

dataset::SyntheticOptions DemoSyntheticOptions() { return dataset::SyntheticOptions(); }

}  // namespace ratslam::apps
