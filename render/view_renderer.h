// Perspective views of a textured 3D world (the simulator's camera), rendered headlessly with
// OSMesa like the figures. World coordinates: x east, y north, z up, metres.
#ifndef RATSLAM_RENDER_VIEW_RENDERER_H_
#define RATSLAM_RENDER_VIEW_RENDERER_H_

#include <cstdint>
#include <memory>
#include <vector>

#include "common/gray_image.h"
#include "common/status.h"

namespace ratslam::render {

// One vertex of a textured triangle: (u, v) count texture repeats, `tile` picks the texture in
// the atlas, `shade` scales the texture's brightness (face orientation).
struct ViewVertex {
  float x, y, z;
  float u, v;
  float tile;
  float shade;
};

struct ViewMesh {
  uint64_t id = 0;        // meshes with the same id and size share their triangles (uploaded once)
  uint64_t atlas_id = 0;  // and meshes with the same atlas_id their texture atlas
  std::vector<ViewVertex> triangles;
  int tile_px = 64;            // each texture is tile_px x tile_px grey levels
  int tiles_per_side = 8;      // the atlas is a square of tiles_per_side^2 textures
  std::vector<uint8_t> atlas;  // (tile_px * tiles_per_side)^2 grey levels, rows top down
};

struct ViewCamera {
  double x_m = 0, y_m = 0, z_m = 1.2;
  double yaw_rad = 0;    // heading, counter-clockwise from east
  double pitch_rad = 0;  // up positive
  double horizontal_fov_deg = 90;
  int width_px = 64, height_px = 48;
  double near_m = 0.05, far_m = 200;
};

struct ViewLighting {
  double ambient = 1.0;            // brightness of the whole scene
  double headlight_gain = 0.0;     // extra brightness near the camera (night: a lamp)
  double headlight_range_m = 4.0;  // distance at which the lamp's light halves
};

class ViewRenderer {
 public:
  virtual ~ViewRenderer() = default;
  virtual StatusOr<GrayImage> Render(const ViewMesh& mesh, const ViewCamera& camera,
                                     const ViewLighting& lighting) = 0;
};

// OpenGL 3.3 core through OSMesa (see CreateOsMesaRenderer).
StatusOr<std::unique_ptr<ViewRenderer>> CreateOsMesaViewRenderer();

}  // namespace ratslam::render

#endif  // RATSLAM_RENDER_VIEW_RENDERER_H_
