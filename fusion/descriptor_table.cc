#include "fusion/descriptor_table.h"

#include <algorithm>
#include <cmath>

#include "common/number_text.h"

namespace ratslam::fusion {

bool DescriptorOptions::IsValid(std::string* error) const {
  if (!schema::CheckFields(*this, error)) return false;
  if (file.empty()) {
    if (error) *error = "file: empty (name the descriptor file, e.g. descriptors.npy)";
    return false;
  }
  return true;
}

bool UnitDescriptor(const float* values, size_t n, std::vector<float>* unit) {
  double norm2 = 0.0;
  for (size_t k = 0; k < n; ++k) norm2 += static_cast<double>(values[k]) * values[k];
  if (!(norm2 > 0.0) || !std::isfinite(norm2)) return false;
  const double inverse = 1.0 / std::sqrt(norm2);
  unit->resize(n);
  for (size_t k = 0; k < n; ++k) (*unit)[k] = static_cast<float>(values[k] * inverse);
  return true;
}

StatusOr<std::shared_ptr<const DescriptorTable>> DescriptorTable::Make(
    const dataset::DescriptorMatrix& matrix, const dataset::Dataset& dataset,
    const std::string& name) {
  if (matrix.rows != dataset.images.size()) {
    return Status::Error(name + ": " + std::to_string(matrix.rows) +
                         " descriptors, but data set '" + dataset.name + "' has " +
                         std::to_string(dataset.images.size()) +
                         " camera images (one descriptor per image, in image order)");
  }
  if (matrix.values.size() != matrix.rows * matrix.cols || matrix.cols == 0) {
    return Status::Error(name + ": malformed descriptor matrix");
  }
  auto table = std::make_shared<DescriptorTable>();
  table->dimensions_ = matrix.cols;
  const size_t d = matrix.cols;
  std::vector<float> unit;
  for (size_t i = 0; i < matrix.rows; ++i) {
    const double time_s = dataset.images[i].time_s;
    const std::string which =
        "descriptor " + std::to_string(i) + " (image at " + ShortestNumber(time_s) + " s)";
    if (!UnitDescriptor(matrix.values.data() + i * d, d, &unit)) {
      return Status::Error(name + ": " + which +
                           " has no length (all zeros, or too large to square): cosine "
                           "similarity needs a direction");
    }
    if (!table->times_s_.empty() && time_s <= table->times_s_.back()) {
      if (time_s < table->times_s_.back()) {
        return Status::Error(name + ": the data set's image times go backwards at " + which);
      }
      // Two images at one time: one descriptor must serve both.
      if (!std::equal(unit.begin(), unit.end(), table->unit_.end() - static_cast<ptrdiff_t>(d))) {
        return Status::Error(name + ": " + which +
                             " differs from the descriptor of the image before it, taken at "
                             "the same time; give the images distinct times");
      }
      continue;
    }
    table->times_s_.push_back(time_s);
    table->unit_.insert(table->unit_.end(), unit.begin(), unit.end());
  }
  return std::shared_ptr<const DescriptorTable>(std::move(table));
}

const float* DescriptorTable::At(double time_s) const {
  const auto it = std::lower_bound(times_s_.begin(), times_s_.end(), time_s);
  if (it == times_s_.end() || *it != time_s) return nullptr;
  return unit_.data() + static_cast<size_t>(it - times_s_.begin()) * dimensions_;
}

}  // namespace ratslam::fusion
