// The `ratslam` Python module: configurations, replays, evaluations, Wi-Fi maps, phone location
// and robot calls on data sets, and
// sessions stepped frame by frame with the caller's own inputs, over the same library sessions
// and pipeline the command line uses. Results come back as a dict (the summary) and columns of
// NumPy arrays (experiences, links, trajectory, frames, localisation). Errors raise
// ratslam.Error with the library's message (file, line and key where it has them).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/geometry.h"
#include "common/output_folder.h"
#include "common/output_guard.h"
#include "common/provenance.h"
#include "common/version.h"
#include "dataset/csv.h"
#include "fusion/replay_pipeline.h"
#include "io/config.h"
#include "io/map_file.h"
#include "io/run_outputs.h"
#include "session/call_session.h"
#include "session/evaluation_session.h"
#include "session/locate_session.h"
#include "session/replay_session.h"
#include "session/wifi_map_session.h"

namespace py = pybind11;

namespace ratslam::python {
namespace {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Messages written for the command line name its flags; Python users pass keyword arguments.
std::string InPythonTerms(std::string message) {
  for (const auto& [flag, keyword] :
       {std::pair<std::string, std::string>{"--overwrite", "overwrite=True"},
        {"--save-map", "save_map"},
        {"--at", "at"}}) {
    for (size_t at = message.find(flag); at != std::string::npos;
         at = message.find(flag, at + keyword.size())) {
      message.replace(at, flag.size(), keyword);
    }
  }
  return message;
}

void Check(const Status& status) {
  if (!status.ok()) throw Error(InPythonTerms(status.message()));
}

// The outcome of a run for its OutputGuard: see OutputGuard::Outcome.
OutputGuard::Outcome OutcomeOf(bool ok, bool stopped_with_outputs) {
  if (ok) return OutputGuard::Outcome::kSucceeded;
  return stopped_with_outputs ? OutputGuard::Outcome::kInterrupted : OutputGuard::Outcome::kFailed;
}
template <typename T>
T Take(StatusOr<T> value) {
  Check(value.status());
  return std::move(value).value();
}

// A value written as TOML, for Config.set.
std::string TomlValue(const py::handle& value) {
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(value)) return py::str(value).cast<std::string>();
  if (py::isinstance<py::float_>(value)) {
    const double v = value.cast<double>();
    if (!std::isfinite(v)) throw Error("Config.set: a value must be finite");
    return py::repr(value).cast<std::string>();
  }
  if (py::isinstance<py::str>(value)) return nlohmann::json(value.cast<std::string>()).dump();
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    std::string text = "[";
    for (const py::handle item : value) text += (text.size() > 1 ? ", " : "") + TomlValue(item);
    return text + "]";
  }
  throw Error("Config.set: values are bool, int, float, str or lists of them, not " +
              py::str(value.get_type()).cast<std::string>());
}

class Config {
 public:
  Config() = default;
  explicit Config(fusion::PipelineOptions options) : options_(std::move(options)) {}
  static Config Load(const std::string& path) { return Config(Take(io::LoadConfigFile(path))); }
  static Config FromToml(const std::string& text) {
    return Config(Take(io::ParseConfig(text, "<Config.from_toml>")));
  }
  std::string Toml() const { return io::PrintConfig(options_); }
  // `key` is "section.name" as in the TOML file; the value is checked as a file's would be.
  void Set(const std::string& key, const py::handle& value) {
    const size_t dot = key.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == key.size()) {
      throw Error("Config.set: key '" + key + "' must be section.name");
    }
    const std::string text =
        "[" + key.substr(0, dot) + "]\n" + key.substr(dot + 1) + " = " + TomlValue(value) + "\n";
    fusion::PipelineOptions changed = Take(io::ParseConfigOnto(text, "Config.set", options_));
    std::string error;
    if (!changed.IsValid(&error)) throw Error("Config.set: " + error);
    options_ = std::move(changed);
  }
  py::object ToDict() const {
    return py::module_::import("tomllib").attr("loads")(io::PrintConfig(options_, false));
  }
  const fusion::PipelineOptions& options() const { return options_; }

 private:
  fusion::PipelineOptions options_;
};

// One NumPy column from a field of each record.
template <typename T, typename Record, typename Get>
void Column(py::dict* columns, const char* name, const std::vector<Record>& rows, Get get) {
  py::array_t<T> a(static_cast<py::ssize_t>(rows.size()));
  T* out = a.mutable_data();
  for (size_t i = 0; i < rows.size(); ++i) out[i] = static_cast<T>(get(rows[i]));
  (*columns)[name] = std::move(a);
}

py::dict ExperienceColumns(const ExperienceMap& map) {
  using E = Experience;
  const std::vector<E>& rows = map.experiences();
  py::dict c;
  Column<int64_t>(&c, "id", rows, [](const E& e) { return e.id; });
  Column<double>(&c, "x_m", rows, [](const E& e) { return e.x_m; });
  Column<double>(&c, "y_m", rows, [](const E& e) { return e.y_m; });
  Column<double>(&c, "theta_rad", rows, [](const E& e) { return e.theta_rad; });
  Column<int64_t>(&c, "template_id", rows, [](const E& e) { return e.template_id; });
  Column<double>(&c, "time_s", rows, [](const E& e) { return e.time_s; });
  return c;
}

py::dict LinkColumns(const ExperienceMap& map) {
  const std::vector<Link>& rows = map.links();
  py::dict c;
  Column<int64_t>(&c, "id", rows, [](const Link& l) { return l.id; });
  Column<int64_t>(&c, "from_id", rows, [](const Link& l) { return l.from; });
  Column<int64_t>(&c, "to_id", rows, [](const Link& l) { return l.to; });
  Column<double>(&c, "distance_m", rows, [](const Link& l) { return l.distance_m; });
  Column<double>(&c, "heading_rad", rows, [](const Link& l) { return l.heading_rad; });
  Column<double>(&c, "facing_rad", rows, [](const Link& l) { return l.facing_rad; });
  Column<double>(&c, "duration_s", rows, [](const Link& l) { return l.duration_s; });
  Column<int64_t>(&c, "loop_closure", rows, [](const Link& l) { return l.loop_closure ? 1 : 0; });
  return c;
}

// Each odometry step's pose on the final map, and raw dead reckoning.
py::dict TrajectoryColumns(const fusion::ReplayPipeline& pipeline) {
  using T = TrajectoryRecord;
  const ExperienceMap& map = pipeline.slam().experience_map();
  const std::vector<T>& rows = pipeline.state().trajectory;
  std::vector<Pose2> poses;
  for (const T& r : rows) {
    Pose2 p;
    io::RecordPose(map, r, &p.x_m, &p.y_m, &p.theta_rad);
    poses.push_back(p);
  }
  py::dict c;
  Column<double>(&c, "time_s", rows, [](const T& r) { return r.time_s; });
  Column<int64_t>(&c, "experience_id", rows, [](const T& r) { return r.experience_id; });
  Column<double>(&c, "x_m", poses, [](const Pose2& p) { return p.x_m; });
  Column<double>(&c, "y_m", poses, [](const Pose2& p) { return p.y_m; });
  Column<double>(&c, "theta_rad", poses, [](const Pose2& p) { return p.theta_rad; });
  Column<double>(&c, "odometry_x_m", rows, [](const T& r) { return r.odometry_x_m; });
  Column<double>(&c, "odometry_y_m", rows, [](const T& r) { return r.odometry_y_m; });
  Column<double>(&c, "odometry_theta_rad", rows, [](const T& r) { return r.odometry_theta_rad; });
  return c;
}

py::dict FrameColumns(const fusion::ReplayPipeline& pipeline) {
  using F = FrameRecord;
  const std::vector<F>& rows = pipeline.state().frames;
  py::dict c;
  Column<double>(&c, "time_s", rows, [](const F& f) { return f.time_s; });
  Column<int64_t>(&c, "template_id", rows, [](const F& f) { return f.template_id; });
  Column<int64_t>(&c, "new_template", rows, [](const F& f) { return f.is_new ? 1 : 0; });
  Column<int64_t>(&c, "experience_id", rows, [](const F& f) { return f.experience_id; });
  Column<int64_t>(&c, "recent", rows, [](const F& f) { return f.recent ? 1 : 0; });
  return c;
}

py::dict LocalisationColumns(const fusion::ReplayPipeline& pipeline) {
  using L = LocalisationRecord;
  const std::vector<L>& rows = pipeline.localisation();
  py::dict c;
  Column<double>(&c, "time_s", rows, [](const L& r) { return r.time_s; });
  Column<int64_t>(&c, "experience_id", rows, [](const L& r) { return r.experience_id; });
  Column<int64_t>(&c, "lost", rows, [](const L& r) { return r.lost ? 1 : 0; });
  Column<double>(&c, "x_m", rows, [](const L& r) { return r.x_m; });
  Column<double>(&c, "y_m", rows, [](const L& r) { return r.y_m; });
  Column<double>(&c, "theta_rad", rows, [](const L& r) { return r.theta_rad; });
  return c;
}

// Everything a finished pipeline holds, as columns.
py::dict RunColumns(const fusion::ReplayPipeline& pipeline) {
  py::dict run;
  run["experiences"] = ExperienceColumns(pipeline.slam().experience_map());
  run["links"] = LinkColumns(pipeline.slam().experience_map());
  run["trajectory"] = TrajectoryColumns(pipeline);
  run["frames"] = FrameColumns(pipeline);
  if (pipeline.localising()) run["localisation"] = LocalisationColumns(pipeline);
  return run;
}

// Polls Python's signal handlers from the replay's progress reports (every 500 events), taking
// the GIL only for that: Ctrl-C stops the replay between events, as on the command line.
class InterruptiblePython : public ProgressSink {
 public:
  void Update(const ProgressUpdate&) override {
    if (stop_.load()) return;
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) {
      PyErr_Clear();  // raised again as KeyboardInterrupt once the outputs are written
      stop_.store(true);
    }
  }
  const std::atomic<bool>* flag() const { return &stop_; }
  bool stopped() const { return stop_.load(); }

 private:
  std::atomic<bool> stop_{false};
};

// ratslam.replay: what `ratslam replay` does, into the folder `out`, returning the summary and
// the run as columns.
py::dict Replay(const std::vector<std::string>& data, std::string out,
                const std::optional<Config>& config, const std::string& load_map,
                const std::string& save_map, bool localise, double lost_after_m,
                std::optional<double> until_s, bool overwrite) {
  if (data.empty()) throw Error("replay: give at least one data set");
  session::ReplaySessionOptions options;
  options.pipeline = config ? config->options() : fusion::PipelineOptions();
  options.config_path = config ? "(from Python)" : "";
  options.data = data;
  options.load_map = load_map;
  options.localise = localise;
  options.lost_after_m = lost_after_m;
  if (until_s) {
    if (!std::isfinite(*until_s)) throw Error("replay: until_s must be a finite number of seconds");
    options.until_s = *until_s;
  }
  std::vector<std::string> inputs = data;
  if (!load_map.empty()) inputs.push_back(load_map);
  Check(CheckReplaceable(save_map, overwrite, "--save-map"));
  OutputGuard guard = Take(OutputGuard::Begin(out, overwrite, inputs, "python: ratslam.replay"));
  options.save_map = guard.Staged(save_map);
  options.provenance = {"python: ratslam.replay", UtcNowIso8601(), guard.staging(), out};
  std::unique_ptr<DiskFolder> folder = Take(DiskFolder::Open(guard.staging()));
  session::SessionEnvironment environment;
  environment.out = folder.get();
  InterruptiblePython interrupt;
  environment.progress = &interrupt;
  environment.stop_requested = interrupt.flag();
  session::ReplaySession session(std::move(options), environment);
  StatusOr<session::ReplayResult> result = [&] {
    py::gil_scoped_release release;
    return session.Run();
  }();
  const OutputGuard::Report report = Take(guard.Finish(
      OutcomeOf(result.ok() && result->ok(), result.ok() && result->summary.has_value())));
  Check(result.status());
  if (!report.incomplete.empty()) out = report.incomplete;
  if (interrupt.stopped()) {
    PyErr_SetString(PyExc_KeyboardInterrupt,
                    ("ratslam.replay stopped; the outputs so far are in " + out).c_str());
    throw py::error_already_set();
  }
  if (!result->replay.ok()) {
    throw Error(result->replay.message() + " (the outputs so far are in " + out + ")");
  }
  Check(result->outputs);
  Check(result->save);
  py::dict run = RunColumns(session.pipeline());
  run["summary"] = py::module_::import("json").attr("loads")(result->summary->json);
  return run;
}

// A session stepped with the caller's inputs: an empty data set whose pipeline is fed directly.
class Session {
 public:
  explicit Session(const Config& config) : options_(config.options()) {
    if (options_.sensors.front_end.kind == fusion::FrontEndKind::kFabmap) {
      throw Error(
          "Session: the FABMAP front end learns its models from a whole data set; use "
          "ratslam.replay");
    }
    if (options_.sensors.front_end.kind == fusion::FrontEndKind::kCustom) {
      throw Error("Session: a custom front end is a C++ factory; use ratslam.replay from C++");
    }
    if (options_.visual_odometry.enabled) {
      throw Error("Session: feed odometry yourself ([visual_odometry] enabled must be false)");
    }
    dataset_.name = "python-session";
    pipeline_ = std::make_unique<fusion::ReplayPipeline>(options_, dataset_, &images_);
  }

  static std::unique_ptr<Session> Load(const std::string& path, const Config& config, bool localise,
                                       double lost_after_m) {
    auto session = std::make_unique<Session>(config);
    io::MapFile map = Take(io::LoadMapFile(path));
    Check(session::CheckSameConfiguration(map, session->options_).WithContext(path));
    if (localise) {
      Check(session->pipeline_->AdoptMap(map.state, lost_after_m).WithContext(path));
    } else {
      // Mapping goes on from the map, whatever data set made it.
      fusion::ReplayPipeline::State state = map.state;
      state.events_total = 0;
      state.next_event = 0;
      Check(session->pipeline_->Restore(state).WithContext(path));
      if (!state.trajectory.empty()) session->last_time_s_ = state.trajectory.back().time_s;
    }
    return session;
  }

  void Odometry(double time_s, double forward_speed, double turn_rate) {
    Advance(time_s);
    Within(forward_speed, "odometry: forward_speed");
    Within(turn_rate, "odometry: turn_rate");
    Check(pipeline_->FeedOdometry({time_s, forward_speed, turn_rate}));
  }
  void Image(double time_s, const py::array_t<uint8_t, py::array::c_style>& pixels) {
    if (pixels.ndim() != 2 || pixels.shape(0) < 1 || pixels.shape(1) < 1) {
      throw Error("image: expected a 2-D uint8 array (height, width) of grey levels");
    }
    Advance(time_s);
    GrayImage image;
    image.height = static_cast<int>(pixels.shape(0));
    image.width = static_cast<int>(pixels.shape(1));
    image.pixels.assign(pixels.data(), pixels.data() + pixels.size());
    Check(pipeline_->FeedImage(time_s, image).WithContext("image at t=" + std::to_string(time_s)));
  }
  void Descriptor(double time_s, const py::array& given) {
    // Real numbers only: a complex array cast to float would silently lose its imaginary part.
    const char kind = given.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u') {
      throw Error("descriptor: expected real numbers, got an array of dtype " +
                  std::string(py::str(given.dtype())));
    }
    const auto values =
        py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(given);
    if (!values || values.ndim() != 1 || values.shape(0) < 1) {
      throw Error("descriptor: expected a 1-D array of floats");
    }
    Advance(time_s);
    const std::vector<float> v(values.data(), values.data() + values.size());
    for (float x : v) {
      if (!std::isfinite(x)) throw Error("descriptor: values must be finite");
    }
    Check(pipeline_->FeedDescriptor(time_s, v).WithContext("descriptor at t=" +
                                                           std::to_string(time_s)));
  }
  void Wifi(double time_s, const std::map<std::string, double>& readings) {
    Advance(time_s);
    WifiScan scan;
    scan.time_s = time_s;
    for (const auto& [bssid, rssi] : readings) {
      if (bssid.empty()) throw Error("wifi at t=" + std::to_string(time_s) + ": empty BSSID");
      Within(rssi, "wifi: RSSI of " + bssid);
      scan.readings.push_back({bssid, rssi});
    }
    Check(pipeline_->FeedWifi(scan).WithContext("wifi at t=" + std::to_string(time_s)));
  }
  void Compass(double time_s, double heading_rad) {
    Advance(time_s);
    Within(heading_rad, "compass: heading_rad");
    pipeline_->FeedCompass({time_s, heading_rad});
  }
  void Pressure(double time_s, double pressure_hpa) {
    Advance(time_s);
    Within(pressure_hpa, "pressure: pressure_hpa");
    Check(pipeline_->FeedPressure({time_s, pressure_hpa})
              .WithContext("pressure at t=" + std::to_string(time_s)));
  }

  void SaveMap(const std::string& path) const {
    io::MapFile map;
    map.config_fingerprint = io::ConfigFingerprint(options_);
    map.dataset_name = dataset_.name;
    map.config = io::PrintConfig(options_, false);
    map.state = pipeline_->Snapshot();
    Check(io::SaveMapFile(map, path));
  }

  py::dict Summary() const {
    const Ratslam& slam = pipeline_->slam();
    py::dict d;
    d["frames"] = pipeline_->state().frames.size();
    d["templates"] = slam.local_view().size();
    d["experiences"] = slam.experience_map().num_experiences();
    d["links"] = slam.experience_map().num_links();
    d["loop_closures"] = slam.counters().loop_closures;
    d["view_injections"] = slam.counters().injections;
    d["odometry_steps"] = pipeline_->state().trajectory.size();
    const auto current = slam.experience_map().current();
    d["current_experience"] = current ? py::object(py::int_(*current)) : py::object(py::none());
    if (pipeline_->localising()) {
      d["recognitions"] = slam.localisation_counters().recognitions;
      d["unmapped_views"] = slam.localisation_counters().unmapped_views;
      d["relocalisations"] = slam.localisation_counters().relocalisations;
    }
    return d;
  }
  py::object CurrentExperience() const {
    const auto current = pipeline_->slam().experience_map().current();
    return current ? py::object(py::int_(*current)) : py::object(py::none());
  }
  py::tuple Pose() const {
    double x, y, theta;
    pipeline_->slam().experience_map().CurrentPose(&x, &y, &theta);
    return py::make_tuple(x, y, theta);
  }
  const fusion::ReplayPipeline& pipeline() const { return *pipeline_; }

 private:
  // The bound every number of a data-set file meets (kMaxCsvMagnitude): what a file could not
  // hold, a caller cannot feed either.
  static void Within(double value, const std::string& what) {
    if (!std::isfinite(value) || std::abs(value) > dataset::kMaxCsvMagnitude) {
      throw Error(what + " must be a finite number of magnitude at most 1e12, got " +
                  std::to_string(value));
    }
  }
  void Advance(double time_s) {
    Within(time_s, "time_s");
    if (last_time_s_ && time_s < *last_time_s_) {
      throw Error("time goes backwards: " + std::to_string(time_s) + " s after " +
                  std::to_string(*last_time_s_) + " s");
    }
    last_time_s_ = time_s;
  }

  fusion::PipelineOptions options_;
  dataset::Dataset dataset_;
  dataset::FileImageLoader images_;
  std::unique_ptr<fusion::ReplayPipeline> pipeline_;
  std::optional<double> last_time_s_;
};

py::dict NodeColumns(const std::vector<fabmap::EvaluationNode>& nodes) {
  py::dict c;
  using Node = fabmap::EvaluationNode;
  Column<double>(&c, "time_s", nodes, [](const Node& n) { return n.time_s; });
  Column<double>(&c, "x_m", nodes, [](const Node& n) { return n.x_m; });
  Column<double>(&c, "y_m", nodes, [](const Node& n) { return n.y_m; });
  Column<int32_t>(&c, "floor", nodes, [](const Node& n) { return n.floor; });
  Column<int32_t>(&c, "session", nodes, [](const Node& n) { return n.session; });
  return c;
}

// ratslam.evaluate: what `ratslam evaluate` does (the FABMAP localisation benchmark), into the
// folder `out`, returning evaluation.json and the map and queries as columns.
py::dict Evaluate(const std::string& map, const std::string& query, const std::string& out,
                  const std::optional<Config>& config, bool lenient, bool overwrite) {
  session::EvaluationSessionOptions options;
  options.pipeline = config ? config->options() : fusion::PipelineOptions();
  options.config_path = config ? "(from Python)" : "";
  options.map_path = map;
  options.query_path = query;
  options.lenient = lenient;
  OutputGuard guard =
      Take(OutputGuard::Begin(out, overwrite, {map, query}, "python: ratslam.evaluate"));
  options.provenance = {"python: ratslam.evaluate", UtcNowIso8601(), guard.staging(), out};
  std::unique_ptr<DiskFolder> folder = Take(DiskFolder::Open(guard.staging()));
  InterruptiblePython interrupt;
  session::EvaluationSession session(std::move(options), folder.get(), nullptr, &interrupt);
  session.set_stop_flag(interrupt.flag());
  StatusOr<session::EvaluationResult> result = [&] {
    py::gil_scoped_release release;
    return session.Run();
  }();
  (void)Take(guard.Finish(OutcomeOf(result.ok(), false)));
  if (interrupt.stopped()) {
    PyErr_SetString(PyExc_KeyboardInterrupt, "ratslam.evaluate stopped before writing its outputs");
    throw py::error_already_set();
  }
  Check(result.status());
  const session::EvaluationResult& r = *result;
  py::dict run;
  run["evaluation"] = py::module_::import("json").attr("loads")(r.json);
  run["map"] = NodeColumns(r.map);
  py::dict queries = NodeColumns(r.queries);
  const auto same = [](auto v) { return v; };
  Column<int64_t>(&queries, "match", r.matches, same);
  Column<double>(&queries, "match_probability", r.match_probability, same);
  Column<double>(&queries, "new_place_probability", r.new_place_probability, same);
  Column<int64_t>(&queries, "best_mapped_place", r.best_mapped_place, same);
  Column<double>(&queries, "best_mapped_probability", r.best_mapped_probability, same);
  Column<double>(&queries, "best_mapped_log_odds", r.best_mapped_log_odds, same);
  run["queries"] = std::move(queries);
  return run;
}

// ratslam.locate: what `ratslam locate` does (the particle filter on a phone log in a Wi-Fi map,
// scored beside weighted 3-NN), without writing files: the summary and a row per scan.
py::dict LocatePhone(const std::string& wifi_map, const std::string& data,
                     const std::optional<std::string>& config, bool lenient) {
  const phone::LocateOptions options =
      config ? Take(io::LoadLocateConfigFile(*config)) : phone::LocateOptions();
  const session::PhoneSetup setup = Take(session::SetUpPhone(options, wifi_map, data, lenient));
  StatusOr<session::LocateResult> result = [&] {
    py::gil_scoped_release release;
    return session::Locate(setup, data, wifi_map);
  }();
  Check(result.status());
  const std::vector<session::LocatedScan>& scans = result->scans;
  py::dict c;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Column<double>(&c, "time_s", scans, [](const session::LocatedScan& s) { return s.time_s; });
  Column<double>(&c, "x_m", scans, [](const session::LocatedScan& s) { return s.estimate.x_m; });
  Column<double>(&c, "y_m", scans, [](const session::LocatedScan& s) { return s.estimate.y_m; });
  Column<int32_t>(&c, "floor", scans,
                  [](const session::LocatedScan& s) { return s.estimate.floor; });
  Column<int64_t>(&c, "known_aps", scans,
                  [](const session::LocatedScan& s) { return static_cast<int64_t>(s.known_aps); });
  Column<double>(&c, "true_x_m", scans,
                 [&](const session::LocatedScan& s) { return s.truth ? s.truth->x_m : nan; });
  Column<double>(&c, "true_y_m", scans,
                 [&](const session::LocatedScan& s) { return s.truth ? s.truth->y_m : nan; });
  Column<double>(&c, "error_m", scans,
                 [&](const session::LocatedScan& s) { return s.truth ? s.error_m : nan; });
  Column<double>(&c, "knn_error_m", scans,
                 [&](const session::LocatedScan& s) { return s.truth ? s.knn_error_m : nan; });
  py::dict run;
  run["summary"] = py::module_::import("json").attr("loads")(result->summary.dump());
  run["scans"] = std::move(c);
  return run;
}

// ratslam.wifi_map: what `ratslam wifi-map` does (the Gaussian-process Wi-Fi map of data sets
// with ground truth, or of a replay's run), written to the file `out`; returns the summary.
py::dict WifiMap(const std::vector<std::string>& data, const std::string& out,
                 const std::optional<std::string>& run, const std::optional<std::string>& config,
                 bool lenient, bool overwrite) {
  const phone::LocateOptions options =
      config ? Take(io::LoadLocateConfigFile(*config)) : phone::LocateOptions();
  Check(CheckReplaceable(out, overwrite, "out"));
  const session::WifiMapInput input{data, run, lenient};
  StatusOr<session::BuiltWifiMap> built = [&] {
    py::gil_scoped_release release;
    return session::BuildWifiMap(options, input, out);
  }();
  Check(built.status());
  const std::filesystem::path path = out;
  std::unique_ptr<DiskFolder> folder =
      Take(DiskFolder::Open(path.has_parent_path() ? path.parent_path().string() : "."));
  Check(folder->Write(path.filename().string(), built->map.Encode()));
  return py::module_::import("json").attr("loads")(built->summary.dump());
}

// ratslam.call: what `ratslam call` does (the phone located up to `at`, the robot's tour to its
// candidates over the experience graph), without writing files: call.json and the route.
py::dict Call(const std::string& map, const std::string& wifi_map, const std::string& data,
              double at, const std::optional<std::string>& config, bool lenient) {
  const phone::LocateOptions options =
      config ? Take(io::LoadLocateConfigFile(*config)) : phone::LocateOptions();
  const session::RobotMap robot = Take(session::LoadRobotMap(map));
  const session::PhoneSetup setup = Take(session::SetUpPhone(options, wifi_map, data, lenient));
  StatusOr<session::CallResult> result = [&] {
    py::gil_scoped_release release;
    return session::CallRobot(setup, robot, at, {data, map, wifi_map});
  }();
  Check(result.status());
  const std::vector<uint32_t>& route = result->plan.route;
  const std::vector<Point2>& nodes = result->graph.nodes;
  std::vector<size_t> steps(route.size());
  for (size_t k = 0; k < steps.size(); ++k) steps[k] = k;
  py::dict r;
  Column<int64_t>(&r, "experience_id", steps,
                  [&](size_t k) { return static_cast<int64_t>(route[k]); });
  Column<double>(&r, "x_m", steps, [&](size_t k) { return nodes[route[k]].x; });
  Column<double>(&r, "y_m", steps, [&](size_t k) { return nodes[route[k]].y; });
  py::dict out;
  out["call"] = py::module_::import("json").attr("loads")(result->summary.dump());
  out["route"] = std::move(r);
  return out;
}

}  // namespace
}  // namespace ratslam::python

PYBIND11_MODULE(ratslam, m) {
  using namespace ratslam::python;
  m.doc() =
      "RatSLAM: replays, localisation on saved maps and frame-by-frame sessions (see "
      "docs/python.md).";
  py::register_exception<Error>(m, "Error", PyExc_RuntimeError);
  m.attr("__version__") = ratslam::RatslamVersion();

  py::class_<Config>(m, "Config", "A pipeline configuration (the TOML of `ratslam print-config`).")
      .def(py::init<>(), "The built-in defaults.")
      .def_static("load", &Config::Load, py::arg("path"), "Reads a TOML configuration file.")
      .def_static("from_toml", &Config::FromToml, py::arg("text"))
      .def("toml", &Config::Toml, "The resolved configuration as TOML, with comments.")
      .def("set", &Config::Set, py::arg("key"), py::arg("value"),
           "Sets 'section.name' to a value, checked as a configuration file's would be.")
      .def("to_dict", &Config::ToDict, "The configuration as nested dicts.");

  m.def("replay", &Replay, py::arg("data"), py::arg("out"), py::arg("config") = std::nullopt,
        py::arg("load_map") = "", py::arg("save_map") = "", py::arg("localise") = false,
        py::arg("lost_after_m") = 5.0, py::arg("until_s") = std::nullopt,
        py::arg("overwrite") = false,
        "Replays data sets (a list of paths: one multi-session run) into folder `out`, as "
        "`ratslam replay` does. Returns {'summary': dict (summary.json), 'experiences', 'links', "
        "'trajectory', 'frames' and, when localising, 'localisation': dicts of NumPy arrays}.");

  m.def("evaluate", &Evaluate, py::arg("map"), py::arg("query"), py::arg("out"),
        py::arg("config") = std::nullopt, py::arg("lenient") = false, py::arg("overwrite") = false,
        "The FABMAP localisation benchmark on data sets `map` and `query` (the same path: one "
        "data set split by [evaluation]) into folder `out`, as `ratslam evaluate` does (without "
        "its figures). Returns {'evaluation': dict (evaluation.json), 'map': columns of the "
        "mapped places, 'queries': columns with 'match' (map index, -1: rejected as a new "
        "place), the posteriors and the best mapped place}.");

  m.def("locate", &LocatePhone, py::arg("wifi_map"), py::arg("data"),
        py::arg("config") = std::nullopt, py::arg("lenient") = false,
        "Locates a phone log (`data`) in a Wi-Fi map (`ratslam wifi-map`) with the particle "
        "filter, as `ratslam locate` does, without writing files. `config`: a locate TOML file. "
        "Returns {'summary': dict (summary.json without 'run'), 'scans': columns per Wi-Fi scan "
        "(estimate, known_aps, truth and errors: NaN without ground truth, inf on the wrong "
        "floor)}.");

  m.def("wifi_map", &WifiMap, py::arg("data"), py::arg("out"), py::arg("run") = std::nullopt,
        py::arg("config") = std::nullopt, py::arg("lenient") = false, py::arg("overwrite") = false,
        "Builds a Gaussian-process Wi-Fi map from data sets (a list of paths) with ground truth, "
        "or from a replay's run folder `run` of them (positions from the run's map), and writes "
        "it to the file `out`, as `ratslam wifi-map` does. `config`: a locate TOML file. Returns "
        "the summary (`--json`'s, without 'seconds' and 'run').");

  m.def("call", &Call, py::arg("map"), py::arg("wifi_map"), py::arg("data"), py::arg("at"),
        py::arg("config") = std::nullopt, py::arg("lenient") = false,
        "Calls the robot of `map` (a run folder or a saved map) to the phone of `data` as located "
        "in `wifi_map` by time `at` (s), as `ratslam call` does, without writing files. Returns "
        "{'call': dict (call.json without 'run'), 'route': columns per step of the robot's route "
        "(experience_id, x_m, y_m)}.");

  py::class_<Session>(m, "Session",
                      "A RatSLAM session fed frame by frame: odometry, grey images, Wi-Fi scans "
                      "and compass headings, in time order.")
      .def(py::init<const Config&>(), py::arg("config") = Config())
      .def_static("load", &Session::Load, py::arg("path"), py::arg("config") = Config(),
                  py::arg("localise") = false, py::arg("lost_after_m") = 5.0,
                  "Continues from a saved map (any run's, made under the same configuration); "
                  "with localise=True the map is frozen and only localised on.")
      .def("odometry", &Session::Odometry, py::arg("time_s"), py::arg("forward_speed_m_per_s"),
           py::arg("turn_rate_rad_per_s"),
           "Speeds held since the previous odometry input (as a data set's odometry.csv).")
      .def("image", &Session::Image, py::arg("time_s"), py::arg("pixels"),
           "A grey image, uint8 array (height, width).")
      .def("wifi", &Session::Wifi, py::arg("time_s"), py::arg("readings"),
           "A Wi-Fi scan: {bssid: rssi_dbm}.")
      .def("compass", &Session::Compass, py::arg("time_s"), py::arg("heading_rad"))
      .def("pressure", &Session::Pressure, py::arg("time_s"), py::arg("pressure_hpa"),
           "A barometer reading, hPa (floors: barometer.use_barometer).")
      .def("descriptor", &Session::Descriptor, py::arg("time_s"), py::arg("values"),
           "A place descriptor for the frame at time_s (front_end.kind = \"descriptors\"): a "
           "1-D float array, compared by cosine similarity.")
      .def("save_map", &Session::SaveMap, py::arg("path"))
      .def("summary", &Session::Summary)
      .def_property_readonly("current_experience", &Session::CurrentExperience)
      .def_property_readonly("pose", &Session::Pose,
                             "(x_m, y_m, theta_rad): the current experience plus dead reckoning.")
      .def("experiences",
           [](const Session& s) { return ExperienceColumns(s.pipeline().slam().experience_map()); })
      .def("links",
           [](const Session& s) { return LinkColumns(s.pipeline().slam().experience_map()); })
      .def("trajectory", [](const Session& s) { return TrajectoryColumns(s.pipeline()); })
      .def("frames", [](const Session& s) { return FrameColumns(s.pipeline()); })
      .def("localisation", [](const Session& s) { return LocalisationColumns(s.pipeline()); });
}
