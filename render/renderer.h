// Turns scenes into images. The interface lets figures be tested without a GL context.
#ifndef RATSLAM_RENDER_RENDERER_H_
#define RATSLAM_RENDER_RENDERER_H_

#include <memory>

#include "common/status.h"
#include "render/image.h"
#include "render/scene.h"

namespace ratslam::render {

class SceneRenderer {
 public:
  virtual ~SceneRenderer() = default;
  // Renders images, then triangles (antialiased, alpha-blended), then texts.
  virtual StatusOr<RgbaImage> Render(const Scene& scene) = 0;
};

// Headless OpenGL 3.3 core rendering through OSMesa (llvmpipe), loaded at run time with dlopen:
// no display, no X, no libGL. Fails with a clear message when libOSMesa is missing or a context
// cannot be made. The environment variable RATSLAM_OSMESA_LIBRARY selects a specific library.
StatusOr<std::unique_ptr<SceneRenderer>> CreateOsMesaRenderer();

// Renders `scene` with a new OSMesa renderer and writes it as PNG.
Status RenderToPng(const Scene& scene, const std::string& path);

}  // namespace ratslam::render

#endif  // RATSLAM_RENDER_RENDERER_H_
