// Internal to the bag readers (ROS 1 and ROS 2): choosing topics and turning the selected
// messages, in time order, into a data set.
#ifndef RATSLAM_DATASET_BAG_COMMON_H_
#define RATSLAM_DATASET_BAG_COMMON_H_

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/rosbag.h"

namespace ratslam::dataset {

// Picks the topic for one stream from `topic_types` (topic -> message type). `wanted` empty: the
// only topic of one of `types` (none: empty; several: an error naming them and `key`). Named: that
// topic (normalised; with "/compressed" appended when `try_compressed` and only that exists), an
// error when missing.
StatusOr<std::string> ResolveBagTopic(const std::string& bag, const std::string& what,
                                      const std::string& key, const std::string& wanted,
                                      const std::map<std::string, std::string>& topic_types,
                                      const std::set<std::string>& types, bool try_compressed);

// The message types each stream accepts, and the topics chosen for them (empty: none).
struct BagMessageTypes {
  std::set<std::string> image, odometry, ground_truth, imu;
};
struct SelectedBagTopics {
  std::string image, odometry, ground_truth, imu;
};

// ResolveBagTopic for each stream of `wanted` ([bag]); ground truth and IMU only when named.
StatusOr<SelectedBagTopics> SelectBagTopics(const std::string& bag, const BagTopics& wanted,
                                            const std::map<std::string, std::string>& topic_types,
                                            const BagMessageTypes& types);

// Yaw (counter-clockwise about z) of a unit quaternion.
double YawOfQuaternion(double x, double y, double z, double w);

// Collects messages as they come in time order. Times are nanoseconds since the epoch; the data
// set's times are seconds after the earliest collected message. Each Add checks that the time
// does not go backwards on its topic and that the values are finite; errors start with `where`.
class BagDatasetBuilder {
 public:
  Status AddImage(int64_t time_ns, const std::string& topic, const std::string& where,
                  std::string reference, uint64_t index);
  Status AddOdometry(int64_t time_ns, const std::string& topic, const std::string& where,
                     double forward_speed_m_per_s, double turn_rate_rad_per_s);
  Status AddGroundTruth(int64_t time_ns, const std::string& topic, const std::string& where,
                        double x_m, double y_m, double theta_rad);
  Status AddCompass(int64_t time_ns, const std::string& topic, const std::string& where,
                    double heading_rad);

  // `dataset` with the collected streams; an error naming `bag` when nothing was collected.
  StatusOr<Dataset> Finish(Dataset dataset, const std::string& bag) &&;

 private:
  Status CheckOrder(int64_t time_ns, const std::string& topic, const std::string& where);

  Dataset collected_;
  std::vector<int64_t> image_ns_, odometry_ns_, truth_ns_, compass_ns_;
  std::map<std::string, int64_t> last_time_ns_;
};

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_BAG_COMMON_H_
