#include "sensors/kernel_camera_matcher.h"

#include <cmath>
#include <stdexcept>

namespace ratslam::sensors {

bool KernelCameraOptions::IsValid(std::string* error) const {
  return schema::CheckFields(*this, error);
}

KernelCameraMatcher::KernelCameraMatcher(const KernelCameraOptions& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("KernelCameraOptions: " + error);
}

StatusOr<std::vector<float>> KernelCameraMatcher::MakeTemplate(const GrayImageView& image) const {
  const int w = options_.template_width_px, h = options_.template_height_px;
  if (image.pixels == nullptr || image.width < w || image.height < h) {
    return Status::Error("image of " + std::to_string(image.width) + "x" +
                         std::to_string(image.height) + " px is smaller than the " +
                         std::to_string(w) + "x" + std::to_string(h) + " template");
  }
  std::vector<float> t(static_cast<size_t>(w) * h);
  double mean = 0.0;
  for (int ty = 0; ty < h; ++ty) {
    const int y0 = ty * image.height / h, y1 = (ty + 1) * image.height / h;
    for (int tx = 0; tx < w; ++tx) {
      const int x0 = tx * image.width / w, x1 = (tx + 1) * image.width / w;
      uint64_t sum = 0;
      for (int y = y0; y < y1; ++y) {
        const uint8_t* row = image.pixels + static_cast<size_t>(y) * image.stride_bytes;
        for (int x = x0; x < x1; ++x) sum += row[x];
      }
      const double v = static_cast<double>(sum) / (255.0 * (x1 - x0) * (y1 - y0));
      t[static_cast<size_t>(ty) * w + tx] = static_cast<float>(v);
      mean += v;
    }
  }
  if (options_.subtract_mean) {
    mean /= static_cast<double>(t.size());
    for (float& v : t) v = static_cast<float>(v - mean);
  }
  return t;
}

double KernelCameraMatcher::Similarity(const std::vector<float>& a,
                                       const std::vector<float>& b) const {
  if (a.empty() || a.size() != b.size()) return 0.0;
  double sum = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = static_cast<double>(a[i]) - b[i];
    sum += d * d;
  }
  return std::exp(-sum / (2.0 * options_.kernel_sigma * options_.kernel_sigma));  // eq. 7
}

KernelCameraMatch KernelCameraMatcher::Best(const std::vector<float>& query,
                                            const std::vector<uint8_t>* allowed) const {
  KernelCameraMatch best;
  for (uint32_t id = 0; id < templates_.size(); ++id) {
    if (allowed && !(*allowed)[id]) continue;
    const double c = Similarity(query, templates_[id]);
    if (c > best.similarity) {
      best.similarity = c;
      best.id = static_cast<int32_t>(id);
    }
  }
  return best;
}

uint32_t KernelCameraMatcher::Add(const std::vector<float>& t) {
  templates_.push_back(t);
  return static_cast<uint32_t>(templates_.size() - 1);
}

Status KernelCameraMatcher::SetTemplates(std::vector<std::vector<float>> templates) {
  const size_t n = static_cast<size_t>(options_.template_width_px) * options_.template_height_px;
  for (const auto& t : templates) {
    if (!t.empty() && t.size() != n) {
      return Status::Error("camera templates: size does not match template_width x height");
    }
  }
  templates_ = std::move(templates);
  return Status::Ok();
}

}  // namespace ratslam::sensors
