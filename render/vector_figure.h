// Vector output of our 2D scenes (PDF and SVG through Cairo), beside the OSMesa PNG path: true
// strokes, circles and rectangles from the scene's shapes, and text set in a real font
// (DejaVu Sans through fontconfig; embedded in the PDF, glyph outlines in the SVG).
//
// A scene is laid out in pixels; a vector figure maps its width onto a page `width_mm` wide, so
// a text `height_px` high (cap height, as the PNG path draws it) comes out at
// height_px / kCapHeightPerEm * (page width in points / scene width in pixels) points.
// VectorLayoutWidthPx picks the pixel width at which a figure's smallest text is legible on a
// page of a given width.
#ifndef RATSLAM_RENDER_VECTOR_FIGURE_H_
#define RATSLAM_RENDER_VECTOR_FIGURE_H_

#include <string>

#include "common/status.h"
#include "render/scene.h"

namespace ratslam::render {

enum class VectorFormat { kPdf, kSvg };

// DejaVu Sans: cap height 0.729 em (its OS/2 table: 1493 of 2048 units).
inline constexpr double kCapHeightPerEm = 0.729;
// The smallest text size a journal accepts in a figure (7 pt at print size).
inline constexpr double kMinTextPt = 7.0;
// A one-column figure (88 mm), the default page width, and a two-column one (180 mm).
inline constexpr double kOneColumnMm = 88.0;
inline constexpr double kTwoColumnMm = 180.0;

inline double MillimetresToPoints(double mm) { return mm / 25.4 * 72.0; }

// The scene width in pixels that puts text of `smallest_text_px` (cap height) at exactly
// kMinTextPt on a page `width_mm` wide. Our figures' smallest text is 13 px, so a one-column
// figure is laid out about 620 px wide.
int VectorLayoutWidthPx(double width_mm, float smallest_text_px = 13.0f);

// The size in points that text `height_px` high gets when `scene_width_px` becomes `width_mm`.
double TextPoints(float height_px, int scene_width_px, double width_mm);

// Writes `scene` as a PDF or SVG page `width_mm` wide (the height keeps the scene's aspect).
// The file is replaced atomically; an error names it. Same scene, same bytes.
Status WriteVectorFigure(const Scene& scene, const std::string& path, VectorFormat format,
                         double width_mm = kOneColumnMm);

}  // namespace ratslam::render

#endif  // RATSLAM_RENDER_VECTOR_FIGURE_H_
