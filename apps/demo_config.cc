#include "apps/demo_config.h"

namespace ratslam {

PipelineOptions DemoPipelineOptions() {
  PipelineOptions o;
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

SyntheticOptions DemoSyntheticOptions() { return SyntheticOptions(); }

}  // namespace ratslam
