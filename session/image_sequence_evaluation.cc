#include "session/image_sequence_evaluation.h"

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/file_util.h"
#include "common/number_text.h"
#include "dataset/csv.h"
#include "dataset/descriptor_file.h"
#include "fusion/descriptor_table.h"
#include "fusion/fabmap/localiser.h"
#include "fusion/fabmap/visual_model.h"
#include "io/provenance_json.h"
#include "io/visual_model_file.h"

namespace ratslam::session {
namespace {

namespace fs = std::filesystem;

bool IsImageName(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* e : {".png", ".jpg", ".jpeg", ".pgm", ".ppm", ".bmp", ".tif", ".tiff"}) {
    if (ext == e) return true;
  }
  return false;
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

bool Within(const QueryAnswer& a, int reference, int tolerance) {
  return a.truth >= 0 && reference >= 0 && std::abs(reference - a.truth) <= tolerance;
}

nlohmann::ordered_json MetricsJson(const PlaceRecognitionMetrics& m) {
  nlohmann::ordered_json j;
  j["queries"] = m.queries;
  j["declined"] = m.declined;
  j["recall_at_1"] = m.recall_at_1;
  j["recall_at_5"] = m.recall_at_5;
  j["pr_auc"] = m.pr_auc;
  j["recall_at_100_precision"] = m.recall_at_100_precision;
  return j;
}

// Places every query in turn (`add(q)` adds query q to the matcher and returns its result):
// sequence answers (centred when the options say so) and single-frame answers, and each
// query's raw differences when `differences` is not null.
Status MatchQueries(const sensors::SequenceMatcherOptions& o, size_t queries,
                    const std::function<StatusOr<sensors::SequenceMatcher::Result>(size_t)>& add,
                    const std::vector<int>& truth, std::vector<QueryAnswer>* sequence,
                    std::vector<QueryAnswer>* single, std::vector<std::vector<float>>* differences,
                    const std::function<void(size_t, size_t)>& progress,
                    const std::atomic<bool>* stop, sensors::SequenceMatcher* matcher) {
  // Centred: query q is placed once the (sequence_length - 1) / 2 frames after it are in, the
  // route's last ones by its last sequence.
  const size_t lag = o.centred ? static_cast<size_t>(o.sequence_length - 1) / 2 : 0;
  for (size_t q = 0; q < queries; ++q) {
    if (stop && stop->load()) return Status::Error("stopped");
    StatusOr<sensors::SequenceMatcher::Result> r = add(q);
    if (!r.ok()) return r.status();
    sequence->push_back({truth[q], std::move(r->sequence)});
    if (lag > 0 && q >= lag) (*sequence)[q - lag].match = matcher->MatchAt(static_cast<int>(lag));
    single->push_back({truth[q], std::move(r->single)});
    if (differences) differences->push_back(std::move(r->differences));
    if (progress) progress(q + 1, queries);
  }
  for (size_t q = queries - std::min(queries, lag); lag > 0 && q < queries; ++q) {
    (*sequence)[q].match = matcher->MatchAt(static_cast<int>(queries - 1 - q));
  }
  return Status::Ok();
}

struct DescriptorRows {
  size_t rows = 0, cols = 0;
  std::vector<float> unit;  // row-major, each row of unit length
};

// The descriptors of `path`, one row per image of `folder`, each scaled to unit length.
StatusOr<DescriptorRows> LoadDescriptorRows(const std::string& path, const std::string& folder,
                                            size_t images) {
  StatusOr<dataset::DescriptorMatrix> m = dataset::ReadDescriptorFile(path);
  if (!m.ok()) return m.status();
  if (m->rows != images) {
    return Status::Error(path + ": " + std::to_string(m->rows) + " rows for the " +
                         std::to_string(images) + " images of " + folder +
                         " (one row per image, in file-name order)");
  }
  DescriptorRows d;
  d.rows = m->rows;
  d.cols = m->cols;
  d.unit.reserve(m->values.size());
  std::vector<float> unit;
  for (size_t r = 0; r < m->rows; ++r) {
    if (!fusion::UnitDescriptor(m->values.data() + r * m->cols, m->cols, &unit)) {
      return Status::Error(path + ": row " + std::to_string(r + 1) +
                           " has no direction (all zeros), so no cosine similarity");
    }
    d.unit.insert(d.unit.end(), unit.begin(), unit.end());
  }
  return d;
}

struct DescriptorPair {
  DescriptorRows references, queries;
};

// The options' two descriptor files, when given, checked against the image counts and each
// other's length.
StatusOr<std::optional<DescriptorPair>> LoadDescriptorPair(
    const ImageSequenceEvaluationOptions& options, const ImageSequenceEvaluation& e) {
  if (options.reference_descriptors.empty() != options.query_descriptors.empty()) {
    return Status::Error("descriptors: give a file for the map and one for the queries, or none");
  }
  if (options.reference_descriptors.empty()) return std::optional<DescriptorPair>();
  StatusOr<DescriptorRows> r = LoadDescriptorRows(
      options.reference_descriptors, options.reference_folder, e.reference_files.size());
  if (!r.ok()) return r.status();
  StatusOr<DescriptorRows> q =
      LoadDescriptorRows(options.query_descriptors, options.query_folder, e.query_files.size());
  if (!q.ok()) return q.status();
  if (q->cols != r->cols) {
    return Status::Error(options.query_descriptors + ": " + std::to_string(q->cols) +
                         " values per row, " + options.reference_descriptors + " has " +
                         std::to_string(r->cols));
  }
  return std::optional<DescriptorPair>(DescriptorPair{std::move(*r), std::move(*q)});
}

// The descriptors matched as the images are, by sequences and single frames, over 1 - cosine
// similarity; the images' blank frames stay blank.
StatusOr<MatcherAnswers> MatchByDescriptors(const ImageSequenceEvaluationOptions& options,
                                            const DescriptorPair& d,
                                            const ImageSequenceEvaluation& e,
                                            const std::vector<sensors::PreparedFrame>& query_frames,
                                            const std::atomic<bool>* stop) {
  sensors::SequenceMatcher matcher(options.matcher);
  for (bool blank : e.reference_blank) {
    sensors::PreparedFrame place;
    place.blank = blank;
    RATSLAM_RETURN_IF_ERROR(matcher.AddReference(std::move(place)));
  }
  const Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
      reference_rows(d.references.unit.data(), static_cast<Eigen::Index>(d.references.rows),
                     static_cast<Eigen::Index>(d.references.cols));
  MatcherAnswers answers;
  RATSLAM_RETURN_IF_ERROR(MatchQueries(
      options.matcher, query_frames.size(),
      [&](size_t q) {
        const Eigen::Map<const Eigen::VectorXf> query(d.queries.unit.data() + q * d.queries.cols,
                                                      static_cast<Eigen::Index>(d.queries.cols));
        const Eigen::VectorXf cosine = reference_rows * query;
        std::vector<float> row(cosine.size());
        for (Eigen::Index r = 0; r < cosine.size(); ++r) {
          row[r] = std::clamp(1.0f - cosine[r], 0.0f, 2.0f);
        }
        return matcher.AddQueryDifferences(std::move(row), query_frames[q].blank);
      },
      e.truth, &answers.sequence, &answers.single, nullptr, {}, stop, &matcher));
  answers.sequence_metrics = MetricsOf(answers.sequence, options.frame_tolerance);
  answers.single_metrics = MetricsOf(answers.single, options.frame_tolerance);
  return answers;
}

// The visual words of every image of `folder` (`names` in it).
Status WordsOf(const fabmap::TrainedVisualModel& model, const std::string& folder,
               const std::vector<std::string>& names, ImageLoader* loader,
               std::vector<fabmap::Observation>* words, double* mean_words,
               const std::atomic<bool>* stop) {
  double total = 0.0;
  for (const std::string& name : names) {
    if (stop && stop->load()) return Status::Error("stopped");
    const std::string path = (fs::path(folder) / name).string();
    StatusOr<GrayImage> image = loader->Load(path);
    if (!image.ok()) return image.status();
    StatusOr<fabmap::Observation> w = fabmap::ImageWords(model, *image);
    if (!w.ok()) return w.status().WithContext(path);
    total += static_cast<double>(w->size());
    words->push_back(*std::move(w));
  }
  *mean_words = names.empty() ? 0.0 : total / static_cast<double>(names.size());
  return Status::Ok();
}

// FABMAP (vision alone) over the references as places: each non-blank query's answer is the
// most probable non-blank place, its confidence the log odds of that place against the new one;
// up to five candidates, best first, each outside the others' `exclusion` windows.
StatusOr<ImageSequenceEvaluation::Fabmap> MatchByFabmap(
    const ImageSequenceEvaluationOptions& options, const ImageSequenceEvaluation& e,
    const std::vector<sensors::PreparedFrame>& query_frames, ImageLoader* loader,
    const std::atomic<bool>* stop) {
  const auto start = std::chrono::steady_clock::now();
  ImageSequenceEvaluation::Fabmap f;
  const fusion::FabmapSettings& settings = options.fabmap_settings;
  fabmap::VisualModelOptions model_options = settings.visual_model;
  f.trained_here = model_options.file.empty();
  if (model_options.file.empty() && model_options.training_images.empty()) {
    model_options.training_images = options.reference_folder;
  }
  StatusOr<fabmap::TrainedVisualModel> model =
      io::LoadOrTrainVisualModel(model_options, settings.features, settings.vocabulary,
                                 settings.localiser.chow_liu, *loader, {});
  if (!model.ok()) return model.status();
  f.vocabulary = model->vocabulary.size();
  std::vector<fabmap::Observation> reference_words, query_words;
  RATSLAM_RETURN_IF_ERROR(WordsOf(*model, options.reference_folder, e.reference_files, loader,
                                  &reference_words, &f.words_per_reference, stop));
  RATSLAM_RETURN_IF_ERROR(WordsOf(*model, options.query_folder, e.query_files, loader, &query_words,
                                  &f.words_per_query, stop));
  std::vector<fabmap::MapNode> places(reference_words.size());
  for (size_t i = 0; i < places.size(); ++i) {
    places[i].visual = std::move(reference_words[i]);
    places[i].travelled_m = static_cast<double>(i);
    places[i].time_s = static_cast<double>(i);
  }
  fabmap::LocaliserSettings localiser = settings.localiser;
  localiser.localiser.mode = fabmap::FabmapMode::kVision;  // images have no Wi-Fi
  StatusOr<std::unique_ptr<fabmap::Localiser>> built =
      fabmap::Localiser::Build(localiser, &model->model, places);
  if (!built.ok()) return built.status();
  const int exclusion = options.matcher.exclusion_window;
  for (size_t q = 0; q < query_words.size(); ++q) {
    if (stop && stop->load()) return Status::Error("stopped");
    QueryAnswer a;
    a.truth = e.truth[q];
    if (!query_frames[q].blank) {
      const fabmap::LocalisationResult r = (*built)->Localise({query_words[q], std::nullopt});
      // Lower is better for PlaceCandidates: the negated posterior; blank references never.
      std::vector<double> score(r.place_probability.size());
      for (size_t i = 0; i < score.size(); ++i) {
        score[i] = e.reference_blank[i] ? std::numeric_limits<double>::infinity()
                                        : -r.place_probability[i];
      }
      a.match.candidates = sensors::PlaceCandidates(score, 5, exclusion);
      if (!a.match.candidates.empty()) {
        a.match.declined = false;
        a.match.reference = a.match.candidates.front().reference;
        // Log odds of the answer against the new place, from the two posteriors; a blank
        // reference that FABMAP preferred leaves the answer's own posterior in the numerator.
        const double p = r.place_probability[static_cast<size_t>(a.match.reference)];
        a.match.confidence = a.match.reference == r.best_mapped_place
                                 ? r.best_mapped_log_odds
                                 : std::log(std::max(p, 1e-300)) -
                                       std::log(std::max(r.new_place_probability, 1e-300));
      }
    }
    f.answers.push_back(std::move(a));
  }
  f.metrics = MetricsOf(f.answers, options.frame_tolerance);
  f.seconds = Seconds(start);
  return f;
}

}  // namespace

bool IsImageSequenceFolder(const std::string& path) {
  std::error_code ec;
  if (!fs::is_directory(path, ec) || fs::exists(fs::path(path) / "manifest.toml", ec)) {
    return false;
  }
  for (const fs::directory_entry& e : fs::directory_iterator(path, ec)) {
    if (e.is_regular_file(ec) && IsImageName(e.path())) return true;
  }
  return false;
}

StatusOr<std::vector<std::string>> ListImageSequence(const std::string& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return Status::Error(folder + ": not a folder");
  std::vector<std::string> names;
  for (const fs::directory_entry& e : fs::directory_iterator(folder, ec)) {
    if (e.is_regular_file(ec) && IsImageName(e.path())) {
      names.push_back(e.path().filename().string());
    }
  }
  if (ec) return Status::Error(folder + ": " + ec.message());
  if (names.empty()) return Status::Error(folder + ": no image files (png, jpg, pgm, ...)");
  std::sort(names.begin(), names.end());
  return names;
}

StatusOr<std::vector<int>> PairQueriesWithReferences(const std::vector<std::string>& references,
                                                     const std::vector<std::string>& queries,
                                                     const std::string& ground_truth_csv) {
  std::map<std::string, int> reference_index, query_index;
  for (size_t i = 0; i < references.size(); ++i) reference_index[references[i]] = int(i);
  for (size_t i = 0; i < queries.size(); ++i) query_index[queries[i]] = int(i);
  std::vector<int> truth(queries.size(), -1);
  if (!ground_truth_csv.empty()) {
    StatusOr<dataset::CsvTable> t =
        dataset::CsvTable::Read(ground_truth_csv, {"query", "reference"});
    if (!t.ok()) return t.status();
    for (size_t r = 0; r < t->rows(); ++r) {
      StatusOr<std::string> q = t->Text(r, "query"), ref = t->Text(r, "reference");
      if (!q.ok()) return q.status();
      if (!ref.ok()) return ref.status();
      const auto qi = query_index.find(*q);
      if (qi == query_index.end()) {
        return t->ErrorAt(r, "query", "'" + *q + "' is not an image of the query folder");
      }
      const auto ri = reference_index.find(*ref);
      if (ri == reference_index.end()) {
        return t->ErrorAt(r, "reference", "'" + *ref + "' is not an image of the reference folder");
      }
      if (truth[qi->second] >= 0) {
        return t->ErrorAt(r, "query", "'" + *q + "' is paired twice");
      }
      truth[qi->second] = ri->second;
    }
    return truth;
  }
  const bool by_name = std::all_of(queries.begin(), queries.end(), [&](const std::string& q) {
    return reference_index.count(q) > 0;
  });
  if (by_name) {
    for (size_t i = 0; i < queries.size(); ++i) truth[i] = reference_index[queries[i]];
    return truth;
  }
  if (queries.size() == references.size()) {
    for (size_t i = 0; i < queries.size(); ++i) truth[i] = static_cast<int>(i);
    return truth;
  }
  return Status::Error("cannot pair the " + std::to_string(queries.size()) + " queries with the " +
                       std::to_string(references.size()) +
                       " references: their file names differ and so do their numbers; give "
                       "--ground-truth (a CSV with columns query,reference)");
}

PlaceRecognitionMetrics MetricsOf(const std::vector<QueryAnswer>& answers, int frame_tolerance) {
  PlaceRecognitionMetrics m;
  std::vector<const QueryAnswer*> accepted;
  size_t right_at_1 = 0, right_at_5 = 0;
  for (const QueryAnswer& a : answers) {
    if (a.truth < 0) continue;
    ++m.queries;
    if (a.match.declined) {
      ++m.declined;
      continue;
    }
    right_at_1 += Within(a, a.match.reference, frame_tolerance);
    const size_t top = std::min<size_t>(5, a.match.candidates.size());
    right_at_5 += std::any_of(
        a.match.candidates.begin(), a.match.candidates.begin() + top,
        [&](const sensors::PlaceCandidate& c) { return Within(a, c.reference, frame_tolerance); });
    accepted.push_back(&a);
  }
  if (m.queries == 0) return m;
  const double n = static_cast<double>(m.queries);
  m.recall_at_1 = right_at_1 / n;
  m.recall_at_5 = right_at_5 / n;
  // Most confident first; ties are accepted together (one threshold cannot split them).
  std::stable_sort(accepted.begin(), accepted.end(),
                   [](const QueryAnswer* a, const QueryAnswer* b) {
                     return a->match.confidence > b->match.confidence;
                   });
  size_t right = 0;
  double last_recall = 0.0;
  bool perfect = true;
  for (size_t i = 0; i < accepted.size(); ++i) {
    right += Within(*accepted[i], accepted[i]->match.reference, frame_tolerance);
    if (i + 1 < accepted.size() &&
        accepted[i + 1]->match.confidence == accepted[i]->match.confidence) {
      continue;
    }
    PrecisionRecall p;
    p.recall = right / n;
    p.precision = static_cast<double>(right) / static_cast<double>(i + 1);
    p.threshold = accepted[i]->match.confidence;
    m.pr_auc += p.precision * (p.recall - last_recall);
    last_recall = p.recall;
    perfect = perfect && right == i + 1;
    if (perfect) m.recall_at_100_precision = p.recall;
    m.curve.push_back(p);
  }
  return m;
}

StatusOr<ImageSequenceEvaluation> EvaluateImageSequences(
    const ImageSequenceEvaluationOptions& options, ImageLoader* loader,
    const std::function<void(size_t, size_t)>& progress, const std::atomic<bool>* stop) {
  std::string error;
  if (!options.matcher.IsValid(&error)) return Status::Error("[sequence] " + error);
  if (options.frame_tolerance < 0) return Status::Error("frame tolerance must not be negative");
  const auto start = std::chrono::steady_clock::now();
  ImageSequenceEvaluation e;
  StatusOr<std::vector<std::string>> refs = ListImageSequence(options.reference_folder);
  if (!refs.ok()) return refs.status();
  StatusOr<std::vector<std::string>> queries = ListImageSequence(options.query_folder);
  if (!queries.ok()) return queries.status();
  e.reference_files = std::move(*refs);
  e.query_files = std::move(*queries);
  StatusOr<std::vector<int>> truth =
      PairQueriesWithReferences(e.reference_files, e.query_files, options.ground_truth_csv);
  if (!truth.ok()) return truth.status();
  e.truth = std::move(*truth);
  // Descriptor files are read first: a bad one fails before the images are matched.
  StatusOr<std::optional<DescriptorPair>> descriptors = LoadDescriptorPair(options, e);
  if (!descriptors.ok()) return descriptors.status();

  const sensors::SequenceMatcherOptions& o = options.matcher;
  auto prepare = [&](const std::string& folder,
                     const std::string& name) -> StatusOr<sensors::PreparedFrame> {
    const std::string path = (fs::path(folder) / name).string();
    StatusOr<GrayImage> image = loader->Load(path);
    if (!image.ok()) return image.status();
    return sensors::PrepareFrame(image->pixels.data(), image->width, image->height, o);
  };
  sensors::SequenceMatcher matcher(o);
  for (const std::string& name : e.reference_files) {
    if (stop && stop->load()) return Status::Error("stopped");
    StatusOr<sensors::PreparedFrame> f = prepare(options.reference_folder, name);
    if (!f.ok()) return f.status();
    e.blank_references += f->blank;
    e.reference_blank.push_back(f->blank);
    if (Status s = matcher.AddReference(std::move(*f)); !s.ok()) {
      return Status::Error((fs::path(options.reference_folder) / name).string() + ": " +
                           s.message());
    }
  }
  std::vector<sensors::PreparedFrame> query_frames;
  query_frames.reserve(e.query_files.size());
  for (const std::string& name : e.query_files) {
    if (stop && stop->load()) return Status::Error("stopped");
    StatusOr<sensors::PreparedFrame> f = prepare(options.query_folder, name);
    if (!f.ok()) return f.status();
    e.blank_queries += f->blank;
    query_frames.push_back(std::move(*f));
  }
  e.load_seconds = Seconds(start);

  const auto matching = std::chrono::steady_clock::now();
  RATSLAM_RETURN_IF_ERROR(MatchQueries(
      o, query_frames.size(),
      [&](size_t q) -> StatusOr<sensors::SequenceMatcher::Result> {
        StatusOr<sensors::SequenceMatcher::Result> r = matcher.AddQuery(query_frames[q]);
        if (!r.ok()) {
          return Status::Error((fs::path(options.query_folder) / e.query_files[q]).string() + ": " +
                               r.status().message());
        }
        return r;
      },
      e.truth, &e.sequence, &e.single, &e.differences, progress, stop, &matcher));
  e.match_seconds = Seconds(matching);
  e.sequence_metrics = MetricsOf(e.sequence, options.frame_tolerance);
  e.single_metrics = MetricsOf(e.single, options.frame_tolerance);
  if (*descriptors) {
    const auto start_descriptors = std::chrono::steady_clock::now();
    StatusOr<MatcherAnswers> d = MatchByDescriptors(options, **descriptors, e, query_frames, stop);
    if (!d.ok()) return d.status();
    e.descriptor_dimensions = (*descriptors)->references.cols;
    e.descriptors = std::move(*d);
    e.descriptor_match_seconds = Seconds(start_descriptors);
  }
  if (options.fabmap) {
    StatusOr<ImageSequenceEvaluation::Fabmap> f =
        MatchByFabmap(options, e, query_frames, loader, stop);
    if (!f.ok()) return f.status();
    e.fabmap = std::move(*f);
  }
  return e;
}

Status WriteImageSequenceOutputs(const ImageSequenceEvaluationOptions& options,
                                 const ImageSequenceEvaluation& e, const std::string& config_toml,
                                 uint64_t config_fingerprint, const RunProvenance& provenance,
                                 OutputFolder* out) {
  nlohmann::ordered_json j;
  j["mode"] = "image_sequence";
  j["map"] = options.reference_folder;
  j["query"] = options.query_folder;
  if (!options.ground_truth_csv.empty()) j["ground_truth"] = options.ground_truth_csv;
  j["references"] = e.reference_files.size();
  j["blank_references"] = e.blank_references;
  j["query_frames"] = e.query_files.size();
  j["blank_queries"] = e.blank_queries;
  j["frame_tolerance"] = options.frame_tolerance;
  j["sequence_length"] = options.matcher.sequence_length;
  j["centred"] = options.matcher.centred;
  const nlohmann::ordered_json sequence = MetricsJson(e.sequence_metrics);
  for (const auto& [key, value] : sequence.items()) j[key] = value;
  j["baselines"]["single_frame"] = MetricsJson(e.single_metrics);
  if (e.descriptors) {
    nlohmann::ordered_json d;
    d["map_file"] = options.reference_descriptors;
    d["query_file"] = options.query_descriptors;
    d["dimensions"] = e.descriptor_dimensions;
    const nlohmann::ordered_json by_sequence = MetricsJson(e.descriptors->sequence_metrics);
    for (const auto& [key, value] : by_sequence.items()) d[key] = value;
    d["single_frame"] = MetricsJson(e.descriptors->single_metrics);
    d["match_seconds"] = e.descriptor_match_seconds;
    j["descriptors"] = d;
  }
  if (e.fabmap) {
    nlohmann::ordered_json f = MetricsJson(e.fabmap->metrics);
    f["visual_words"] = e.fabmap->vocabulary;
    f["trained_on_references"] =
        e.fabmap->trained_here && options.fabmap_settings.visual_model.training_images.empty();
    f["words_per_reference"] = e.fabmap->words_per_reference;
    f["words_per_query"] = e.fabmap->words_per_query;
    f["seconds"] = e.fabmap->seconds;
    j["baselines"]["fabmap"] = f;
  }
  j["load_seconds"] = e.load_seconds;
  j["match_seconds"] = e.match_seconds;
  j["query_time_ms"] =
      e.query_files.empty() ? 0.0 : 1000.0 * e.match_seconds / e.query_files.size();
  j["run"] = io::RunObject(provenance, {options.reference_folder, options.query_folder},
                           std::nullopt, config_fingerprint);
  std::ostringstream csv;
  csv << "query,file,truth,sequence_match,sequence_confidence,sequence_correct,single_match,"
         "single_confidence,single_correct";
  if (e.descriptors) {
    csv << ",descriptor_sequence_match,descriptor_sequence_confidence,descriptor_sequence_correct,"
           "descriptor_single_match,descriptor_single_confidence,descriptor_single_correct";
  }
  if (e.fabmap) csv << ",fabmap_match,fabmap_confidence,fabmap_correct";
  csv << '\n';
  for (size_t q = 0; q < e.query_files.size(); ++q) {
    auto cells = [&](const QueryAnswer& a) {
      std::string s;
      if (a.match.declined) return std::string(",,") + (a.truth >= 0 ? "0" : "");
      s = std::to_string(a.match.reference) + ',' + ShortestNumber(a.match.confidence) + ',';
      if (a.truth >= 0) s += Within(a, a.match.reference, options.frame_tolerance) ? "1" : "0";
      return s;
    };
    csv << q << ',' << e.query_files[q] << ','
        << (e.truth[q] >= 0 ? std::to_string(e.truth[q]) : std::string()) << ','
        << cells(e.sequence[q]) << ',' << cells(e.single[q]);
    if (e.descriptors) {
      csv << ',' << cells(e.descriptors->sequence[q]) << ',' << cells(e.descriptors->single[q]);
    }
    if (e.fabmap) csv << ',' << cells(e.fabmap->answers[q]);
    csv << '\n';
  }
  std::ostringstream pr;
  pr << "method,threshold,precision,recall\n";
  std::vector<std::pair<const char*, const PlaceRecognitionMetrics*>> methods = {
      {"sequence", &e.sequence_metrics}, {"single_frame", &e.single_metrics}};
  if (e.descriptors) {
    methods.push_back({"descriptor_sequence", &e.descriptors->sequence_metrics});
    methods.push_back({"descriptor_single_frame", &e.descriptors->single_metrics});
  }
  if (e.fabmap) methods.push_back({"fabmap", &e.fabmap->metrics});
  for (const auto& [name, metrics] : methods) {
    for (const PrecisionRecall& p : metrics->curve) {
      pr << name << ',' << ShortestNumber(p.threshold) << ',' << ShortestNumber(p.precision) << ','
         << ShortestNumber(p.recall) << '\n';
    }
  }
  return out->Write({{"config.toml", config_toml},
                     {"evaluation.json", j.dump(2) + "\n"},
                     {"queries.csv", csv.str()},
                     {"pr_curve.csv", pr.str()}});
}

}  // namespace ratslam::session
