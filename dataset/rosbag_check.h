// A strict check of a ROS 1 bag's record structure (format 2.0), run before librosbag-storage
// sees the file: librosbag trusts the lengths and offsets it reads (a header field longer than its
// header overflows a heap buffer in ros::Header::parse), so a malformed bag must never reach it.
#ifndef RATSLAM_DATASET_ROSBAG_CHECK_H_
#define RATSLAM_DATASET_ROSBAG_CHECK_H_

#include <string>

#include "common/status.h"

namespace ratslam::dataset {

// Walks every record: the bag header first, chunks (decompressed: none, bz2, lz4) holding
// connection and message records, then at index_pos exactly conn_count connection records and
// chunk_count chunk-info records, with index records after each chunk. Every length fits what
// holds it; every header field is name=value; every fixed-size field has its size; every offset
// (index_pos, a chunk info's chunk_pos, an index entry's message offset) lands on a record of the
// right kind; every connection id used is defined. The error names the bag and the byte offset.
// A bag that passed is remembered by path, size and modification time.
Status CheckRosbagStructure(const std::string& path);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_ROSBAG_CHECK_H_
