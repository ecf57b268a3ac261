#include "viewer/figure_output.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "render/image.h"

namespace ratslam::viewer {

StatusOr<std::vector<FigureFormat>> ParseFigureFormats(const std::string& list) {
  std::vector<FigureFormat> formats;
  std::istringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    FigureFormat f;
    if (item == "png") {
      f = FigureFormat::kPng;
    } else if (item == "pdf") {
      f = FigureFormat::kPdf;
    } else if (item == "svg") {
      f = FigureFormat::kSvg;
    } else {
      return Status::Error("unknown figure format '" + item + "' (png, pdf or svg)");
    }
    if (std::find(formats.begin(), formats.end(), f) != formats.end()) {
      return Status::Error("figure format '" + item + "' given twice");
    }
    formats.push_back(f);
  }
  if (formats.empty()) return Status::Error("no figure format (png, pdf or svg)");
  return formats;
}

const char* FigureExtension(FigureFormat format) {
  switch (format) {
    case FigureFormat::kPdf:
      return ".pdf";
    case FigureFormat::kSvg:
      return ".svg";
    default:
      return ".png";
  }
}

FigureFormat FormatOfPath(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".pdf") return FigureFormat::kPdf;
  if (ext == ".svg") return FigureFormat::kSvg;
  return FigureFormat::kPng;
}

std::pair<int, int> VectorLayoutSize(int width_px, int height_px, double width_mm) {
  const int w = render::VectorLayoutWidthPx(width_mm);
  const int h = std::max(
      1, static_cast<int>(std::lround(static_cast<double>(w) * height_px / std::max(1, width_px))));
  return {w, h};
}

std::vector<FigureTarget> FigureTargets(const std::string& path,
                                        const std::vector<FigureFormat>* formats) {
  if (formats == nullptr) return {{FormatOfPath(path), path}};
  std::filesystem::path stem(path);
  const std::string ext = stem.extension().string();
  if (ext == ".png" || ext == ".pdf" || ext == ".svg") stem.replace_extension();
  std::vector<FigureTarget> targets;
  for (FigureFormat f : *formats) targets.push_back({f, stem.string() + FigureExtension(f)});
  return targets;
}

render::VectorFormat VectorFormatOf(FigureFormat format) {
  return format == FigureFormat::kPdf ? render::VectorFormat::kPdf : render::VectorFormat::kSvg;
}

StatusOr<std::unique_ptr<render::SceneRenderer>> RendererFor(
    const std::vector<FigureTarget>& targets) {
  for (const FigureTarget& t : targets) {
    if (t.format == FigureFormat::kPng) return render::CreateOsMesaRenderer();
  }
  return std::unique_ptr<render::SceneRenderer>();
}

Status WriteFigure(render::SceneRenderer* renderer, const SceneBuilder& build, int width_px,
                   int height_px, const std::vector<FigureTarget>& targets, double width_mm) {
  return WriteNaturalFigure(
      renderer,
      [&](int layout_width_px) {
        if (layout_width_px == 0) return build(width_px, height_px);
        const auto [w, h] = VectorLayoutSize(width_px, height_px, width_mm);
        return build(w, h);
      },
      targets, width_mm);
}

Status WriteNaturalFigure(render::SceneRenderer* renderer,
                          const std::function<render::Scene(int width_px)>& build,
                          const std::vector<FigureTarget>& targets, double width_mm) {
  for (const FigureTarget& target : targets) {
    if (target.format == FigureFormat::kPng) {
      if (renderer == nullptr) return Status::Error(target.path + ": no PNG renderer");
      StatusOr<render::RgbaImage> image = renderer->Render(build(0));
      if (!image.ok()) return image.status().WithContext(target.path);
      RATSLAM_RETURN_IF_ERROR(render::WritePng(image.value(), target.path));
    } else {
      RATSLAM_RETURN_IF_ERROR(
          render::WriteVectorFigure(build(render::VectorLayoutWidthPx(width_mm)), target.path,
                                    VectorFormatOf(target.format), width_mm));
    }
  }
  return Status::Ok();
}

}  // namespace ratslam::viewer
