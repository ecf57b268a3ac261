#include "render/vector_figure.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/file_util.h"

namespace ratslam::render {
namespace {

constexpr const char* kFontFamily = "DejaVu Sans";

cairo_status_t Append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

void SetColor(cairo_t* cr, Rgba c) {
  cairo_set_source_rgba(cr, c.r / 255.0, c.g / 255.0, c.b / 255.0, c.a / 255.0);
}

// The scene's RGBA image as a Cairo surface (premultiplied ARGB in native byte order).
cairo_surface_t* ImageSurface(const SceneImage& image) {
  cairo_surface_t* surface =
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, image.pixels_wide, image.pixels_high);
  if (cairo_surface_status(surface) != CAIRO_STATUS_SUCCESS) return surface;
  cairo_surface_flush(surface);
  unsigned char* data = cairo_image_surface_get_data(surface);
  const int stride = cairo_image_surface_get_stride(surface);
  for (int y = 0; y < image.pixels_high; ++y) {
    auto* row = reinterpret_cast<uint32_t*>(data + static_cast<size_t>(y) * stride);
    for (int x = 0; x < image.pixels_wide; ++x) {
      const uint8_t* p = &image.rgba[(static_cast<size_t>(y) * image.pixels_wide + x) * 4];
      const uint32_t a = p[3];
      auto premultiply = [a](uint32_t v) { return (v * a + 127) / 255; };
      row[x] = (a << 24) | (premultiply(p[0]) << 16) | (premultiply(p[1]) << 8) | premultiply(p[2]);
    }
  }
  cairo_surface_mark_dirty(surface);
  return surface;
}

void DrawImage(cairo_t* cr, const SceneImage& image) {
  if (image.pixels_wide <= 0 || image.pixels_high <= 0 ||
      image.rgba.size() != static_cast<size_t>(image.pixels_wide) * image.pixels_high * 4) {
    return;
  }
  cairo_surface_t* surface = ImageSurface(image);
  cairo_save(cr);
  cairo_rectangle(cr, image.left, image.top, image.width, image.height);
  cairo_clip(cr);
  cairo_translate(cr, image.left, image.top);
  cairo_scale(cr, image.width / image.pixels_wide, image.height / image.pixels_high);
  cairo_set_source_surface(cr, surface, 0, 0);
  cairo_pattern_set_filter(cairo_get_source(cr),
                           image.smooth ? CAIRO_FILTER_BILINEAR : CAIRO_FILTER_NEAREST);
  cairo_paint(cr);
  cairo_restore(cr);
  cairo_surface_destroy(surface);
}

void DrawShape(cairo_t* cr, const SceneShape& s) {
  SetColor(cr, s.color);
  switch (s.kind) {
    case SceneShape::Kind::kLine:
    case SceneShape::Kind::kPolyline:
      cairo_new_path(cr);
      cairo_move_to(cr, s.points[0].x, s.points[0].y);
      for (size_t i = 1; i < s.points.size(); ++i) cairo_line_to(cr, s.points[i].x, s.points[i].y);
      cairo_set_line_width(cr, s.width_px);
      cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
      cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
      cairo_stroke(cr);
      break;
    case SceneShape::Kind::kDisc:
      cairo_new_path(cr);
      cairo_arc(cr, s.points[0].x, s.points[0].y, s.radius_px, 0, 2 * M_PI);
      cairo_fill(cr);
      break;
    case SceneShape::Kind::kRing: {
      // Scene angles run counter-clockwise on screen (y down): Cairo's angle is the negative.
      const double cx = s.points[0].x, cy = s.points[0].y;
      const double a0 = -s.start_rad, a1 = -s.end_rad;
      cairo_new_path(cr);
      if (a1 <= a0) {
        cairo_arc_negative(cr, cx, cy, s.radius_px, a0, a1);
        cairo_arc(cr, cx, cy, s.inner_radius_px, a1, a0);
      } else {
        cairo_arc(cr, cx, cy, s.radius_px, a0, a1);
        cairo_arc_negative(cr, cx, cy, s.inner_radius_px, a1, a0);
      }
      cairo_close_path(cr);
      cairo_fill(cr);
      break;
    }
    case SceneShape::Kind::kRect:
      cairo_new_path(cr);
      cairo_rectangle(cr, s.points[0].x, s.points[0].y, s.points[1].x - s.points[0].x,
                      s.points[1].y - s.points[0].y);
      cairo_fill(cr);
      break;
    case SceneShape::Kind::kTriangle:
      cairo_new_path(cr);
      cairo_move_to(cr, s.points[0].x, s.points[0].y);
      cairo_line_to(cr, s.points[1].x, s.points[1].y);
      cairo_line_to(cr, s.points[2].x, s.points[2].y);
      cairo_close_path(cr);
      cairo_fill(cr);
      break;
  }
}

void DrawText(cairo_t* cr, const SceneText& t) {
  if (t.text.empty()) return;
  cairo_select_font_face(cr, kFontFamily, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, t.height_px / kCapHeightPerEm);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, t.text.c_str(), &extents);
  double x = t.position.x;
  if (t.anchor == TextAnchor::kCenter) x -= extents.x_advance / 2;
  if (t.anchor == TextAnchor::kRight) x -= extents.x_advance;
  SetColor(cr, t.color);
  cairo_move_to(cr, x, t.position.y);
  cairo_show_text(cr, t.text.c_str());
}

// Cairo numbers SVG ids (surface33, image37, clip1) with counters global to the process, so a
// second identical figure would differ. Renumbers them in order of first appearance, where they
// are defined (id="...") and referred to (#...). (A hand-written scan: std::regex trips GCC 12's
// maybe-uninitialized warning under the sanitizers.)
std::string CanonicalSvgIds(const std::string& svg) {
  static const char* const kKinds[] = {"surface", "image", "clip", "mask", "pattern", "source"};
  std::map<std::string, std::map<std::string, int>> renumbered;
  std::string out;
  out.reserve(svg.size());
  size_t i = 0;
  while (i < svg.size()) {
    size_t name = std::string::npos;  // where an id's name would start
    if (svg.compare(i, 4, "id=\"") == 0) name = i + 4;
    if (svg[i] == '#') name = i + 1;
    bool replaced = false;
    for (const char* kind : kKinds) {
      if (name == std::string::npos) break;
      const size_t length = std::char_traits<char>::length(kind);
      if (svg.compare(name, length, kind) != 0) continue;
      size_t end = name + length;
      while (end < svg.size() && std::isdigit(static_cast<unsigned char>(svg[end]))) ++end;
      if (end == name + length) continue;
      std::map<std::string, int>& numbers = renumbered[kind];
      const auto found = numbers.emplace(svg.substr(name + length, end - name - length),
                                         static_cast<int>(numbers.size()) + 1);
      out.append(svg, i, name - i);
      out += kind + std::to_string(found.first->second);
      i = end;
      replaced = true;
      break;
    }
    if (!replaced) out.push_back(svg[i++]);
  }
  return out;
}

}  // namespace

int VectorLayoutWidthPx(double width_mm, float smallest_text_px) {
  // smallest_text_px / kCapHeightPerEm * (points / pixels) = kMinTextPt.
  const double points = MillimetresToPoints(width_mm);
  return static_cast<int>(std::floor(points * smallest_text_px / kCapHeightPerEm / kMinTextPt));
}

double TextPoints(float height_px, int scene_width_px, double width_mm) {
  return height_px / kCapHeightPerEm * MillimetresToPoints(width_mm) / scene_width_px;
}

Status WriteVectorFigure(const Scene& scene, const std::string& path, VectorFormat format,
                         double width_mm) {
  if (scene.width() <= 0 || scene.height() <= 0 || !(width_mm > 0) || width_mm > 10000) {
    return Status::Error(path + ": cannot draw a " + std::to_string(scene.width()) + "x" +
                         std::to_string(scene.height()) + " scene " + std::to_string(width_mm) +
                         " mm wide");
  }
  const double scale = MillimetresToPoints(width_mm) / scene.width();
  const double page_w = scene.width() * scale, page_h = scene.height() * scale;
  std::string bytes;
  cairo_surface_t* surface =
      format == VectorFormat::kPdf
          ? cairo_pdf_surface_create_for_stream(Append, &bytes, page_w, page_h)
          : cairo_svg_surface_create_for_stream(Append, &bytes, page_w, page_h);
  if (format == VectorFormat::kPdf) {
    // No creation date: the same scene gives the same bytes.
    cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATOR, "ratslam");
    cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATE_DATE, "");
  } else {
    cairo_svg_surface_restrict_to_version(surface, CAIRO_SVG_VERSION_1_1);
  }
  cairo_t* cr = cairo_create(surface);
  cairo_scale(cr, scale, scale);
  SetColor(cr, scene.background());
  cairo_paint(cr);
  for (const SceneImage& image : scene.images()) DrawImage(cr, image);
  for (const SceneShape& shape : scene.shapes()) DrawShape(cr, shape);
  for (const SceneText& text : scene.texts()) DrawText(cr, text);
  cairo_show_page(cr);
  const cairo_status_t drawn = cairo_status(cr);
  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t finished = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  if (drawn != CAIRO_STATUS_SUCCESS || finished != CAIRO_STATUS_SUCCESS) {
    return Status::Error(path + ": Cairo: " +
                         cairo_status_to_string(drawn != CAIRO_STATUS_SUCCESS ? drawn : finished));
  }
  return WriteFileAtomically(path, format == VectorFormat::kSvg ? CanonicalSvgIds(bytes) : bytes);
}

}  // namespace ratslam::render
