#include "ratslam/records.h"

namespace ratslam {

std::string ToString(DecisionSource source) {
  switch (source) {
    case DecisionSource::kCamera:
      return "camera";
    case DecisionSource::kWifi:
      return "wifi";
    case DecisionSource::kNew:
      return "new";
  }
  return "unknown";
}

}  // namespace ratslam
