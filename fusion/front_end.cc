#include "fusion/front_end.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fusion/front_end_internal.h"

namespace ratslam::fusion {

std::string ToString(FrontEndKind kind) {
  switch (kind) {
    case FrontEndKind::kClassicCamera:
      return "classic_camera";
    case FrontEndKind::kFused:
      return "fused";
    case FrontEndKind::kFabmap:
      return "fabmap";
    case FrontEndKind::kNone:
      return "none";
    case FrontEndKind::kDescriptors:
      return "descriptors";
    case FrontEndKind::kCustom:
      return "custom";
  }
  return "unknown";
}

namespace {

// A shipped config (configs/) for the streams a data set has.
std::string ConfigThatFits(const dataset::Dataset& d) {
  const bool images = !d.images.empty(), wifi = !d.wifi.empty(), compass = !d.compass.empty();
  if (images && wifi && compass) return "configs/sim-fused.toml (camera, Wi-Fi and compass)";
  if (images) return "configs/synthetic.toml (the classic camera front end)";
  if (wifi && compass) return "configs/ipin2023-wifi-compass.toml (Wi-Fi and compass)";
  if (wifi) return "configs/ipin2023-wifi.toml (Wi-Fi)";
  return "";
}

}  // namespace

Status CheckFrontEndInputs(const FrontEndSettings& settings, const dataset::Dataset& dataset) {
  const FrontEndKind kind = settings.front_end.kind;
  bool camera = kind == FrontEndKind::kClassicCamera || kind == FrontEndKind::kDescriptors,
       wifi = false, compass = false;
  if (kind == FrontEndKind::kFused) {
    camera = settings.fused.use_camera;
    wifi = settings.fused.use_wifi;
    compass = settings.fused.use_compass;
  } else if (kind == FrontEndKind::kNone) {
    wifi = true;
  } else if (kind == FrontEndKind::kFabmap) {
    const fabmap::FabmapMode mode = settings.fabmap.localiser.localiser.mode;
    camera = fabmap::UsesVision(mode);
    wifi = fabmap::UsesWifi(mode);
  }
  std::string missing;
  if (camera && dataset.images.empty()) missing = "camera images";
  if (wifi && dataset.wifi.empty())
    missing += (missing.empty() ? "" : " and ") + std::string("Wi-Fi scans");
  if (compass && dataset.compass.empty())
    missing += (missing.empty() ? "" : " and ") + std::string("a compass (heading) stream");
  if (missing.empty()) return Status::Ok();
  std::string message = "the " + ToString(kind) + " front end needs " + missing +
                        ", and data set '" + dataset.name + "' has none";
  const std::string fits = ConfigThatFits(dataset);
  if (!fits.empty()) message += "; a config that fits this data: " + fits;
  return Status::Error(message);
}

StatusOr<FrontEndKind> FrontEndKindFromString(const std::string& name) {
  if (name == "classic_camera") return FrontEndKind::kClassicCamera;
  if (name == "fused") return FrontEndKind::kFused;
  if (name == "fabmap") return FrontEndKind::kFabmap;
  if (name == "none") return FrontEndKind::kNone;
  if (name == "descriptors") return FrontEndKind::kDescriptors;
  if (name == "custom") return FrontEndKind::kCustom;
  return Status::Error("unknown front end '" + name +
                       "' (valid: classic_camera, fused, fabmap, none, descriptors, custom)");
}

bool FabmapSettings::IsValid(std::string* error) const {
  std::string inner;
  auto check = [&](bool ok, const char* section) {
    if (!ok && error) *error = std::string(section) + "." + inner;
    return ok;
  };
  return check(localiser.localiser.IsValid(&inner), "fabmap") &&
         check(localiser.fabmap.IsValid(&inner), "fabmap_model") &&
         check(localiser.visual_detector.IsValid(&inner), "visual_detector") &&
         check(localiser.wifi_detector.IsValid(&inner), "wifi_detector") &&
         check(features.IsValid(&inner), "visual_words") &&
         check(vocabulary.IsValid(&inner), "vocabulary") &&
         check(visual_model.IsValid(&inner), "visual_model") &&
         check(localiser.wifi_words.IsValid(&inner), "wifi_words") &&
         check(localiser.virtual_wifi.IsValid(&inner), "virtual_wifi") &&
         check(front_end.IsValid(&inner), "fabmap_front_end") && LearningFits(error);
}

// The earlier-session threshold is learnt from Wi-Fi scans' scores: a mode without Wi-Fi has
// none, and one with vision too decides on images, whose frames the learner does not record.
bool FabmapSettings::LearningFits(std::string* error) const {
  const fabmap::FabmapMode mode = localiser.localiser.mode;
  const bool wifi_only = fabmap::UsesWifi(mode) && !fabmap::UsesVision(mode);
  const char* key = front_end.learn_earlier_session_log_odds
                        ? "fabmap_front_end.learn_earlier_session_log_odds"
                    : front_end.calibrate_earlier_session_log_odds
                        ? "fabmap_front_end.calibrate_earlier_session_log_odds"
                        : nullptr;
  if (key == nullptr || wifi_only) return true;
  if (error) {
    *error = std::string(key) +
             ": needs a FABMAP mode of Wi-Fi alone (fabmap.mode = " + fabmap::ToString(mode) + ")";
  }
  return false;
}

bool FabmapFrontEndOptions::IsValid(std::string* error) const {
  if (!schema::CheckFields(*this, error)) return false;
  if (earlier_sessions_apart && !decide_by_log_odds) {
    if (error) *error = "earlier_sessions_apart: needs decide_by_log_odds = true";
    return false;
  }
  if (learn_earlier_session_log_odds && !earlier_sessions_apart) {
    if (error) *error = "learn_earlier_session_log_odds: needs earlier_sessions_apart = true";
    return false;
  }
  if (calibrate_earlier_session_log_odds && !earlier_sessions_apart) {
    if (error) *error = "calibrate_earlier_session_log_odds: needs earlier_sessions_apart = true";
    return false;
  }
  if (calibrate_earlier_session_log_odds && learn_earlier_session_log_odds) {
    if (error) {
      *error =
          "calibrate_earlier_session_log_odds: learns in its own first pass; set "
          "learn_earlier_session_log_odds = false";
    }
    return false;
  }
  return true;
}

std::string ToString(WifiLearning learning) {
  return learning == WifiLearning::kOnline ? "online" : "whole_data_set";
}

StatusOr<WifiLearning> WifiLearningFromString(const std::string& name) {
  if (name == "whole_data_set") return WifiLearning::kWholeDataSet;
  if (name == "online") return WifiLearning::kOnline;
  return Status::Error("unknown Wi-Fi learning '" + name + "' (whole_data_set or online)");
}

bool FloorOptions::IsValid(std::string* error) const {
  if (!schema::CheckFields(*this, error)) return false;
  return tracker.IsValid(error);
}

bool FusedOptions::IsValid(std::string* error) const {
  if (!schema::CheckFields(*this, error)) return false;
  if (!use_camera && !use_wifi) {
    if (error) *error = "use_wifi: at least one of camera and Wi-Fi must be on";
    return false;
  }
  return true;
}

namespace {

std::unique_ptr<FrontEnd> CreateDecidingFrontEnd(const FrontEndSettings& s,
                                                 const FrontEndResources& resources) {
  switch (s.front_end.kind) {
    case FrontEndKind::kClassicCamera:
      return front_end_internal::MakeClassicCameraFrontEnd(s.classic_camera);
    case FrontEndKind::kFused:
      return front_end_internal::MakeFusedFrontEnd(s.fused, s.camera_12x9, s.wifi, s.barometer);
    case FrontEndKind::kFabmap:
      return front_end_internal::MakeFabmapFrontEnd(s.fabmap, s.barometer, resources.fabmap);
    case FrontEndKind::kNone:
      return front_end_internal::MakeNoViewFrontEnd();
    case FrontEndKind::kDescriptors:
      return front_end_internal::MakeDescriptorFrontEnd(s.descriptors, resources.descriptors);
    case FrontEndKind::kCustom: {
      if (!resources.custom) {
        throw std::invalid_argument("front end kind 'custom' needs a front-end factory");
      }
      std::unique_ptr<FrontEnd> front_end = resources.custom();
      if (!front_end) throw std::invalid_argument("the custom front-end factory made nothing");
      return front_end;
    }
  }
  return nullptr;
}

}  // namespace

std::unique_ptr<FrontEnd> CreateFrontEnd(const FrontEndSettings& s,
                                         const FrontEndResources& resources) {
  std::unique_ptr<FrontEnd> front_end = CreateDecidingFrontEnd(s, resources);
  if (front_end && s.sequence.recognise_views) {
    return front_end_internal::MakeSequenceRecognition(std::move(front_end), s.sequence);
  }
  return front_end;
}

}  // namespace ratslam::fusion
