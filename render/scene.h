// A 2D scene in pixel coordinates (origin top-left, y down): the backend-independent description
// of an image. Figures build scenes; a SceneRenderer turns them into pixels.
#ifndef RATSLAM_RENDER_SCENE_H_
#define RATSLAM_RENDER_SCENE_H_

#include <cstdint>
#include <string>
#include <vector>

namespace ratslam::render {

struct Rgba {
  uint8_t r = 0, g = 0, b = 0, a = 255;
};

struct ScenePoint {
  float x = 0.0f;
  float y = 0.0f;
};

// A texture drawn into a rectangle (heat maps). Pixels are RGBA, rows top to bottom.
struct SceneImage {
  float left = 0, top = 0, width = 0, height = 0;
  int pixels_wide = 0, pixels_high = 0;
  std::vector<uint8_t> rgba;
  bool smooth = false;  // linear filtering instead of nearest
};

enum class TextAnchor { kLeft, kCenter, kRight };

struct SceneText {
  ScenePoint position;  // baseline point at the anchor
  std::string text;
  float height_px = 14;
  Rgba color;
  TextAnchor anchor = TextAnchor::kLeft;
};

// A drawing operation as the figure asked for it, for vector backends (PDF, SVG), which draw
// true strokes, circles and rectangles instead of the triangles an OpenGL backend needs.
struct SceneShape {
  enum class Kind { kLine, kPolyline, kDisc, kRing, kRect, kTriangle };
  Kind kind = Kind::kTriangle;
  // kLine, kPolyline: the points; kDisc, kRing: the centre; kRect: top-left and bottom-right;
  // kTriangle: the three corners.
  std::vector<ScenePoint> points;
  float width_px = 0;                        // kLine, kPolyline: stroke width
  float radius_px = 0, inner_radius_px = 0;  // kDisc: radius; kRing: outer and inner
  float start_rad = 0, end_rad = 0;          // kRing: counter-clockwise on screen
  Rgba color;
};

class Scene {
 public:
  Scene(int width_px, int height_px, Rgba background)
      : width_(width_px), height_(height_px), background_(background) {}

  // A straight segment of the given width (antialiased by the renderer).
  void Line(ScenePoint a, ScenePoint b, float width_px, Rgba color);
  void Polyline(const std::vector<ScenePoint>& points, float width_px, Rgba color);
  void Disc(ScenePoint center, float radius_px, Rgba color, int segments = 16);
  void Ring(ScenePoint center, float inner_radius_px, float outer_radius_px, float start_rad,
            float end_rad, Rgba color, int segments = 8);
  void Rect(float left, float top, float width, float height, Rgba color);
  void Triangle(ScenePoint a, ScenePoint b, ScenePoint c, Rgba color);
  void Image(SceneImage image) { images_.push_back(std::move(image)); }
  void Text(ScenePoint position, std::string text, float height_px, Rgba color,
            TextAnchor anchor = TextAnchor::kLeft);
  // Draws `other` (without its background) with its origin at (dx, dy): panels side by side.
  void Append(const Scene& other, float dx, float dy);

  struct Vertex {
    float x, y;
    Rgba color;
  };
  int width() const { return width_; }
  int height() const { return height_; }
  Rgba background() const { return background_; }
  // Triangles (three vertices each), drawn in order after the images.
  const std::vector<Vertex>& triangles() const { return triangles_; }
  // The same drawing as the shapes it was made of, in the same order.
  const std::vector<SceneShape>& shapes() const { return shapes_; }
  const std::vector<SceneImage>& images() const { return images_; }
  const std::vector<SceneText>& texts() const { return texts_; }

 private:
  int width_, height_;
  Rgba background_;
  void AddTriangle(ScenePoint a, ScenePoint b, ScenePoint c, Rgba color);
  void AddLine(ScenePoint a, ScenePoint b, float width_px, Rgba color);

  std::vector<Vertex> triangles_;
  std::vector<SceneShape> shapes_;
  std::vector<SceneImage> images_;
  std::vector<SceneText> texts_;
};

}  // namespace ratslam::render

#endif  // RATSLAM_RENDER_SCENE_H_
