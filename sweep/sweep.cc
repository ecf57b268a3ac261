// Sweep files, objectives and plans (sweep/sweep.h); running, Slurm and collecting are in
// sweep_runner.cc, sweep_slurm.cc and sweep_collect.cc.
#include "sweep/sweep.h"

#include <fcntl.h>
#include <glob.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "common/file_util.h"
#include "common/output_guard.h"
#include "common/random.h"
#include "common/text_file.h"
#include "common/toml_binder.h"
#include "io/config.h"
#include "io/run_outputs.h"
#include "session/evaluation_session.h"
#include "sweep/sweep_internal.h"

extern char** environ;

namespace ratslam::sweep {
namespace fs = std::filesystem;
using json = nlohmann::json;

// Where a run's metrics are: replay's summary or the benchmark's evaluation.
std::string MetricsFile(const SweepSpec& spec) {
  return spec.command == "evaluate" ? "evaluation.json" : "summary.json";
}

std::string RunFolder(const std::string& dir, int index) {
  char name[16];
  std::snprintf(name, sizeof name, "%05d", index);
  return (fs::path(dir) / "runs" / name).string();
}

// A CSV field, quoted when it holds a separator, a quote or a line break.
std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

namespace {

constexpr int kPlanVersion = 1;
constexpr size_t kMaxSweepBytes = 1 << 20;

// An objective: a metric, or an arithmetic expression of metrics ("map_ate_m + 0.05 * templates")
// with + - * /, parentheses, unary minus and numbers. Kept as reverse Polish notation.
class Expression {
 public:
  static StatusOr<Expression> Parse(const std::string& text) {
    Expression e;
    e.text_ = text;
    size_t pos = 0;
    if (!e.Sum(&pos) || (e.Skip(&pos), pos != text.size())) {
      return Status::Error("cannot read the objective '" + text + "' near character " +
                           std::to_string(pos + 1));
    }
    return e;
  }
  // The metrics it reads, in order of first use.
  std::vector<std::string> Metrics() const {
    std::vector<std::string> out;
    for (const Token& t : rpn_) {
      if (t.kind == 'm' && std::find(out.begin(), out.end(), t.name) == out.end()) {
        out.push_back(t.name);
      }
    }
    return out;
  }
  template <typename Lookup>
  std::optional<double> Evaluate(Lookup&& lookup) const {
    std::vector<double> stack;
    for (const Token& t : rpn_) {
      if (t.kind == 'n') {
        stack.push_back(t.value);
      } else if (t.kind == 'm') {
        const std::optional<double> v = lookup(t.name);
        if (!v) return std::nullopt;
        stack.push_back(*v);
      } else if (t.kind == '~') {
        stack.back() = -stack.back();
      } else {
        const double b = stack.back();
        stack.pop_back();
        double& a = stack.back();
        a = t.kind == '+' ? a + b : t.kind == '-' ? a - b : t.kind == '*' ? a * b : a / b;
      }
    }
    if (stack.size() != 1 || !std::isfinite(stack.back())) return std::nullopt;
    return stack.back();
  }

 private:
  struct Token {
    char kind;  // n number, m metric, ~ negation, or the operator
    double value = 0.0;
    std::string name;
  };
  void Skip(size_t* pos) const {
    while (*pos < text_.size() && text_[*pos] == ' ') ++*pos;
  }
  bool Sum(size_t* pos) {
    if (!Product(pos)) return false;
    for (Skip(pos); *pos < text_.size() && (text_[*pos] == '+' || text_[*pos] == '-'); Skip(pos)) {
      const char op = text_[(*pos)++];
      if (!Product(pos)) return false;
      rpn_.push_back({op, 0.0, {}});
    }
    return true;
  }
  bool Product(size_t* pos) {
    if (!Factor(pos)) return false;
    for (Skip(pos); *pos < text_.size() && (text_[*pos] == '*' || text_[*pos] == '/'); Skip(pos)) {
      const char op = text_[(*pos)++];
      if (!Factor(pos)) return false;
      rpn_.push_back({op, 0.0, {}});
    }
    return true;
  }
  bool Factor(size_t* pos) {
    Skip(pos);
    if (*pos >= text_.size()) return false;
    const char c = text_[*pos];
    if (c == '-') {
      ++*pos;
      if (!Factor(pos)) return false;
      rpn_.push_back({'~', 0.0, {}});
      return true;
    }
    if (c == '(') {
      ++*pos;
      if (!Sum(pos)) return false;
      Skip(pos);
      if (*pos >= text_.size() || text_[*pos] != ')') return false;
      ++*pos;
      return true;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      double v = 0.0;
      const auto r = std::from_chars(text_.data() + *pos, text_.data() + text_.size(), v);
      if (r.ec != std::errc()) return false;
      *pos = static_cast<size_t>(r.ptr - text_.data());
      rpn_.push_back({'n', v, {}});
      return true;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      const size_t start = *pos;
      while (*pos < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[*pos])) ||
                                     text_[*pos] == '_' || text_[*pos] == '.')) {
        ++*pos;
      }
      rpn_.push_back({'m', 0.0, text_.substr(start, *pos - start)});
      return true;
    }
    return false;
  }
  std::string text_;
  std::vector<Token> rpn_;
};

// The [sweep] table's own keys, bound like every other TOML table.
struct SweepSettings {
  std::string base_config;
  std::string command = "replay";
  std::string method = "grid";
  int samples = 0;
  uint64_t seed = 1;
  std::vector<std::string> metrics;
  std::string objective;
  std::string aggregate = "mean";
  std::string goal = "minimize";
  double timeout_s = 0.0;
  std::string keep = "small";
  std::string search = "all";
  double halving_rate = 3.0;

  template <typename V>
  void VisitFields(V&& v) {
    v("base_config", base_config, "configuration the parameters vary; empty: the defaults",
      schema::Any());
    v("command", command, "replay, or evaluate (the FABMAP benchmark)", schema::Any());
    v("method", method, "grid (every combination) or random (seeded draws)", schema::Any());
    v("samples", samples, "random: number of draws", schema::Unit("runs").NonNegative());
    v("seed", seed, "random: seed of the draws", schema::Any());
    v("metrics", metrics, "dotted keys of summary.json (evaluation.json) collected from every run",
      schema::Any());
    v("objective", objective, "the metric the sweep optimises", schema::Any().NotEmpty());
    v("aggregate", aggregate, "over the data sets: mean or worst", schema::Any());
    v("goal", goal, "minimize or maximize", schema::Any());
    v("timeout_s", timeout_s, "per run; 0: none", schema::Unit("s").NonNegative());
    v("keep", keep, "small (summary, config, trajectory) or all (every output)", schema::Any());
    v("search", search, "all tasks, or halving (successive halving over the data sets)",
      schema::Any());
    v("halving_rate", halving_rate, "halving: the share kept is 1/rate, data sets grow by rate",
      schema::Unit("").AtLeast(2).AtMost(100));
  }
};

std::string Literal(const toml::node& node, bool* ok) {
  *ok = true;
  if (const auto* i = node.as_integer()) return std::to_string(i->get());
  if (const auto* f = node.as_floating_point()) {
    if (std::isfinite(f->get())) return schema::TomlNumber(f->get());
  }
  if (const auto* b = node.as_boolean()) return b->get() ? "true" : "false";
  if (const auto* s = node.as_string()) return TomlQuoted(s->get());
  *ok = false;
  return "";
}

std::string Number(double v, bool integer) {
  return integer ? std::to_string(std::llround(v)) : schema::TomlNumber(v);
}

// Paths of a sweep file are relative to its folder; a glob gives every match, sorted.
StatusOr<std::vector<std::string>> Expand(const std::string& pattern, const fs::path& base,
                                          const std::string& where) {
  const std::string full = fs::path(pattern).is_absolute() ? pattern : (base / pattern).string();
  if (full.find_first_of("*?[") == std::string::npos) {
    if (!PathExists(full)) return Status::Error(where + ": no such data set: " + full);
    return std::vector<std::string>{fs::absolute(full).lexically_normal().string()};
  }
  glob_t g{};
  const int rc = glob(full.c_str(), 0, nullptr, &g);
  std::vector<std::string> out;
  for (size_t i = 0; rc == 0 && i < g.gl_pathc; ++i) {
    out.push_back(fs::absolute(g.gl_pathv[i]).lexically_normal().string());
  }
  globfree(&g);
  if (out.empty()) return Status::Error(where + ": no file matches " + full);
  std::sort(out.begin(), out.end());
  return out;
}

StatusOr<Parameter> ReadParameter(const std::string& key, const toml::node& node,
                                  const std::string& source) {
  Parameter p;
  p.key = key;
  p.line = static_cast<int>(node.source().begin.line);
  const std::string where = schema::TomlWhere(source, &node) + ": parameter '" + key + "'";
  if (key.find('.') == std::string::npos) {
    return Status::Error(where + ": expected \"section.key\"");
  }
  if (const auto* list = node.as_array()) {
    for (const auto& element : *list) {
      bool ok = false;
      p.values.push_back(Literal(element, &ok));
      if (!ok) return Status::Error(where + ": values must be numbers, booleans or strings");
    }
    if (p.values.empty()) return Status::Error(where + ": no values");
    return p;
  }
  const auto* range = node.as_table();
  if (!range || range->size() != 1) {
    return Status::Error(where +
                         ": expected a list of values or one of {linear = [a, b, n]}, {log = [a, "
                         "b, n]}, {uniform = [a, b]}, {log_uniform = [a, b]}");
  }
  const std::string kind(range->cbegin()->first.str());
  const auto* bounds = range->cbegin()->second.as_array();
  std::vector<double> v;
  bool integer = bounds != nullptr;
  for (size_t i = 0; bounds && i < bounds->size(); ++i) {
    double x = 0.0;
    if (!schema::TomlToDouble(*bounds->get(i), &x)) return Status::Error(where + ": not a number");
    if (i < 2 && !bounds->get(i)->as_integer()) integer = false;
    v.push_back(x);
  }
  const bool sampled = kind == "uniform" || kind == "log_uniform";
  const bool log_scale = kind == "log" || kind == "log_uniform";
  if (!(kind == "linear" || kind == "log" || sampled)) {
    return Status::Error(where + ": unknown range '" + kind +
                         "' (linear, log, uniform or log_uniform)");
  }
  if (v.size() != (sampled ? 2u : 3u) ||
      (!sampled && (v[2] < 2 || v[2] != std::floor(v[2]) || v[2] > 100000))) {
    return Status::Error(where + ": expected " +
                         (sampled ? std::string("[a, b]") : "[a, b, n] with a whole n >= 2"));
  }
  if (log_scale && !(v[0] > 0.0 && v[1] > 0.0)) {
    return Status::Error(where + ": a log range needs positive ends");
  }
  p.integer = integer;
  p.log_scale = log_scale;
  p.lo = v[0];
  p.hi = v[1];
  if (sampled) return p;
  const int n = static_cast<int>(v[2]);
  for (int i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / (n - 1);
    const double x = log_scale ? std::exp(std::log(v[0]) + t * (std::log(v[1]) - std::log(v[0])))
                               : v[0] + t * (v[1] - v[0]);
    const std::string literal = Number(i == n - 1 ? v[1] : x, integer);
    if (std::find(p.values.begin(), p.values.end(), literal) == p.values.end()) {
      p.values.push_back(literal);
    }
  }
  return p;
}

// "[section]\nkey = value\n..." for a set of overrides, one header per section.
std::string OverrideText(const std::vector<std::pair<std::string, std::string>>& overrides) {
  std::map<std::string, std::string> by_section;
  for (const auto& [key, value] : overrides) {
    const size_t dot = key.find('.');
    by_section[key.substr(0, dot)] += key.substr(dot + 1) + " = " + value + "\n";
  }
  std::string text;
  for (const auto& [section, lines] : by_section) text += "[" + section + "]\n" + lines;
  return text;
}

// The message of a config error without its "source:line: " prefix.
std::string WithoutLocation(const std::string& message, const std::string& source) {
  if (message.rfind(source + ":", 0) != 0) return message;
  const size_t colon = message.find(": ", source.size());
  return colon == std::string::npos ? message : message.substr(colon + 2);
}

json SpecToJson(const SweepSpec& s) {
  json parameters = json::array();
  for (const Parameter& p : s.parameters) {
    parameters.push_back({{"key", p.key},
                          {"values", p.values},
                          {"log_scale", p.log_scale},
                          {"integer", p.integer},
                          {"lo", p.lo},
                          {"hi", p.hi},
                          {"line", p.line}});
  }
  return {{"source", s.source},
          {"command", s.command},
          {"base_config", s.base_config_text},
          {"datasets", s.datasets},
          {"parameters", parameters},
          {"method", s.method},
          {"samples", s.samples},
          {"seed", s.seed},
          {"metrics", s.metrics},
          {"objective", s.objective},
          {"aggregate", s.aggregate},
          {"goal", s.goal},
          {"timeout_s", s.timeout_s},
          {"keep_all", s.keep_all},
          {"search", s.search},
          {"halving_rate", s.halving_rate}};
}

// A plan.json that does not hold what `sweep plan` writes (edited by hand, or damaged).
struct PlanError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// An integer field within [lo, hi]: json's own conversion of a fraction or of a number out of
// the type's range is undefined.
int64_t IntAt(const json& j, const char* key, int64_t lo, int64_t hi) {
  const json& v = j.at(key);
  const bool in_range = v.is_number_unsigned()  ? v.get<uint64_t>() <= static_cast<uint64_t>(hi)
                        : v.is_number_integer() ? v.get<int64_t>() >= lo && v.get<int64_t>() <= hi
                                                : false;
  if (!in_range) {
    throw PlanError(std::string(key) + " must be an integer from " + std::to_string(lo) + " to " +
                    std::to_string(hi));
  }
  return v.get<int64_t>();
}

// A number field, finite and within [lo, hi].
double NumberAt(const json& j, const char* key, double fallback, double lo, double hi) {
  if (!j.contains(key)) return fallback;
  const json& v = j.at(key);
  if (!v.is_number() || !(v.get<double>() >= lo && v.get<double>() <= hi)) {
    std::ostringstream range;
    range << " must be a "
          << (hi < std::numeric_limits<double>::max() ? "number from "
                                                      : "finite number of at least ")
          << lo;
    if (hi < std::numeric_limits<double>::max()) range << " to " << hi;
    throw PlanError(std::string(key) + range.str());
  }
  return v.get<double>();
}

// A string field that must be one of `allowed`.
std::string OneOf(const json& j, const char* key, std::initializer_list<const char*> allowed,
                  const char* fallback = nullptr) {
  const std::string v =
      fallback && !j.contains(key) ? std::string(fallback) : j.at(key).get<std::string>();
  for (const char* a : allowed) {
    if (v == a) return v;
  }
  throw PlanError(std::string(key) + " '" + v + "' is not one the sweep knows");
}

SweepSpec SpecFromJson(const json& j) {
  SweepSpec s;
  s.source = j.at("source").get<std::string>();
  s.base_config_text = j.at("base_config").get<std::string>();
  s.command = OneOf(j, "command", {"replay", "evaluate"}, "replay");
  s.datasets = j.at("datasets").get<std::vector<std::vector<std::string>>>();
  for (const json& p : j.at("parameters")) {
    Parameter q;
    q.key = p.at("key").get<std::string>();
    q.values = p.at("values").get<std::vector<std::string>>();
    q.log_scale = p.at("log_scale").get<bool>();
    q.integer = p.at("integer").get<bool>();
    q.lo = p.at("lo").get<double>();
    q.hi = p.at("hi").get<double>();
    q.line = static_cast<int>(IntAt(p, "line", 0, std::numeric_limits<int>::max()));
    s.parameters.push_back(q);
  }
  s.method = OneOf(j, "method", {"grid", "random"});
  s.samples = static_cast<int>(IntAt(j, "samples", 0, std::numeric_limits<int>::max()));
  const json& seed = j.at("seed");
  if (!seed.is_number_unsigned() && !(seed.is_number_integer() && seed.get<int64_t>() >= 0)) {
    throw PlanError("seed must be an integer of at least 0");
  }
  s.seed = seed.get<uint64_t>();
  s.metrics = j.at("metrics").get<std::vector<std::string>>();
  s.objective = j.at("objective").get<std::string>();
  if (StatusOr<Expression> e = Expression::Parse(s.objective); !e.ok()) {
    throw PlanError("objective: " + e.status().message());
  }
  s.aggregate = OneOf(j, "aggregate", {"mean", "worst"});
  s.goal = OneOf(j, "goal", {"minimize", "maximize"});
  s.timeout_s = NumberAt(j, "timeout_s", 0.0, 0.0, std::numeric_limits<double>::max());
  s.keep_all = j.at("keep_all").get<bool>();
  s.search = OneOf(j, "search", {"all", "halving"}, "all");  // added after the first plans
  s.halving_rate = NumberAt(j, "halving_rate", 3.0, 2.0, 100.0);
  return s;
}

json PlanToJson(const Plan& plan) {
  json tasks = json::array();
  for (const Task& t : plan.tasks) {
    json overrides = json::array();
    for (const auto& [key, value] : t.overrides) overrides.push_back({key, value});
    tasks.push_back(
        {{"index", t.index}, {"point", t.point}, {"dataset", t.dataset}, {"overrides", overrides}});
  }
  return {{"format", "ratslam-sweep-plan"},
          {"version", kPlanVersion},
          {"spec", SpecToJson(plan.spec)},
          {"points", plan.points},
          {"tasks", tasks}};
}

}  // namespace

// The value at a dotted path of a JSON object ("match_rate_within_m.5"), if it is a number; true
// and false count as 1 and 0 (so a point's mean over its data sets is a share).
std::optional<double> Metric(const json& summary, const std::string& dotted) {
  const json* node = &summary;
  size_t start = 0;
  while (true) {
    const size_t dot = dotted.find('.', start);
    const std::string part = dotted.substr(start, dot == std::string::npos ? dot : dot - start);
    if (!node->is_object() || !node->contains(part)) return std::nullopt;
    node = &(*node)[part];
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  if (node->is_boolean()) return node->get<bool>() ? 1.0 : 0.0;
  if (!node->is_number()) return std::nullopt;
  return node->get<double>();
}

// The objective (a metric or an expression of metrics) of one run's summary.
std::optional<double> ObjectiveOf(const json& summary, const std::string& objective) {
  StatusOr<Expression> e = Expression::Parse(objective);
  if (!e.ok()) return std::nullopt;
  return e->Evaluate([&](const std::string& name) { return Metric(summary, name); });
}

namespace {

// [sweep]: its settings checked into `spec` (the base configuration aside). `parsed` holds the
// table; errors name its key's line.
Status ReadSweepSettings(const toml::table& parsed, schema::TableBinder& top,
                         const std::string& path, SweepSettings* settings, SweepSpec* spec) {
  if (const toml::table* t = top.Table("sweep")) {
    schema::TableBinder binder(*t, "[sweep]", "sweep.", path);
    settings->VisitFields(binder);
    RATSLAM_RETURN_IF_ERROR(binder.Finish());
  } else {
    return Status::Error(path + ": missing [sweep] table");
  }
  const SweepSettings& s = *settings;
  const toml::table& sweep_table = *parsed["sweep"].as_table();
  auto fail_at = [&](const char* key, const std::string& message) {
    return Status::Error(schema::TomlWhere(path, sweep_table.get(key)) + ": sweep." + key + ": " +
                         message);
  };
  if (s.command != "replay" && s.command != "evaluate") {
    return fail_at("command", "must be replay or evaluate");
  }
  spec->command = s.command;
  if (s.method != "grid" && s.method != "random")
    return fail_at("method", "must be grid or random");
  if (s.method == "random" && s.samples < 1) {
    return fail_at("samples", "random needs samples >= 1");
  }
  if (s.aggregate != "mean" && s.aggregate != "worst") {
    return fail_at("aggregate", "must be mean or worst");
  }
  if (s.goal != "minimize" && s.goal != "maximize") {
    return fail_at("goal", "must be minimize or maximize");
  }
  if (s.keep != "small" && s.keep != "all") return fail_at("keep", "must be small or all");
  if (s.search != "all" && s.search != "halving") {
    return fail_at("search", "must be all or halving");
  }
  spec->search = s.search;
  spec->halving_rate = s.halving_rate;
  spec->method = s.method;
  spec->samples = s.samples;
  spec->seed = s.seed;
  spec->metrics = s.metrics;
  StatusOr<Expression> objective = Expression::Parse(s.objective);
  if (!objective.ok()) return fail_at("objective", objective.status().message());
  // The objective's metrics first, then the others asked for.
  std::vector<std::string> metrics;
  for (const std::string& m : objective->Metrics()) {
    if (std::find(spec->metrics.begin(), spec->metrics.end(), m) == spec->metrics.end()) {
      metrics.push_back(m);
    }
  }
  spec->metrics.insert(spec->metrics.begin(), metrics.begin(), metrics.end());
  // A misspelt metric once ran every task and ranked nothing: the names are checked now, by
  // their first part against the keys the command's summary can have.
  const std::vector<std::string>& keys =
      s.command == "evaluate" ? session::EvaluationKeys() : io::SummaryKeys();
  const std::set<std::string> known(keys.begin(), keys.end());
  const std::string file = s.command == "evaluate" ? "evaluation.json" : "summary.json";
  for (const std::string& m : spec->metrics) {
    const std::string first = m.substr(0, m.find('.'));
    if (known.count(first)) continue;
    const std::vector<std::string> in_expression = objective->Metrics();
    const bool in_objective =
        std::find(in_expression.begin(), in_expression.end(), m) != in_expression.end();
    return fail_at(in_objective ? "objective" : "metrics",
                   "'" + m + "' is not a key of " + file + schema::DidYouMean(first, known));
  }
  spec->objective = s.objective;
  spec->aggregate = s.aggregate;
  spec->goal = s.goal;
  spec->timeout_s = s.timeout_s;
  spec->keep_all = s.keep == "all";
  return Status::Ok();
}

// [[datasets]]: `data = [...]` is one run over those sessions; `glob = "..."` is one run per
// matching file or folder. Relative paths are from `base`, the sweep file's folder.
Status ReadDatasets(schema::TableBinder& top, const std::string& path, const fs::path& base,
                    SweepSpec* spec) {
  for (const toml::table* entry : top.Tables("datasets")) {
    schema::TableBinder binder(*entry, "[[datasets]]", "datasets.", path);
    std::vector<std::string> data;
    std::string pattern;
    binder("data", data, "the sessions of one run", schema::Any());
    binder("glob", pattern, "one run per match", schema::Any());
    RATSLAM_RETURN_IF_ERROR(binder.Finish());
    const std::string where = schema::TomlWhere(path, entry);
    if (data.empty() == pattern.empty()) {
      return Status::Error(where + ": [[datasets]] needs either data = [...] or glob = \"...\"");
    }
    if (!pattern.empty()) {
      StatusOr<std::vector<std::string>> matches = Expand(pattern, base, where);
      if (!matches.ok()) return matches.status();
      for (const std::string& m : *matches) spec->datasets.push_back({m});
      continue;
    }
    std::vector<std::string> sessions;
    for (const std::string& d : data) {
      StatusOr<std::vector<std::string>> matches = Expand(d, base, where);
      if (!matches.ok()) return matches.status();
      sessions.insert(sessions.end(), matches->begin(), matches->end());
    }
    spec->datasets.push_back(sessions);
  }
  if (spec->datasets.empty()) return Status::Error(path + ": no [[datasets]]");
  if (spec->command == "evaluate") {
    for (const auto& d : spec->datasets) {
      if (d.size() > 2) {
        return Status::Error(path + ": evaluate takes data = [map] or [map, query], not " +
                             std::to_string(d.size()) + " data sets");
      }
    }
  }
  return Status::Ok();
}

// [parameters]: each key's values or range (a grid needs values).
Status ReadParameters(schema::TableBinder& top, const std::string& path, SweepSpec* spec) {
  const toml::table* parameters = top.Table("parameters");
  if (!parameters) return Status::Ok();
  for (const auto& [key, node] : *parameters) {
    StatusOr<Parameter> p = ReadParameter(std::string(key.str()), node, path);
    if (!p.ok()) return p.status();
    if (spec->method == "grid" && p->values.empty()) {
      return Status::Error(schema::TomlWhere(path, &node) + ": parameter '" + p->key +
                           "': uniform and log_uniform ranges need method = \"random\"");
    }
    spec->parameters.push_back(*p);
  }
  return Status::Ok();
}

}  // namespace

StatusOr<SweepSpec> LoadSweepFile(const std::string& path) {
  StatusOr<std::string> text = ReadRegularFile(path, "sweep file", kMaxSweepBytes);
  if (!text.ok()) return text.status();
  StatusOr<toml::table> parsed = schema::ParseToml(*text, path);
  if (!parsed.ok()) return parsed.status();
  const fs::path base = fs::absolute(path).parent_path();
  SweepSpec spec;
  spec.source = path;
  schema::TableBinder top(*parsed, "the sweep file", "", path);
  SweepSettings settings;
  RATSLAM_RETURN_IF_ERROR(ReadSweepSettings(*parsed, top, path, &settings, &spec));
  fusion::PipelineOptions base_options;
  if (!settings.base_config.empty()) {
    const fs::path config = fs::path(settings.base_config).is_absolute()
                                ? fs::path(settings.base_config)
                                : base / settings.base_config;
    StatusOr<fusion::PipelineOptions> loaded = io::LoadConfigFile(config.string());
    if (!loaded.ok()) return loaded.status().WithContext(path + ": sweep.base_config");
    base_options = *loaded;
  }
  spec.base_config_text = io::PrintConfig(base_options, false);
  RATSLAM_RETURN_IF_ERROR(ReadDatasets(top, path, base, &spec));
  RATSLAM_RETURN_IF_ERROR(ReadParameters(top, path, &spec));
  RATSLAM_RETURN_IF_ERROR(top.Finish());
  return spec;
}

StatusOr<Plan> MakePlan(const SweepSpec& spec) {
  Plan plan;
  plan.spec = spec;
  StatusOr<fusion::PipelineOptions> base =
      io::ParseConfig(spec.base_config_text, "base configuration");
  if (!base.ok()) return base.status();
  // Each value alone first, so that an error names the parameter's line.
  for (const Parameter& p : spec.parameters) {
    std::vector<std::string> values = p.values;
    if (values.empty()) values = {Number(p.lo, p.integer), Number(p.hi, p.integer)};
    for (const std::string& v : values) {
      StatusOr<fusion::PipelineOptions> one =
          io::ParseConfigOnto(OverrideText({{p.key, v}}), spec.source, *base);
      if (!one.ok()) {
        return Status::Error(spec.source + ":" + std::to_string(p.line) + ": parameter '" + p.key +
                             "' = " + v + ": " +
                             WithoutLocation(one.status().message(), spec.source));
      }
    }
  }
  // Counted before anything is built: more than 10^6 runs is not a sweep this tool can hold.
  double runs = spec.method == "grid" ? 1.0 : static_cast<double>(spec.samples);
  for (const Parameter& p : spec.parameters) {
    if (spec.method == "grid") runs *= static_cast<double>(p.values.size());
  }
  runs *= static_cast<double>(spec.datasets.size());
  if (runs > 1e6) {
    return Status::Error(spec.source + ": " + schema::TomlNumber(runs) +
                         " runs; a sweep plans at most 10^6");
  }
  std::vector<std::vector<std::pair<std::string, std::string>>> points;
  if (spec.method == "grid") {
    points.push_back({});
    for (const Parameter& p : spec.parameters) {
      std::vector<std::vector<std::pair<std::string, std::string>>> next;
      for (const auto& partial : points) {
        for (const std::string& v : p.values) {
          next.push_back(partial);
          next.back().emplace_back(p.key, v);
        }
      }
      points = std::move(next);
    }
  } else {
    Random random(spec.seed);
    for (int s = 0; s < spec.samples; ++s) {
      std::vector<std::pair<std::string, std::string>> point;
      for (const Parameter& p : spec.parameters) {
        if (!p.values.empty()) {
          point.emplace_back(p.key, p.values[random.NextU64() % p.values.size()]);
        } else {
          const double u = random.Uniform();
          const double x = p.log_scale
                               ? std::exp(std::log(p.lo) + u * (std::log(p.hi) - std::log(p.lo)))
                               : p.lo + u * (p.hi - p.lo);
          point.emplace_back(p.key, Number(x, p.integer));
        }
      }
      points.push_back(point);
    }
  }
  plan.points = static_cast<int>(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    for (size_t d = 0; d < spec.datasets.size(); ++d) {
      Task t;
      t.index = static_cast<int>(plan.tasks.size());
      t.point = static_cast<int>(i);
      t.dataset = static_cast<int>(d);
      t.overrides = points[i];
      plan.tasks.push_back(t);
    }
    // The whole combination (relations between keys, e.g. min < max) once per point.
    StatusOr<fusion::PipelineOptions> all =
        io::ParseConfigOnto(OverrideText(points[i]), spec.source, *base);  // base parsed once
    if (!all.ok()) {
      std::string values;
      for (const auto& [key, value] : points[i])
        values += (values.empty() ? "" : ", ") + key + " = " + value;
      return Status::Error(spec.source + ": point " + std::to_string(i) + " (" + values +
                           "): " + WithoutLocation(all.status().message(), spec.source));
    }
  }
  return plan;
}

StatusOr<fusion::PipelineOptions> TaskConfig(const Plan& plan, const Task& task) {
  StatusOr<fusion::PipelineOptions> base =
      io::ParseConfig(plan.spec.base_config_text, "base configuration");
  if (!base.ok()) return base.status();
  return io::ParseConfigOnto(OverrideText(task.overrides), plan.spec.source, *base);
}

Status WritePlan(const Plan& plan, const std::string& dir) {
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "runs", ec);
  if (ec) return Status::Error(dir + ": cannot create folder: " + ec.message());
  const std::string text = PlanToJson(plan).dump(1) + "\n";
  const fs::path plan_path = fs::path(dir) / "plan.json";
  if (PathExists(plan_path)) {
    StatusOr<std::string> existing = ReadRegularFile(plan_path.string(), "plan", size_t{1} << 30);
    if (!existing.ok()) return existing.status();
    if (*existing == text) return Status::Ok();  // re-planning the same sweep changes nothing
    return Status::Error(plan_path.string() +
                         ": holds a different plan; use a new folder for a changed sweep");
  }
  std::string csv = "index,point,dataset,data,overrides\n";
  for (const Task& t : plan.tasks) {
    std::string data, overrides;
    for (const std::string& d : plan.spec.datasets[t.dataset])
      data += (data.empty() ? "" : ";") + d;
    for (const auto& [key, value] : t.overrides) {
      overrides += (overrides.empty() ? "" : ";") + key + "=" + value;
    }
    csv += std::to_string(t.index) + "," + std::to_string(t.point) + "," +
           std::to_string(t.dataset) + "," + CsvField(data) + "," + CsvField(overrides) + "\n";
  }
  RATSLAM_RETURN_IF_ERROR(WriteFileAtomically((fs::path(dir) / "tasks.csv").string(), csv));
  return WriteFileAtomically(plan_path.string(), text);
}

StatusOr<Plan> ReadPlan(const std::string& dir) {
  const std::string path = (fs::path(dir) / "plan.json").string();
  StatusOr<std::string> text = ReadRegularFile(path, "plan", size_t{1} << 30);
  if (!text.ok()) return text.status();
  try {
    const json j = json::parse(*text);
    if (j.at("format") != "ratslam-sweep-plan" || j.at("version") != kPlanVersion) {
      return Status::Error(path + ": not a sweep plan of version " + std::to_string(kPlanVersion));
    }
    Plan plan;
    plan.spec = SpecFromJson(j.at("spec"));
    if (plan.spec.datasets.empty()) throw PlanError("spec: no data sets");
    const json& tasks = j.at("tasks");
    if (!tasks.is_array()) throw PlanError("tasks must be an array");
    // Every point has a task (MakePlan: one per data set, point-major), so a point count above
    // the tasks' is damage, not a plan.
    plan.points = static_cast<int>(IntAt(j, "points", 0, static_cast<int64_t>(tasks.size())));
    std::vector<const Task*> first_of_point(static_cast<size_t>(plan.points), nullptr);
    plan.tasks.reserve(tasks.size());
    for (const json& t : tasks) {
      const size_t i = plan.tasks.size();
      Task task;
      task.index = static_cast<int>(IntAt(t, "index", 0, std::numeric_limits<int>::max()));
      task.point = static_cast<int>(IntAt(t, "point", 0, std::max(plan.points - 1, 0)));
      task.dataset = static_cast<int>(IntAt(t, "dataset", 0, std::numeric_limits<int>::max()));
      for (const json& o : t.at("overrides")) {
        task.overrides.emplace_back(o.at(0).get<std::string>(), o.at(1).get<std::string>());
      }
      const Task* first =
          plan.points > 0 ? first_of_point[static_cast<size_t>(task.point)] : nullptr;
      if (static_cast<size_t>(task.index) != i || plan.points == 0 ||
          static_cast<size_t>(task.dataset) >= plan.spec.datasets.size() ||
          (first && first->overrides != task.overrides)) {
        return Status::Error(path + ": task " + std::to_string(i) +
                             " is out of order, names a missing data set or point, or differs "
                             "from its point's parameters");
      }
      plan.tasks.push_back(task);
      if (!first) first_of_point[static_cast<size_t>(task.point)] = &plan.tasks.back();
    }
    for (int p = 0; p < plan.points; ++p) {
      if (!first_of_point[static_cast<size_t>(p)]) {
        throw PlanError("point " + std::to_string(p) + " has no task");
      }
    }
    return plan;
  } catch (const json::exception& e) {
    return Status::Error(path + ": " + e.what());
  } catch (const PlanError& e) {
    return Status::Error(path + ": " + e.what());
  }
}
}  // namespace ratslam::sweep
