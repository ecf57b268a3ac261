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
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "common/file_util.h"
#include "common/output_guard.h"
#include "common/random.h"
#include "common/text_file.h"
#include "common/toml_binder.h"
#include "fusion/io/config.h"
#include "fusion/io/run_outputs.h"
#include "session/evaluation_session.h"

extern char** environ;

namespace ratslam::sweep {
namespace fs = std::filesystem;
using json = nlohmann::json;

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

SweepSpec SpecFromJson(const json& j) {
  SweepSpec s;
  s.source = j.at("source").get<std::string>();
  s.base_config_text = j.at("base_config").get<std::string>();
  s.command = j.value("command", std::string("replay"));
  s.datasets = j.at("datasets").get<std::vector<std::vector<std::string>>>();
  for (const json& p : j.at("parameters")) {
    Parameter q;
    q.key = p.at("key").get<std::string>();
    q.values = p.at("values").get<std::vector<std::string>>();
    q.log_scale = p.at("log_scale").get<bool>();
    q.integer = p.at("integer").get<bool>();
    q.lo = p.at("lo").get<double>();
    q.hi = p.at("hi").get<double>();
    q.line = p.at("line").get<int>();
    s.parameters.push_back(q);
  }
  s.method = j.at("method").get<std::string>();
  s.samples = j.at("samples").get<int>();
  s.seed = j.at("seed").get<uint64_t>();
  s.metrics = j.at("metrics").get<std::vector<std::string>>();
  s.objective = j.at("objective").get<std::string>();
  s.aggregate = j.at("aggregate").get<std::string>();
  s.goal = j.at("goal").get<std::string>();
  s.timeout_s = j.at("timeout_s").get<double>();
  s.keep_all = j.at("keep_all").get<bool>();
  s.search = j.value("search", std::string("all"));  // added after the first plans
  s.halving_rate = j.value("halving_rate", 3.0);
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
  if (const toml::table* t = top.Table("sweep")) {
    schema::TableBinder binder(*t, "[sweep]", "sweep.", path);
    settings.VisitFields(binder);
    RATSLAM_RETURN_IF_ERROR(binder.Finish());
  } else {
    return Status::Error(path + ": missing [sweep] table");
  }
  const toml::table& sweep_table = *(*parsed)["sweep"].as_table();
  auto fail_at = [&](const char* key, const std::string& message) {
    return Status::Error(schema::TomlWhere(path, sweep_table.get(key)) + ": sweep." + key + ": " +
                         message);
  };
  if (settings.command != "replay" && settings.command != "evaluate") {
    return fail_at("command", "must be replay or evaluate");
  }
  spec.command = settings.command;
  if (settings.method != "grid" && settings.method != "random") {
    return fail_at("method", "must be grid or random");
  }
  if (settings.method == "random" && settings.samples < 1) {
    return fail_at("samples", "random needs samples >= 1");
  }
  if (settings.aggregate != "mean" && settings.aggregate != "worst") {
    return fail_at("aggregate", "must be mean or worst");
  }
  if (settings.goal != "minimize" && settings.goal != "maximize") {
    return fail_at("goal", "must be minimize or maximize");
  }
  if (settings.keep != "small" && settings.keep != "all") {
    return fail_at("keep", "must be small or all");
  }
  if (settings.search != "all" && settings.search != "halving") {
    return fail_at("search", "must be all or halving");
  }
  spec.search = settings.search;
  spec.halving_rate = settings.halving_rate;
  spec.method = settings.method;
  spec.samples = settings.samples;
  spec.seed = settings.seed;
  spec.metrics = settings.metrics;
  StatusOr<Expression> objective = Expression::Parse(settings.objective);
  if (!objective.ok()) return fail_at("objective", objective.status().message());
  // The objective's metrics first, then the others asked for.
  std::vector<std::string> metrics;
  for (const std::string& m : objective->Metrics()) {
    if (std::find(spec.metrics.begin(), spec.metrics.end(), m) == spec.metrics.end()) {
      metrics.push_back(m);
    }
  }
  spec.metrics.insert(spec.metrics.begin(), metrics.begin(), metrics.end());
  // A misspelt metric once ran every task and ranked nothing: the names are checked now, by
  // their first part against the keys the command's summary can have.
  {
    const std::vector<std::string>& keys =
        settings.command == "evaluate" ? EvaluationKeys() : SummaryKeys();
    const std::set<std::string> known(keys.begin(), keys.end());
    const std::string file = settings.command == "evaluate" ? "evaluation.json" : "summary.json";
    for (const std::string& m : spec.metrics) {
      const std::string top = m.substr(0, m.find('.'));
      if (known.count(top)) continue;
      const std::vector<std::string> in_expression = objective->Metrics();
      const bool in_objective =
          std::find(in_expression.begin(), in_expression.end(), m) != in_expression.end();
      return fail_at(in_objective ? "objective" : "metrics",
                     "'" + m + "' is not a key of " + file + schema::DidYouMean(top, known));
    }
  }
  spec.objective = settings.objective;
  spec.aggregate = settings.aggregate;
  spec.goal = settings.goal;
  spec.timeout_s = settings.timeout_s;
  spec.keep_all = settings.keep == "all";

  PipelineOptions base_options;
  if (!settings.base_config.empty()) {
    const fs::path config = fs::path(settings.base_config).is_absolute()
                                ? fs::path(settings.base_config)
                                : base / settings.base_config;
    StatusOr<PipelineOptions> loaded = LoadConfigFile(config.string());
    if (!loaded.ok()) return loaded.status().WithContext(path + ": sweep.base_config");
    base_options = *loaded;
  }
  spec.base_config_text = PrintConfig(base_options, false);

  // [[datasets]]: `data = [...]` is one run over those sessions; `glob = "..."` is one run per
  // matching file or folder.
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
      for (const std::string& m : *matches) spec.datasets.push_back({m});
      continue;
    }
    std::vector<std::string> sessions;
    for (const std::string& d : data) {
      StatusOr<std::vector<std::string>> matches = Expand(d, base, where);
      if (!matches.ok()) return matches.status();
      sessions.insert(sessions.end(), matches->begin(), matches->end());
    }
    spec.datasets.push_back(sessions);
  }
  if (spec.datasets.empty()) return Status::Error(path + ": no [[datasets]]");
  if (spec.command == "evaluate") {
    for (const auto& d : spec.datasets) {
      if (d.size() > 2) {
        return Status::Error(path + ": evaluate takes data = [map] or [map, query], not " +
                             std::to_string(d.size()) + " data sets");
      }
    }
  }
  if (const toml::table* parameters = top.Table("parameters")) {
    for (const auto& [key, node] : *parameters) {
      StatusOr<Parameter> p = ReadParameter(std::string(key.str()), node, path);
      if (!p.ok()) return p.status();
      if (spec.method == "grid" && p->values.empty()) {
        return Status::Error(schema::TomlWhere(path, &node) + ": parameter '" + p->key +
                             "': uniform and log_uniform ranges need method = \"random\"");
      }
      spec.parameters.push_back(*p);
    }
  }
  RATSLAM_RETURN_IF_ERROR(top.Finish());
  return spec;
}

StatusOr<Plan> MakePlan(const SweepSpec& spec) {
  Plan plan;
  plan.spec = spec;
  StatusOr<PipelineOptions> base = ParseConfig(spec.base_config_text, "base configuration");
  if (!base.ok()) return base.status();
  // Each value alone first, so that an error names the parameter's line.
  for (const Parameter& p : spec.parameters) {
    std::vector<std::string> values = p.values;
    if (values.empty()) values = {Number(p.lo, p.integer), Number(p.hi, p.integer)};
    for (const std::string& v : values) {
      StatusOr<PipelineOptions> one =
          ParseConfigOnto(OverrideText({{p.key, v}}), spec.source, *base);
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
    StatusOr<PipelineOptions> all =
        ParseConfigOnto(OverrideText(points[i]), spec.source, *base);  // base parsed once
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

StatusOr<PipelineOptions> TaskConfig(const Plan& plan, const Task& task) {
  StatusOr<PipelineOptions> base = ParseConfig(plan.spec.base_config_text, "base configuration");
  if (!base.ok()) return base.status();
  return ParseConfigOnto(OverrideText(task.overrides), plan.spec.source, *base);
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
    plan.points = j.at("points").get<int>();
    for (const json& t : j.at("tasks")) {
      Task task;
      task.index = t.at("index").get<int>();
      task.point = t.at("point").get<int>();
      task.dataset = t.at("dataset").get<int>();
      for (const json& o : t.at("overrides")) {
        task.overrides.emplace_back(o.at(0).get<std::string>(), o.at(1).get<std::string>());
      }
      if (task.index != static_cast<int>(plan.tasks.size()) || task.dataset < 0 ||
          task.dataset >= static_cast<int>(plan.spec.datasets.size())) {
        return Status::Error(path + ": task " + std::to_string(plan.tasks.size()) +
                             " is out of order or names a missing data set");
      }
      plan.tasks.push_back(task);
    }
    return plan;
  } catch (const json::exception& e) {
    return Status::Error(path + ": " + e.what());
  }
}

namespace {

struct Running {
  int index = 0;
  pid_t pid = -1;
  std::string program;
  std::chrono::steady_clock::time_point start;
};

std::string LastLine(const std::string& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  return last;
}

StatusOr<TaskOutcome> ReadOutcome(const std::string& dir, int index) {
  TaskOutcome o;
  o.index = index;
  o.status = "pending";
  const std::string path = RunFolder(dir, index) + "/status.json";
  if (!PathExists(path)) return o;
  StatusOr<std::string> text = ReadRegularFile(path, "run status", 1 << 20);
  if (!text.ok()) return text.status();
  try {
    const json j = json::parse(*text);
    o.status = j.at("status").get<std::string>();
    o.exit_code = j.at("exit_code").get<int>();
    o.wall_s = j.at("wall_s").get<double>();
    o.error = j.at("error").get<std::string>();
    o.program = j.value("program", std::string());
    o.host = j.value("host", std::string());
  } catch (const json::exception&) {
    TaskOutcome pending;  // torn or damaged: the run is repeated
    pending.index = index;
    pending.status = "pending";
    return pending;
  }
  return o;
}

// Processes other than this one with `folder` as one of their arguments (a run's --out).
std::vector<pid_t> ProcessesNaming(const std::string& folder) {
  std::vector<pid_t> found;
  std::error_code ec;
  for (fs::directory_iterator it("/proc", ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    pid_t pid = 0;
    const auto [rest, error] = std::from_chars(name.data(), name.data() + name.size(), pid);
    if (error != std::errc() || rest != name.data() + name.size() || pid <= 1 || pid == getpid()) {
      continue;
    }
    std::ifstream cmdline(it->path() / "cmdline", std::ios::binary);
    for (std::string arg; std::getline(cmdline, arg, '\0');) {
      if (arg == folder) {
        found.push_back(pid);
        break;
      }
    }
  }
  return found;
}

// Whether `pid` is a process that has not ended (a zombie has: it waits only to be reaped).
bool Alive(pid_t pid) {
  if (kill(pid, 0) != 0) return false;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(stat, line);
  const size_t paren = line.rfind(')');  // "pid (name) state ...": the name may hold spaces
  return paren == std::string::npos || paren + 2 >= line.size() || line[paren + 2] != 'Z';
}

// A run left behind by a killed sweep runner is still writing into its folder: ended before the
// folder is reused. It is found by its command line, which names the folder, not by the pid file
// the runner writes after starting it: a runner killed between the two leaves no pid file, and
// the orphan would otherwise write its outputs into the next attempt's folder (seen in CI: the
// next attempt refused to overwrite them).
void EndOrphan(const std::string& folder) {
  if (!PathExists(folder)) return;  // never started
  const std::vector<pid_t> orphans = ProcessesNaming(folder);
  for (pid_t pid : orphans) {
    kill(-pid, SIGKILL);  // its process group (runs start in their own)
    kill(pid, SIGKILL);
  }
  for (pid_t pid : orphans) {
    for (int i = 0; i < 500 && Alive(pid); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
}

// Starts task `index` as `program replay ...` in its own process group.
StatusOr<Running> Start(const Plan& plan, const std::string& dir, int index,
                        const std::string& program) {
  const Task& task = plan.tasks.at(index);
  const std::string folder = RunFolder(dir, index);
  EndOrphan(folder);
  std::error_code ec;
  fs::remove_all(folder, ec);  // a run that never ended starts again from nothing
  fs::create_directories(folder, ec);
  if (ec) return Status::Error(folder + ": cannot create folder: " + ec.message());
  StatusOr<PipelineOptions> config = TaskConfig(plan, task);
  if (!config.ok()) return config.status();
  const std::string config_path = folder + "/config.toml";
  RATSLAM_RETURN_IF_ERROR(
      WriteFileAtomically(config_path, PrintConfig(*config), /*flush_to_disk=*/false));
  std::vector<std::string> args = {program, plan.spec.command, "--config", config_path};
  const std::vector<std::string>& data = plan.spec.datasets[task.dataset];
  if (plan.spec.command == "evaluate") {
    args.insert(args.end(), {"--map", data.front(), "--query", data.back()});
  } else {
    for (const std::string& d : data) {
      args.push_back("--data");
      args.push_back(d);
    }
  }
  args.insert(args.end(), {"--out", folder, "--quiet"});
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, (folder + "/stdout.txt").c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, (folder + "/stderr.txt").c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);  // its own group: a terminal's Ctrl-C is ours
  // The run ends with this runner, even one killed with SIGKILL (ratslam asks the kernel for a
  // signal when its parent dies; see kEndWithParentVariable).
  std::vector<std::string> environment;
  const std::string marker = std::string(kEndWithParentVariable) + "=";
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::string_view(*e).substr(0, marker.size()) != marker) environment.emplace_back(*e);
  }
  environment.push_back(marker + std::to_string(::getpid()));
  std::vector<char*> envp;
  for (std::string& e : environment) envp.push_back(e.data());
  envp.push_back(nullptr);
  Running r;
  r.index = index;
  r.program = program;
  r.start = std::chrono::steady_clock::now();
  const int rc =
      posix_spawn(&r.pid, program.c_str(), &actions, &attributes, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (rc != 0) return Status::Error(program + ": cannot start: " + std::strerror(rc));
  // Who writes into the folder (for people; EndOrphan finds a left-behind run by its command
  // line, which also covers a runner killed before this line).
  std::ofstream(folder + "/pid") << r.pid << "\n";
  return r;
}

// Records how a run ended; with keep = small, removes all but the small outputs.
Status Finish(const Plan& plan, const std::string& dir, const Running& r, int wait_status,
              bool timed_out, TaskOutcome* outcome) {
  const std::string folder = RunFolder(dir, r.index);
  outcome->index = r.index;
  outcome->wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - r.start).count();
  outcome->exit_code =
      WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : 128 + WTERMSIG(wait_status);
  outcome->status = timed_out ? "timeout" : outcome->exit_code == 0 ? "ok" : "failed";
  outcome->error = outcome->status == "ok" ? "" : LastLine(folder + "/stderr.txt");
  if (timed_out) {
    outcome->error = "no result after " + schema::TomlNumber(plan.spec.timeout_s) + " s";
  } else if (!WIFEXITED(wait_status) && outcome->error.empty()) {
    outcome->error = std::string("killed by signal ") + strsignal(WTERMSIG(wait_status));
  }
  if (!plan.spec.keep_all && outcome->status == "ok") {
    static const std::set<std::string> kKept = {"summary.json", "evaluation.json",
                                                "config.toml",  "trajectory_tum.txt",
                                                "stderr.txt",   "pid"};
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec)) {
      if (!kKept.count(entry.path().filename().string())) fs::remove_all(entry.path(), ec);
    }
  }
  char host[256] = "";
  gethostname(host, sizeof host - 1);
  outcome->program = r.program;
  outcome->host = host;
  const json status = {{"status", outcome->status},   {"exit_code", outcome->exit_code},
                       {"wall_s", outcome->wall_s},   {"error", outcome->error},
                       {"program", outcome->program}, {"host", outcome->host}};
  // Not flushed to disk (a flush per run cost more than the run itself on short replays): a
  // status torn by a power cut reads as pending and the run is repeated, never lost.
  return WriteFileAtomically(folder + "/status.json", status.dump(1) + "\n",
                             /*flush_to_disk=*/false);
}

// True when the run was ended by a stop request (it runs again next time, unrecorded).
bool Interrupted(int wait_status) {
  if (WIFSIGNALED(wait_status)) {
    const int s = WTERMSIG(wait_status);
    return s == SIGINT || s == SIGTERM;
  }
  return WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 130;
}

}  // namespace

StatusOr<std::vector<TaskOutcome>> ReadOutcomes(const std::string& dir) {
  StatusOr<Plan> plan = ReadPlan(dir);
  if (!plan.ok()) return plan.status();
  std::vector<TaskOutcome> out;
  for (const Task& t : plan->tasks) {
    StatusOr<TaskOutcome> o = ReadOutcome(dir, t.index);
    if (!o.ok()) return o.status();
    out.push_back(*o);
  }
  return out;
}

// The objective of a run, when it succeeded and its summary has it (defined with Collect).
std::optional<double> RunObjective(const Plan& plan, const std::string& dir, int index);

namespace {

// Runs the tasks of `queue` (all pending), options.jobs at a time, adding to `report`; `total`
// only feeds the progress line.
Status RunQueue(const Plan& plan, const std::string& dir, const std::vector<int>& queue,
                const RunOptions& options, int total, RunReport* report) {
  std::vector<Running> running;
  size_t next = 0;
  auto stopping = [&] { return options.stop_requested && options.stop_requested->load(); };
  auto show = [&] {
    if (!options.progress) return;
    // "sweep, N failed": the failures are a detail of the phase (see apps/progress.h).
    options.progress->Update({"sweep, " + std::to_string(report->failed) + " failed",
                              static_cast<uint64_t>(report->done + report->skipped),
                              static_cast<uint64_t>(total)});
  };
  Status error;
  while (error.ok() && ((next < queue.size() && !stopping()) || !running.empty())) {
    while (error.ok() && !stopping() && next < queue.size() &&
           static_cast<int>(running.size()) < std::max(1, options.jobs)) {
      StatusOr<Running> r = Start(plan, dir, queue[next++], options.program);
      if (!r.ok()) {
        error = r.status();
        break;
      }
      running.push_back(*r);
      show();
    }
    bool changed = false;
    for (size_t i = 0; i < running.size();) {
      Running& r = running[i];
      int wait_status = 0;
      const pid_t done = waitpid(r.pid, &wait_status, WNOHANG);
      const double age =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - r.start).count();
      const bool timed_out = plan.spec.timeout_s > 0.0 && age > plan.spec.timeout_s;
      if (done == 0 && (timed_out || stopping())) {
        kill(-r.pid, timed_out ? SIGKILL : SIGTERM);
        waitpid(r.pid, &wait_status, 0);
      } else if (done == 0) {
        ++i;
        continue;
      }
      if (!timed_out && (stopping() || Interrupted(wait_status))) {
        ++report->pending;  // unrecorded: it runs again next time
      } else {
        TaskOutcome outcome;
        Status s = Finish(plan, dir, r, wait_status, timed_out, &outcome);
        if (!s.ok() && error.ok()) error = s;
        ++report->done;
        if (outcome.status != "ok") ++report->failed;
      }
      running.erase(running.begin() + static_cast<std::ptrdiff_t>(i));
      changed = true;
    }
    if (changed) show();
    if (!running.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  for (const Running& r : running) {  // after an error: end what is still running
    kill(-r.pid, SIGTERM);
    int wait_status = 0;
    waitpid(r.pid, &wait_status, 0);
    ++report->pending;
  }
  report->pending += static_cast<int>(queue.size() - next);
  return error;
}

// Successive halving (Jamieson and Talwalkar 2016) over data sets: every point runs on a few
// data sets, the best 1/rate of the points go on to rate times as many, until the survivors
// have run on all of them. Data sets enter in a seeded random order. Deterministic given the
// runs' results, so a resumed sweep makes the same decisions. Writes DIR/search.json.
Status RunHalving(const Plan& plan, const std::string& dir, const RunOptions& options,
                  RunReport* report) {
  const SweepSpec& spec = plan.spec;
  const int datasets = static_cast<int>(spec.datasets.size());
  const double rate = spec.halving_rate;
  std::vector<int> order(datasets);
  for (int d = 0; d < datasets; ++d) order[d] = d;
  Random random(spec.seed ^ 0x5eedULL);
  for (int i = datasets - 1; i > 0; --i) {
    std::swap(order[i], order[random.NextU64() % static_cast<uint64_t>(i + 1)]);
  }
  // Halvings: as many as the points need, but no more than the data sets allow.
  const int halvings = std::max(
      0, std::min(static_cast<int>(
                      std::ceil(std::log(std::max(1, plan.points)) / std::log(rate) - 1e-9)),
                  static_cast<int>(std::floor(std::log(datasets) / std::log(rate) + 1e-9))));
  int used = std::max(1, static_cast<int>(std::ceil(datasets / std::pow(rate, halvings))));
  std::vector<int> survivors(plan.points);
  for (int p = 0; p < plan.points; ++p) survivors[p] = p;
  std::map<std::pair<int, int>, int> task_of;  // (point, data set) -> task
  for (const Task& t : plan.tasks) task_of[{t.point, t.dataset}] = t.index;
  const bool minimize = spec.goal == "minimize";
  json rounds = json::array();
  int planned_runs = 0;
  while (true) {
    std::vector<int> queue;
    for (int p : survivors) {
      for (int k = 0; k < used; ++k) {
        const int index = task_of.at({p, order[k]});
        StatusOr<TaskOutcome> o = ReadOutcome(dir, index);
        if (!o.ok()) return o.status();
        if (o->status == "pending") queue.push_back(index);
      }
    }
    std::sort(queue.begin(), queue.end());
    planned_runs += static_cast<int>(queue.size());
    RATSLAM_RETURN_IF_ERROR(
        RunQueue(plan, dir, queue, options, static_cast<int>(plan.tasks.size()), report));
    if (report->pending > 0) return Status::Ok();  // stopped: the next run resumes this round
    // Each survivor's objective over the data sets used so far; a failed run ranks it last.
    std::vector<std::pair<double, int>> ranked;
    for (int p : survivors) {
      double sum = 0.0, worst = minimize ? -1e300 : 1e300;
      bool failed = false;
      for (int k = 0; k < used; ++k) {
        const std::optional<double> v = RunObjective(plan, dir, task_of.at({p, order[k]}));
        if (!v) {
          failed = true;
          break;
        }
        sum += *v;
        worst = minimize ? std::max(worst, *v) : std::min(worst, *v);
      }
      double value = spec.aggregate == "mean" ? sum / used : worst;
      if (failed) value = minimize ? 1e300 : -1e300;
      ranked.emplace_back(minimize ? value : -value, p);  // ascending is best first
    }
    std::sort(ranked.begin(), ranked.end());
    json round = {{"datasets", used}, {"points", survivors}, {"runs", queue.size()}};
    if (used >= datasets) {
      rounds.push_back(round);
      break;
    }
    const size_t keep =
        std::max<size_t>(1, static_cast<size_t>(std::ceil(survivors.size() / rate)));
    survivors.clear();
    for (size_t i = 0; i < keep && i < ranked.size(); ++i) survivors.push_back(ranked[i].second);
    std::sort(survivors.begin(), survivors.end());
    round["kept"] = survivors;
    rounds.push_back(round);
    used = std::min(datasets, static_cast<int>(std::ceil(used * rate)));
  }
  const json search = {{"search", "halving"},           {"rate", rate},
                       {"dataset_order", order},        {"rounds", rounds},
                       {"finalists", survivors},        {"runs", planned_runs},
                       {"grid_runs", plan.tasks.size()}};
  return WriteFileAtomically((fs::path(dir) / "search.json").string(), search.dump(1) + "\n");
}

}  // namespace

StatusOr<RunReport> RunSweep(const std::string& dir, const RunOptions& options) {
  StatusOr<Plan> plan = ReadPlan(dir);
  if (!plan.ok()) return plan.status();
  // Two runners on one folder would start every task twice and end each other's runs.
  StatusOr<FolderLock> lock = FolderLock::Acquire(dir, "ratslam sweep run");
  if (!lock.ok()) return lock.status();
  RunReport report;
  Status status;
  if (plan->spec.search == "halving") {
    for (const Task& t : plan->tasks) {
      StatusOr<TaskOutcome> o = ReadOutcome(dir, t.index);
      if (!o.ok()) return o.status();
      if (o->status != "pending") ++report.skipped;
      if (o->status != "pending" && o->status != "ok") ++report.failed;
    }
    status = RunHalving(*plan, dir, options, &report);
  } else {
    std::vector<int> queue;
    for (const Task& t : plan->tasks) {
      StatusOr<TaskOutcome> o = ReadOutcome(dir, t.index);
      if (!o.ok()) return o.status();
      if (o->status == "pending") {
        queue.push_back(t.index);
      } else {
        ++report.skipped;
        if (o->status != "ok") ++report.failed;
      }
    }
    status = RunQueue(*plan, dir, queue, options, static_cast<int>(plan->tasks.size()), &report);
  }
  if (options.progress) options.progress->Finish();
  if (!status.ok()) return status;
  return report;
}

StatusOr<TaskOutcome> RunTask(const std::string& dir, int index, const std::string& program) {
  StatusOr<Plan> plan = ReadPlan(dir);
  if (!plan.ok()) return plan.status();
  if (index < 0 || index >= static_cast<int>(plan->tasks.size())) {
    return Status::Error(dir + ": no task " + std::to_string(index) + " (the plan has " +
                         std::to_string(plan->tasks.size()) + ")");
  }
  StatusOr<TaskOutcome> recorded = ReadOutcome(dir, index);
  if (!recorded.ok() || recorded->status != "pending") return recorded;
  // The same runner as a whole sweep's, with a queue of one: timeout, interruption and the
  // recorded outcome behave alike.
  RunOptions options;
  options.program = program;
  RunReport report;
  RATSLAM_RETURN_IF_ERROR(RunQueue(*plan, dir, {index}, options, 1, &report));
  return ReadOutcome(dir, index);
}

StatusOr<std::vector<TaskOutcome>> RunTasks(const std::string& dir, int first, int count,
                                            const std::string& program) {
  StatusOr<Plan> plan = ReadPlan(dir);
  if (!plan.ok()) return plan.status();
  const int total = static_cast<int>(plan->tasks.size());
  if (first < 0 || first >= total || count < 1) {
    return Status::Error(dir + ": no task " + std::to_string(first) + " (the plan has " +
                         std::to_string(total) + ")");
  }
  std::vector<TaskOutcome> outcomes;
  for (int i = first; i < std::min(total, first + count); ++i) {
    StatusOr<TaskOutcome> o = RunTask(dir, i, program);
    if (!o.ok()) return o.status();
    outcomes.push_back(*o);
  }
  return outcomes;
}

namespace {

std::string ShellQuoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// "0-3,7,9-10" from ascending numbers.
std::string Ranges(const std::vector<int>& numbers) {
  std::string out;
  for (size_t i = 0; i < numbers.size();) {
    size_t j = i;
    while (j + 1 < numbers.size() && numbers[j + 1] == numbers[j] + 1) ++j;
    out += (out.empty() ? "" : ",") + std::to_string(numbers[i]);
    if (j > i) out += "-" + std::to_string(numbers[j]);
    i = j + 1;
  }
  return out;
}

// Runs `argv` (found on PATH) and returns what it wrote to stdout; fails on a non-zero exit.
StatusOr<std::string> Capture(const std::vector<std::string>& args) {
  int fds[2];
  if (pipe(fds) != 0) return Status::Error("pipe: " + std::string(std::strerror(errno)));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  if (rc != 0) {
    close(fds[0]);
    return Status::Error(args[0] + ": cannot start: " + std::strerror(rc));
  }
  std::string out;
  char buffer[4096];
  ssize_t n;
  while ((n = read(fds[0], buffer, sizeof buffer)) > 0) out.append(buffer, static_cast<size_t>(n));
  close(fds[0]);
  int wait_status = 0;
  waitpid(pid, &wait_status, 0);
  if (!WIFEXITED(wait_status) || WEXITSTATUS(wait_status) != 0) {
    return Status::Error(args[0] + " failed (exit " +
                         std::to_string(WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1) +
                         ")");
  }
  return out;
}

}  // namespace

StatusOr<SlurmJobs> WriteSlurmScripts(const std::string& dir, const SlurmOptions& options) {
  StatusOr<std::vector<TaskOutcome>> outcomes = ReadOutcomes(dir);
  if (!outcomes.ok()) return outcomes.status();
  if (options.chunk < 1) return Status::Error("chunk must be at least 1");
  std::vector<int> elements;  // array elements with a pending task
  for (const TaskOutcome& o : *outcomes) {
    const int element = o.index / options.chunk;
    if (o.status == "pending" && (elements.empty() || elements.back() != element)) {
      elements.push_back(element);
    }
  }
  if (elements.empty()) return Status::Error(dir + ": no pending task");
  const std::string folder = fs::absolute(dir).lexically_normal().string();
  std::error_code ec;
  fs::create_directories(fs::path(folder) / "slurm" / "logs", ec);
  if (ec) return Status::Error(folder + "/slurm: cannot create folder: " + ec.message());
  SlurmJobs jobs;
  jobs.array_spec = Ranges(elements);
  if (options.max_parallel > 0) jobs.array_spec += "%" + std::to_string(options.max_parallel);
  std::string common;
  if (!options.partition.empty()) common += "#SBATCH --partition=" + options.partition + "\n";
  if (!options.time.empty()) common += "#SBATCH --time=" + options.time + "\n";
  if (!options.mem.empty()) common += "#SBATCH --mem=" + options.mem + "\n";
  for (const std::string& a : options.sbatch_args) {
    if (a.find('\n') != std::string::npos) {
      return Status::Error("sbatch argument with a line break");
    }
    common += "#SBATCH " + a + "\n";
  }
  const std::string logs = folder + "/slurm/logs/";
  const std::string array =
      "#!/bin/sh\n#SBATCH --job-name=ratslam-sweep\n#SBATCH --array=" + jobs.array_spec +
      "\n#SBATCH --output=" + logs + "task-%a.out\n" + common + "exec " +
      ShellQuoted(options.program) + " sweep task " + ShellQuoted(folder) + " --chunk " +
      std::to_string(options.chunk) + "\n";
  const std::string collect =
      "#!/bin/sh\n#SBATCH --job-name=ratslam-sweep-collect\n#SBATCH "
      "--output=" +
      logs + "collect.out\n" + common + "exec " + ShellQuoted(options.program) + " sweep collect " +
      ShellQuoted(folder) + "\n";
  jobs.array_script = folder + "/slurm/array.sh";
  jobs.collect_script = folder + "/slurm/collect.sh";
  RATSLAM_RETURN_IF_ERROR(
      WriteFilesAtomically({{jobs.array_script, array}, {jobs.collect_script, collect}}));
  return jobs;
}

Status SubmitSlurm(SlurmJobs* jobs) {
  auto job_id = [](const std::string& parsable) {
    std::string id = parsable.substr(0, parsable.find_first_of(";\n"));
    return id;
  };
  StatusOr<std::string> array = Capture({"sbatch", "--parsable", jobs->array_script});
  if (!array.ok()) return array.status();
  jobs->array_job = job_id(*array);
  if (jobs->array_job.empty()) return Status::Error("sbatch printed no job id");
  StatusOr<std::string> collect = Capture(
      {"sbatch", "--parsable", "--dependency=afterany:" + jobs->array_job, jobs->collect_script});
  if (!collect.ok()) return collect.status();
  jobs->collect_job = job_id(*collect);
  return Status::Ok();
}

namespace {

// The value at a dotted path of a JSON object ("match_rate_within_m.5"), if it is a number.
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
  if (!node->is_number()) return std::nullopt;
  return node->get<double>();
}

// The objective (a metric or an expression of metrics) of one run's summary.
std::optional<double> ObjectiveOf(const json& summary, const std::string& objective) {
  StatusOr<Expression> e = Expression::Parse(objective);
  if (!e.ok()) return std::nullopt;
  return e->Evaluate([&](const std::string& name) { return Metric(summary, name); });
}

}  // namespace

std::optional<double> RunObjective(const Plan& plan, const std::string& dir, int index) {
  StatusOr<TaskOutcome> o = ReadOutcome(dir, index);
  if (!o.ok() || o->status != "ok") return std::nullopt;
  StatusOr<std::string> text = ReadRegularFile(RunFolder(dir, index) + "/" + MetricsFile(plan.spec),
                                               "run metrics", size_t{1} << 26);
  if (!text.ok()) return std::nullopt;
  return ObjectiveOf(json::parse(*text, nullptr, false), plan.spec.objective);
}

namespace {

std::string Format(std::optional<double> v) { return v ? schema::TomlNumber(*v) : std::string(); }

}  // namespace

StatusOr<CollectReport> Collect(const std::string& dir) {
  StatusOr<Plan> plan = ReadPlan(dir);
  if (!plan.ok()) return plan.status();
  const SweepSpec& spec = plan->spec;
  CollectReport report;
  // After a finished successive halving, a task that never ran belongs to an eliminated point.
  const bool halving_done = PathExists(fs::path(dir) / "search.json");
  // Data sets by number and by their paths (a number alone sent readers to plan.json).
  std::string csv = "index,point,dataset,data,status,exit_code,wall_s";
  for (const Parameter& p : spec.parameters) {
    csv += ',';
    csv += CsvField(p.key);
  }
  for (const std::string& m : spec.metrics) {
    csv += ',';
    csv += CsvField(m);
  }
  csv += ",error\n";
  json runs = json::array();
  // Per point: the objective of each data set (nullopt when its run did not succeed).
  std::vector<std::vector<std::optional<double>>> objectives(plan->points);
  std::vector<std::pair<double, int>> wall(plan->points);  // sum of wall times, runs
  for (const Task& t : plan->tasks) {
    StatusOr<TaskOutcome> o = ReadOutcome(dir, t.index);
    if (!o.ok()) return o.status();
    json summary;
    if (o->status == "ok") {
      ++report.ok;
      StatusOr<std::string> text = ReadRegularFile(
          RunFolder(dir, t.index) + "/" + MetricsFile(spec), "run metrics", size_t{1} << 26);
      if (text.ok()) summary = json::parse(*text, nullptr, false);
    } else if (o->status == "pending" && halving_done) {
      o->status = "eliminated";
      ++report.eliminated;
    } else if (o->status == "pending") {
      ++report.pending;
    } else {
      ++report.failed;
    }
    std::string data;
    for (const std::string& d : spec.datasets[t.dataset]) data += (data.empty() ? "" : ";") + d;
    csv += std::to_string(t.index) + "," + std::to_string(t.point) + "," +
           std::to_string(t.dataset) + "," + CsvField(data) + "," + o->status + "," +
           std::to_string(o->exit_code) + "," + schema::TomlNumber(o->wall_s);
    json parameters = json::object();
    for (const auto& [key, value] : t.overrides) {
      csv += ',';
      csv += CsvField(value);
      parameters[key] = value;
    }
    json metrics = json::object();
    for (const std::string& m : spec.metrics) {
      const std::optional<double> v = o->status == "ok" ? Metric(summary, m) : std::nullopt;
      csv += ',';
      csv += Format(v);
      metrics[m] = v ? json(*v) : json(nullptr);
    }
    csv += ',';
    csv += CsvField(o->error) + "\n";
    objectives[t.point].push_back(o->status == "ok" ? ObjectiveOf(summary, spec.objective)
                                                    : std::nullopt);
    if (o->status == "ok" && !objectives[t.point].back()) ++report.ok_without_objective;
    if (o->status == "ok" || o->status == "failed" || o->status == "timeout") {
      wall[t.point].first += o->wall_s;
      ++wall[t.point].second;
    }
    runs.push_back(
        {{"index", t.index},
         {"point", t.point},
         {"data", spec.datasets[t.dataset]},
         {"parameters", parameters},
         {"metrics", metrics},
         {"status", o->status},
         {"exit_code", o->exit_code},
         {"wall_s", o->wall_s},
         {"error", o->error},
         {"program", o->program},
         {"host", o->host},
         {"config_fingerprint", summary.is_object() && summary.contains("config_fingerprint")
                                    ? summary["config_fingerprint"]
                                    : json()},
         {"folder", RunFolder(dir, t.index)}});
  }
  const bool minimize = spec.goal == "minimize";
  std::string points_csv = "point";
  for (const Parameter& p : spec.parameters) {
    points_csv += ',';
    points_csv += CsvField(p.key);
  }
  points_csv += ",objective,runs_ok\n";
  std::map<int, std::vector<std::pair<std::string, std::string>>> overrides;
  for (const Task& t : plan->tasks) overrides[t.point] = t.overrides;
  for (int p = 0; p < plan->points; ++p) {
    double aggregate = 0.0;
    int ok = 0;
    bool complete = !objectives[p].empty();
    for (const std::optional<double>& v : objectives[p]) {
      if (!v) {
        complete = false;
        continue;
      }
      if (ok == 0 || spec.aggregate == "mean") {
        aggregate = ok == 0 ? *v : aggregate + *v;
      } else {
        aggregate = minimize ? std::max(aggregate, *v) : std::min(aggregate, *v);
      }
      ++ok;
    }
    if (ok > 0 && spec.aggregate == "mean") aggregate /= ok;
    // A point with a failed or missing run is not ranked.
    const std::optional<double> ranked = complete ? std::optional<double>(aggregate) : std::nullopt;
    report.points.push_back(
        {p, overrides[p], ranked, wall[p].second ? wall[p].first / wall[p].second : 0.0, ok});
    points_csv += std::to_string(p);
    for (const auto& [key, value] : overrides[p]) {
      points_csv += ',';
      points_csv += CsvField(value);
    }
    points_csv += ',';
    points_csv += Format(ranked) + "," + std::to_string(ok) + "\n";
    if (complete && (!report.best_point || (minimize ? aggregate < report.best_objective
                                                     : aggregate > report.best_objective))) {
      report.best_point = p;
      report.best_objective = aggregate;
    }
  }
  const json results = {
      {"sweep", spec.source},
      {"objective", spec.objective},
      {"aggregate", spec.aggregate},
      {"goal", spec.goal},
      {"runs", runs},
      {"ok", report.ok},
      {"failed", report.failed},
      {"pending", report.pending},
      {"best_point", report.best_point ? json(*report.best_point) : json()},
      {"best_objective", report.best_point ? json(report.best_objective) : json()}};
  std::vector<std::pair<std::string, std::string>> files = {
      {(fs::path(dir) / "results.csv").string(), csv},
      {(fs::path(dir) / "points.csv").string(), points_csv},
      {(fs::path(dir) / "results.json").string(), results.dump(1) + "\n"}};
  if (report.best_point) {
    const Task* best = nullptr;
    for (const Task& t : plan->tasks) {
      if (t.point == *report.best_point) best = &t;
    }
    StatusOr<PipelineOptions> config = TaskConfig(*plan, *best);
    if (!config.ok()) return config.status();
    std::string header = "# Best point " + std::to_string(*report.best_point) + " of " +
                         spec.source + ": " + spec.aggregate + " " + spec.objective + " = " +
                         schema::TomlNumber(report.best_objective) + " over " +
                         std::to_string(spec.datasets.size()) + " data set(s)\n";
    for (const auto& [key, value] : best->overrides) header += "#   " + key + " = " + value + "\n";
    files.push_back({(fs::path(dir) / "best.toml").string(), header + "\n" + PrintConfig(*config)});
  }
  RATSLAM_RETURN_IF_ERROR(WriteFilesAtomically(files));
  return report;
}

}  // namespace ratslam::sweep
