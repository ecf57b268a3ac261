// Place descriptors computed outside this program, one per camera image of a data set, for the
// descriptor front end (front_end.h, kDescriptors). The file formats are in
// dataset/descriptor_file.h; io/front_end_resources.h finds a data set's files.
#ifndef RATSLAM_FUSION_DESCRIPTOR_TABLE_H_
#define RATSLAM_FUSION_DESCRIPTOR_TABLE_H_

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/descriptor_file.h"

namespace ratslam::fusion {

struct DescriptorOptions {
  // The data set's descriptor file (.npy or .csv, dataset/descriptor_file.h): a relative
  // name is looked up in each session's folder (beside a bag, video or phone log), so a
  // multi-session run finds one file per session; an absolute path serves a single session.
  std::string file = "descriptors.npy";
  double min_similarity = 0.9;  // least cosine similarity of the best stored descriptor to match
  int recency_templates = 0;    // matches to one of the newest this-many templates: no injection
  double recency_s = 10.0;      // nor to one made less than this long ago

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("file", file,
      "descriptors per camera image (.npy or .csv), relative to each session's folder or absolute",
      schema::Any());
    v("min_similarity", min_similarity,
      "least cosine similarity of the best stored descriptor for its template to become active",
      schema::Unit("").AtLeast(-1).AtMost(1));
    v("recency_templates", recency_templates,
      "matches to one of the newest this-many templates re-use it without injection",
      schema::Unit("templates").NonNegative());
    v("recency_s", recency_s, "so do matches to a template made less than this long ago",
      schema::Unit("s").NonNegative());
  }
};

// `values` (n of them) scaled to unit length, computed in double: the one normalisation of file
// rows and of descriptors fed directly. False (and `unit` untouched) when there is no direction:
// all zeros, or a length that overflows.
bool UnitDescriptor(const float* values, size_t n, std::vector<float>* unit);

// Unit-length descriptors keyed by the data set's image times.
class DescriptorTable {
 public:
  // Row i of `matrix` belongs to `dataset.images[i]`; `name` (the file) is for messages. Fails
  // when the counts differ, a row is all zeros (no direction, so no cosine), or two images share
  // a time with different descriptors.
  static StatusOr<std::shared_ptr<const DescriptorTable>> Make(
      const dataset::DescriptorMatrix& matrix, const dataset::Dataset& dataset,
      const std::string& name);

  size_t dimensions() const { return dimensions_; }
  size_t size() const { return times_s_.size(); }
  // The unit descriptor of the image at `time_s` (exactly one of the data set's image times),
  // or nullptr.
  const float* At(double time_s) const;

 private:
  size_t dimensions_ = 0;
  std::vector<double> times_s_;  // ascending
  std::vector<float> unit_;      // row-major, in times_s_ order
};

}  // namespace ratslam::fusion

#endif  // RATSLAM_FUSION_DESCRIPTOR_TABLE_H_
