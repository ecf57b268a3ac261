// Per-frame place descriptors computed outside this program (NetVLAD, a ViT, anything): one row
// of D floats per camera image of a data set, in image order. Two file formats:
//   .npy  NumPy's format (versions 1-3): a two-dimensional array (frames, D) of little-endian
//         float32 ('<f4') or float64 ('<f8'), C or Fortran order (numpy.save writes these).
//   .csv  (or .txt) one line per frame of D comma-separated numbers; an optional first line
//         whose first field is not a number is a header (its field count must be D too).
// Every value must be finite and within float range. Errors name the file and, for CSV, the
// line and column; for .npy the row and column of a bad value.
#ifndef RATSLAM_DATASET_DESCRIPTOR_FILE_H_
#define RATSLAM_DATASET_DESCRIPTOR_FILE_H_

#include <cstddef>
#include <string>
#include <vector>

#include "common/status.h"

namespace ratslam::dataset {

struct DescriptorMatrix {
  size_t rows = 0;            // frames
  size_t cols = 0;            // dimensions per descriptor
  std::vector<float> values;  // row-major, rows * cols
};

// Largest descriptor file read (bytes): 50k frames of 4096 float64 values fit with room.
inline constexpr size_t kMaxDescriptorFileBytes = size_t{4} << 30;

// Reads `path` by its extension (.npy, else CSV).
StatusOr<DescriptorMatrix> ReadDescriptorFile(const std::string& path);
// The same from bytes already in memory (`name` for messages); `npy` chooses the format.
StatusOr<DescriptorMatrix> ParseDescriptors(const std::string& bytes, const std::string& name,
                                            bool npy);

// Writes `m` as a version 1.0 .npy of '<f4' (what numpy.save writes for a float32 array).
Status WriteDescriptorNpy(const DescriptorMatrix& m, const std::string& path);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_DESCRIPTOR_FILE_H_
