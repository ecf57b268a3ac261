// Writing a figure in the formats a user asks for: PNG through OSMesa (for screens), PDF and SVG
// through Cairo (for papers). A figure is a function from a pixel size to a scene; PNG is laid
// out at the requested pixel size, vector formats at the width that makes their smallest text
// legible on a page of the requested width in millimetres (render/vector_figure.h).
#ifndef RATSLAM_VIEWER_FIGURE_OUTPUT_H_
#define RATSLAM_VIEWER_FIGURE_OUTPUT_H_

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "render/vector_figure.h"

namespace ratslam::viewer {

enum class FigureFormat { kPng, kPdf, kSvg };

// "png", "pdf,svg", ...: each known at most once; an error names the unknown one.
StatusOr<std::vector<FigureFormat>> ParseFigureFormats(const std::string& list);
// ".png", ".pdf", ".svg".
const char* FigureExtension(FigureFormat format);
// The format a file name asks for by its extension (PNG when it names none we write).
FigureFormat FormatOfPath(const std::string& path);

// Where a figure goes: one file per format.
struct FigureTarget {
  FigureFormat format = FigureFormat::kPng;
  std::string path;
};

// The Cairo format of a PDF or SVG figure.
render::VectorFormat VectorFormatOf(FigureFormat format);

// A PNG renderer (OSMesa) when some target is a PNG, else null: PDF and SVG need none.
StatusOr<std::unique_ptr<render::SceneRenderer>> RendererFor(
    const std::vector<FigureTarget>& targets);

// A figure laid out for a pixel size.
using SceneBuilder = std::function<render::Scene(int width_px, int height_px)>;

// The builder of a figure whose options carry width_px and height_px: `draw(options)` at each
// size asked for.
template <typename Options, typename Draw>
SceneBuilder Sized(const Options& options, Draw draw) {
  return [options, draw](int width_px, int height_px) {
    Options o = options;
    o.width_px = width_px;
    o.height_px = height_px;
    return draw(o);
  };
}

// The files for `--out path`: with `formats` (--format), the path's stem plus each format's
// extension; without, the path itself in the format its extension names.
std::vector<FigureTarget> FigureTargets(const std::string& path,
                                        const std::vector<FigureFormat>* formats);

// Writes the figure to each target: PNG built at width_px x height_px and rendered by
// `renderer`; PDF and SVG built at VectorLayoutSize(...) and set on a page `width_mm` wide.
// `renderer` may be null when no target is a PNG.
Status WriteFigure(render::SceneRenderer* renderer, const SceneBuilder& build, int width_px,
                   int height_px, const std::vector<FigureTarget>& targets,
                   double width_mm = render::kOneColumnMm);

// A figure with a natural size: `build(0)` makes the PNG's scene, `build(w)` a scene laid out
// w pixels wide for PDF and SVG (w = VectorLayoutWidthPx(width_mm)).
Status WriteNaturalFigure(render::SceneRenderer* renderer,
                          const std::function<render::Scene(int width_px)>& build,
                          const std::vector<FigureTarget>& targets,
                          double width_mm = render::kOneColumnMm);

// The vector layout's size for a figure whose PNG is width_px x height_px.
std::pair<int, int> VectorLayoutSize(int width_px, int height_px, double width_mm);

}  // namespace ratslam::viewer

#endif  // RATSLAM_VIEWER_FIGURE_OUTPUT_H_
