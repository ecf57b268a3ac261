#include "render/scene.h"

#include <cmath>

namespace ratslam::render {

void Scene::Triangle(ScenePoint a, ScenePoint b, ScenePoint c, Rgba color) {
  SceneShape shape;
  shape.kind = SceneShape::Kind::kTriangle;
  shape.points = {a, b, c};
  shape.color = color;
  shapes_.push_back(std::move(shape));
  AddTriangle(a, b, c, color);
}

void Scene::AddTriangle(ScenePoint a, ScenePoint b, ScenePoint c, Rgba color) {
  triangles_.push_back({a.x, a.y, color});
  triangles_.push_back({b.x, b.y, color});
  triangles_.push_back({c.x, c.y, color});
}

void Scene::Line(ScenePoint a, ScenePoint b, float width_px, Rgba color) {
  if (a.x == b.x && a.y == b.y) return;
  SceneShape shape;
  shape.kind = SceneShape::Kind::kLine;
  shape.points = {a, b};
  shape.width_px = width_px;
  shape.color = color;
  shapes_.push_back(std::move(shape));
  AddLine(a, b, width_px, color);
}

void Scene::AddLine(ScenePoint a, ScenePoint b, float width_px, Rgba color) {
  const float dx = b.x - a.x, dy = b.y - a.y;
  const float length = std::sqrt(dx * dx + dy * dy);
  if (length <= 0.0f) return;
  // A quad around the segment, half the width either side.
  const float nx = -dy / length * 0.5f * width_px, ny = dx / length * 0.5f * width_px;
  const ScenePoint p0{a.x + nx, a.y + ny}, p1{b.x + nx, b.y + ny};
  const ScenePoint p2{b.x - nx, b.y - ny}, p3{a.x - nx, a.y - ny};
  AddTriangle(p0, p1, p2, color);
  AddTriangle(p0, p2, p3, color);
}

void Scene::Polyline(const std::vector<ScenePoint>& points, float width_px, Rgba color) {
  if (points.size() < 2) return;
  SceneShape shape;
  shape.kind = SceneShape::Kind::kPolyline;
  shape.points = points;
  shape.width_px = width_px;
  shape.color = color;
  shapes_.push_back(std::move(shape));
  for (size_t i = 1; i < points.size(); ++i) AddLine(points[i - 1], points[i], width_px, color);
}

void Scene::Disc(ScenePoint center, float radius_px, Rgba color, int segments) {
  SceneShape shape;
  shape.kind = SceneShape::Kind::kDisc;
  shape.points = {center};
  shape.radius_px = radius_px;
  shape.color = color;
  shapes_.push_back(std::move(shape));
  const float step = 2.0f * static_cast<float>(M_PI) / segments;
  for (int i = 0; i < segments; ++i) {
    AddTriangle(
        center,
        {center.x + radius_px * std::cos(i * step), center.y + radius_px * std::sin(i * step)},
        {center.x + radius_px * std::cos((i + 1) * step),
         center.y + radius_px * std::sin((i + 1) * step)},
        color);
  }
}

void Scene::Ring(ScenePoint center, float inner_radius_px, float outer_radius_px, float start_rad,
                 float end_rad, Rgba color, int segments) {
  SceneShape shape;
  shape.kind = SceneShape::Kind::kRing;
  shape.points = {center};
  shape.radius_px = outer_radius_px;
  shape.inner_radius_px = inner_radius_px;
  shape.start_rad = start_rad;
  shape.end_rad = end_rad;
  shape.color = color;
  shapes_.push_back(std::move(shape));
  const float step = (end_rad - start_rad) / segments;
  for (int i = 0; i < segments; ++i) {
    const float a0 = start_rad + i * step, a1 = a0 + step;
    // Angles are counter-clockwise on screen (y points down, so negate the sine).
    const ScenePoint i0{center.x + inner_radius_px * std::cos(a0),
                        center.y - inner_radius_px * std::sin(a0)};
    const ScenePoint i1{center.x + inner_radius_px * std::cos(a1),
                        center.y - inner_radius_px * std::sin(a1)};
    const ScenePoint o0{center.x + outer_radius_px * std::cos(a0),
                        center.y - outer_radius_px * std::sin(a0)};
    const ScenePoint o1{center.x + outer_radius_px * std::cos(a1),
                        center.y - outer_radius_px * std::sin(a1)};
    AddTriangle(i0, o0, o1, color);
    AddTriangle(i0, o1, i1, color);
  }
}

void Scene::Rect(float left, float top, float width, float height, Rgba color) {
  const ScenePoint a{left, top}, b{left + width, top}, c{left + width, top + height},
      d{left, top + height};
  SceneShape shape;
  shape.kind = SceneShape::Kind::kRect;
  shape.points = {a, c};
  shape.color = color;
  shapes_.push_back(std::move(shape));
  AddTriangle(a, b, c, color);
  AddTriangle(a, c, d, color);
}

void Scene::Text(ScenePoint position, std::string text, float height_px, Rgba color,
                 TextAnchor anchor) {
  texts_.push_back({position, std::move(text), height_px, color, anchor});
}

void Scene::Append(const Scene& other, float dx, float dy) {
  for (const Vertex& v : other.triangles_) triangles_.push_back({v.x + dx, v.y + dy, v.color});
  for (SceneShape shape : other.shapes_) {
    for (ScenePoint& p : shape.points) p = {p.x + dx, p.y + dy};
    shapes_.push_back(std::move(shape));
  }
  for (SceneImage image : other.images_) {
    image.left += dx;
    image.top += dy;
    images_.push_back(std::move(image));
  }
  for (SceneText text : other.texts_) {
    text.position = {text.position.x + dx, text.position.y + dy};
    texts_.push_back(std::move(text));
  }
}

}  // namespace ratslam::render
