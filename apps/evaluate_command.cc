// `ratslam evaluate`: the fusion paper's localisation benchmark (sections 5.2-5.3) with FABMAP.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>

#include "apps/cli.h"
#include "apps/progress.h"
#include "common/number_text.h"
#include "common/output_folder.h"
#include "common/provenance.h"
#include "dataset/image_loader.h"
#include "io/config.h"
#include "render/renderer.h"
#include "session/evaluation_session.h"
#include "session/image_sequence_evaluation.h"
#include "viewer/localisation_figure.h"

namespace ratslam::apps {
namespace {

// One matcher of the image-sequence benchmark: its name in the table, its label in the figure.
struct ImageSequenceMatcherRow {
  std::string name, label;
  const session::PlaceRecognitionMetrics* metrics;
};

std::vector<ImageSequenceMatcherRow> MatcherRows(
    const session::ImageSequenceEvaluationOptions& options,
    const session::ImageSequenceEvaluation& e) {
  const std::string sequences =
      "sequences of " + std::to_string(options.matcher.sequence_length) + " frames";
  std::vector<ImageSequenceMatcherRow> rows = {
      {"sequence", sequences, &e.sequence_metrics},
      {"single frame", "single frames", &e.single_metrics}};
  if (e.descriptors) {
    rows.push_back(
        {"desc. sequence", "descriptors, " + sequences, &e.descriptors->sequence_metrics});
    rows.push_back({"desc. single", "descriptors, single frames", &e.descriptors->single_metrics});
  }
  if (e.fabmap) {
    rows.push_back({"FABMAP", "FABMAP (visual words), single frames", &e.fabmap->metrics});
  }
  return rows;
}

// pr_curve.png (every matcher) and difference_matrix.png (the images' sequence answers); the
// difference matrix moves out of `e`.
Status WriteImageSequenceFigures(const Arguments& args,
                                 const session::ImageSequenceEvaluationOptions& options,
                                 const std::vector<ImageSequenceMatcherRow>& rows,
                                 const std::string& tolerance, session::ImageSequenceEvaluation* e,
                                 OutputFolder* out) {
  std::vector<std::string> labels;
  std::vector<std::vector<double>> recall(rows.size()), precision(rows.size());
  for (size_t k = 0; k < rows.size(); ++k) {
    labels.push_back(rows[k].label);
    for (const session::PrecisionRecall& p : rows[k].metrics->curve) {
      recall[k].push_back(p.recall);
      precision[k].push_back(p.precision);
    }
  }
  const std::string title =
      "place recognition: " + std::to_string(e->sequence_metrics.queries) + " queries" + tolerance;
  const std::string accepted =
      e->fabmap ? "accepted: margin over runner-up (FABMAP: log odds) >= threshold"
                : "accepted: the answer's margin over the runner-up >= a threshold";
  RATSLAM_RETURN_IF_ERROR(WriteCommandFigure(args, out->Path("pr_curve.png"), [&](int w) {
    return viewer::PrecisionRecallScene(labels, recall, precision, title, w, accepted);
  }));
  viewer::DifferenceMatrixFigure figure;
  figure.differences = std::move(e->differences);
  for (const session::QueryAnswer& a : e->sequence) figure.answers.push_back(a.match.reference);
  figure.truth = e->truth;
  figure.blank_references = e->reference_blank;
  figure.frame_tolerance = options.frame_tolerance;
  figure.title = "differences and sequence answers";
  return WriteCommandFigure(args, out->Path("difference_matrix.png"),
                            [&](int) { return viewer::DifferenceMatrixScene(figure); });
}

// The terminal's table: a row per matcher.
std::string MatcherTable(const std::vector<ImageSequenceMatcherRow>& rows) {
  char line[160];
  std::snprintf(line, sizeof line, "%-14s %9s %9s %8s %12s %9s\n", "matcher", "recall@1",
                "recall@5", "PR AUC", "R@100%prec", "declined");
  std::string text = line;
  for (const ImageSequenceMatcherRow& row : rows) {
    const session::PlaceRecognitionMetrics& m = *row.metrics;
    std::snprintf(line, sizeof line, "%-14s %8.1f%% %8.1f%% %8.3f %11.1f%% %9zu\n",
                  row.name.c_str(), 100 * m.recall_at_1, 100 * m.recall_at_5, m.pr_auc,
                  100 * m.recall_at_100_precision, m.declined);
    text += line;
  }
  return text;
}

// Place recognition along a route: two image folders, right within N frames.
int ImageSequenceEvaluate(const Arguments& args, const fusion::PipelineOptions& pipeline) {
  auto fail = [](const Status& s) {
    std::cerr << MessagePrefix() << s.message() << "\n";
    return kExitError;
  };
  session::ImageSequenceEvaluationOptions options;
  options.reference_folder = args.values.at("--map");
  options.query_folder = args.values.at("--query");
  options.ground_truth_csv = args.Value("--ground-truth");
  options.frame_tolerance = static_cast<int>(args.Whole("--frame-tolerance"));
  options.matcher = pipeline.sensors.sequence;
  options.reference_descriptors = args.Value("--map-descriptors");
  options.query_descriptors = args.Value("--query-descriptors");
  options.fabmap = args.values.count("--fabmap") > 0;
  options.fabmap_settings = pipeline.sensors.fabmap;
  for (const std::string& folder : {options.reference_folder, options.query_folder}) {
    if (!session::IsImageSequenceFolder(folder)) {
      return fail(Status::Error(folder + ": with --frame-tolerance, --map and --query are "
                                         "folders of images (png, jpg, pgm, ...)"));
    }
  }
  const std::string out_path = args.values.at("--out");
  auto out = DiskFolder::Open(out_path);
  if (!out.ok()) return fail(out.status());
  ProgressPrinter progress(stderr, args.quiet);
  StopCooperatively();
  dataset::FileImageLoader loader;
  StatusOr<session::ImageSequenceEvaluation> e = session::EvaluateImageSequences(
      options, &loader,
      [&](size_t done, size_t total) {
        if (done % 100 == 0 || done == total) {
          ProgressUpdate u;
          u.phase = "queries";
          u.done = done;
          u.total = total;
          progress.Update(u);
        }
      },
      &StopFlag());
  progress.Finish();
  if (!e.ok()) {
    if (StopFlag().load()) {
      std::cerr << MessagePrefix() << "interrupted; no outputs written\n";
      return kExitInterrupted;
    }
    return fail(e.status());
  }
  if (Status s = session::WriteImageSequenceOutputs(options, *e, io::PrintConfig(pipeline),
                                                    io::ConfigFingerprint(pipeline),
                                                    args.Provenance(), out->get());
      !s.ok()) {
    return fail(s);
  }
  const std::vector<ImageSequenceMatcherRow> rows = MatcherRows(options, *e);
  const std::string tolerance = " (right within " + std::to_string(options.frame_tolerance) +
                                (options.frame_tolerance == 1 ? " frame)" : " frames)");
  if (Status s = WriteImageSequenceFigures(args, options, rows, tolerance, &*e, out->get());
      !s.ok()) {
    return fail(s);
  }
  std::string text = MatcherTable(rows);
  text += "(" + std::to_string(e->sequence_metrics.queries) + " queries" + tolerance + ", " +
          std::to_string(e->reference_files.size()) + " references; matching " +
          ShortestNumber(std::round(e->match_seconds * 1000) / 1000) + " s)\n";
  text += MessagePrefix() + "outputs in " + args.Shown(out_path) +
          " (evaluation.json; --json prints it here)\n";
  std::ifstream json((*out)->Path("evaluation.json"), std::ios::binary);
  std::stringstream json_text;
  json_text << json.rdbuf();
  PrintOutcome(args.values.count("--json") > 0, args.quiet, json_text.str(), text);
  return kExitOk;
}

}  // namespace

int EvaluateCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  session::EvaluationSessionOptions options;
  const auto pipeline = LoadOptions(*args, &options.config_path);
  if (!pipeline) return kExitError;
  if (args->values.count("--frame-tolerance")) return ImageSequenceEvaluate(*args, *pipeline);
  for (const char* image_only :
       {"--ground-truth", "--map-descriptors", "--query-descriptors", "--fabmap"}) {
    if (args->values.count(image_only)) {
      std::cerr << MessagePrefix() << image_only << " needs --frame-tolerance\n";
      return kExitUsage;
    }
  }
  options.pipeline = *pipeline;
  options.map_path = args->values.at("--map");
  options.query_path = args->values.at("--query");
  options.lenient = args->lenient;
  options.provenance = args->Provenance();
  const std::string out_path = args->values.at("--out");
  auto fail = [](const Status& s) {
    std::cerr << MessagePrefix() << s.message() << "\n";
    return kExitError;
  };
  auto out = DiskFolder::Open(out_path);
  if (!out.ok()) return fail(out.status());
  ProgressPrinter progress(stderr, args->quiet);
  session::EvaluationSession session(options, out->get(), nullptr, &progress);
  // Ctrl-C or SIGTERM stops it between steps, nothing written (exit 130).
  session.set_stop_flag(&StopFlag());
  StopCooperatively();
  auto fail_or_stop = [&](const Status& s) {
    if (!session.stopped()) return fail(s);
    std::cerr << MessagePrefix() << "interrupted; no outputs written\n";
    return kExitInterrupted;
  };
  if (Status s = session.Load(); !s.ok()) return fail_or_stop(s);
  const fabmap::FabmapMode mode = session.mode();
  if (!args->quiet) {
    std::fprintf(stderr, "%smode %s, %zu map nodes, %zu queries\n", MessagePrefix().c_str(),
                 fabmap::ToString(mode).c_str(), session.result().map.size(),
                 session.result().queries.size());
  }
  if (Status s = session.Prepare(); !s.ok()) return fail_or_stop(s);
  if (Status s = session.Localise(); !s.ok()) return fail_or_stop(s);
  if (Status s = session.WriteOutputs(); !s.ok()) return fail(s);
  const session::EvaluationResult& r = session.result();
  const fabmap::EvaluationMetrics& m = r.metrics;
  // The curves cannot show rejections and floor mistakes (neither is within nor beyond any d on
  // the floor): the labels give their rates.
  const auto label = [](const std::string& name, const fabmap::EvaluationMetrics& x) {
    char rates[96];
    std::snprintf(rates, sizeof rates, " (rejected %.1f %%, other floor %.1f %%)",
                  100 * x.rejection_rate, 100 * x.floor_mistake_rate);
    return name + rates;
  };
  // FABMAP's own curve says how it decided "new place": its arg-max, or the learnt threshold.
  std::string decision = ", arg-max";
  if (r.new_place.calibrated) {
    const fabmap::EvaluationOptions& e = options.pipeline.evaluation;
    const double t = r.new_place.log_odds;
    decision = std::isfinite(t) ? ", learnt threshold " + ShortestNumber(std::round(t)) + " nats"
                                : std::string(", learnt threshold: any mapped place");
    decision += e.new_place_rule == fabmap::NewPlaceRule::kNearRecall
                    ? " (near recall " + ShortestNumber(e.new_place_near_recall) + ")"
                    : " (Youden's J)";
  }
  std::vector<viewer::LocalisationCurve> curves = {
      {label("FABMAP " + fabmap::ToString(mode) + decision, m), m.errors_m}};
  for (const auto& [name, b] : r.baselines) {
    curves.push_back({label("baseline " + name, b), b.errors_m});
  }
  const std::string title = "FABMAP " + fabmap::ToString(mode) + ": " + std::to_string(m.queries) +
                            " queries, " + std::to_string(r.map.size()) + " mapped places";
  if (Status s = WriteCommandFigure(
          *args, (*out)->Path("localisation.png"),
          [&](int w) {
            return viewer::LocalisationCurvesScene(curves, title,
                                                   viewer::LocalisationAxisEndM(curves), w);
          },
          render::kTwoColumnMm);
      !s.ok()) {
    return fail(s);
  }
  {
    std::vector<std::string> labels;
    std::vector<std::vector<double>> recall, precision;
    for (size_t k = 0; k < m.distances_m.size(); ++k) {
      labels.push_back("correct: best mapped place within " + ShortestNumber(m.distances_m[k]) +
                       " m");
      recall.emplace_back();
      precision.emplace_back();
      for (const fabmap::PrecisionRecallPoint& p : r.precision_recall) {
        recall.back().push_back(p.recall[k]);
        precision.back().push_back(p.precision[k]);
      }
    }
    const std::string pr_title = "FABMAP " + fabmap::ToString(mode) + ": precision and recall";
    if (Status s = WriteCommandFigure(*args, (*out)->Path("pr_curve.png"),
                                      [&](int w) {
                                        return viewer::PrecisionRecallScene(labels, recall,
                                                                            precision, pr_title, w);
                                      });
        !s.ok()) {
      return fail(s);
    }
  }

  // The table on a terminal; evaluation.json into a pipe or with --json.
  std::string table;
  char cell[128];
  std::snprintf(cell, sizeof cell, "%-12s %6s %6s %6s %6s | %6s %6s %6s %6s | %6s %6s\n", "mode",
                "c2", "c5", "c10", "c20", "m2", "m5", "m10", "m20", "reject", "floor");
  table += cell;
  const auto row = [&](const std::string& name, const fabmap::EvaluationMetrics& x) {
    std::snprintf(cell, sizeof cell, "%-12s", name.c_str());
    table += cell;
    for (double v : x.correct_within) {
      std::snprintf(cell, sizeof cell, " %6.1f", 100 * v);
      table += cell;
    }
    table += " |";
    for (double v : x.misplaced_beyond) {
      std::snprintf(cell, sizeof cell, " %6.1f", 100 * v);
      table += cell;
    }
    std::snprintf(cell, sizeof cell, " | %6.1f %6.1f\n", 100 * x.rejection_rate,
                  100 * x.floor_mistake_rate);
    table += cell;
  };
  row(fabmap::ToString(mode), m);
  for (const auto& [name, b] : r.baselines) row(name, b);
  table += "(% of queries: cD the match within D m, mD beyond D m or on another floor)\n";
  table +=
      MessagePrefix() + "outputs in " + out_path + " (evaluation.json; --json prints it here)\n";
  std::ifstream json((*out)->Path("evaluation.json"), std::ios::binary);
  std::stringstream json_text;
  json_text << json.rdbuf();
  PrintOutcome(args->values.count("--json") > 0, args->quiet, json_text.str(), table);
  return kExitOk;
}

}  // namespace ratslam::apps
