// One TOML binder for every declared field list (common/schema.h): configs, world files and the
// data-set manifest read and print through it, so each has the same types, the same range checks
// and the same error style, "file:line: section.key: reason". Header-only; users link
// tomlplusplus. Types beyond the built-in ones get a `TomlCodec` specialisation.
#ifndef RATSLAM_COMMON_TOML_BINDER_H_
#define RATSLAM_COMMON_TOML_BINDER_H_

#include <toml++/toml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/number_text.h"
#include "common/schema.h"
#include "common/status.h"
#include "common/toml_string.h"

namespace ratslam::schema {

// Reads a T from a TOML node (an error message, or "" when it worked) and writes it as TOML.
template <typename T>
struct TomlCodec;

// Numbers: shortest text that reads back to the same double, always with a '.' or exponent.
inline std::string TomlNumber(double value) {
  std::string text = ShortestNumber(value);
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

// A number node as a double: integers are taken as numbers; NaN and infinities are refused.
inline bool TomlToDouble(const toml::node& node, double* out) {
  if (const auto* f = node.as_floating_point()) {
    if (!std::isfinite(f->get())) return false;
    *out = f->get();
    return true;
  }
  if (const auto* i = node.as_integer()) {
    *out = static_cast<double>(i->get());
    return true;
  }
  return false;
}

template <>
struct TomlCodec<double> {
  static std::string Read(const toml::node& node, double* out) {
    if (node.as_floating_point() && !std::isfinite(node.as_floating_point()->get())) {
      return "must be a finite number";
    }
    return TomlToDouble(node, out) ? "" : "expected a number";
  }
  static std::string Write(double v) { return TomlNumber(v); }
};

template <>
struct TomlCodec<int> {
  static std::string Read(const toml::node& node, int* out) {
    const auto* v = node.as_integer();
    if (!v) return "expected an integer";
    if (v->get() < std::numeric_limits<int>::min() || v->get() > std::numeric_limits<int>::max()) {
      return "integer out of range";
    }
    *out = static_cast<int>(v->get());
    return "";
  }
  static std::string Write(int v) { return std::to_string(v); }
};

template <>
struct TomlCodec<uint64_t> {
  static std::string Read(const toml::node& node, uint64_t* out) {
    const auto* v = node.as_integer();
    if (!v) return "expected an integer";
    if (v->get() < 0) return "must not be negative";
    *out = static_cast<uint64_t>(v->get());
    return "";
  }
  static std::string Write(uint64_t v) { return std::to_string(v); }
};

template <>
struct TomlCodec<bool> {
  static std::string Read(const toml::node& node, bool* out) {
    const auto* b = node.as_boolean();
    if (!b) return "expected true or false";
    *out = b->get();
    return "";
  }
  static std::string Write(bool v) { return v ? "true" : "false"; }
};

template <>
struct TomlCodec<std::string> {
  static std::string Read(const toml::node& node, std::string* out) {
    const auto* s = node.as_string();
    if (!s) return "expected a string";
    *out = s->get();
    return "";
  }
  static std::string Write(const std::string& v) { return TomlQuoted(v); }
};

template <typename T>
struct TomlCodec<std::vector<T>> {
  static std::string Read(const toml::node& node, std::vector<T>* out) {
    const auto* a = node.as_array();
    if (!a) return "expected a list";
    std::vector<T> values;
    for (const auto& element : *a) {
      T value{};
      const std::string error = TomlCodec<T>::Read(element, &value);
      if (!error.empty()) return "element " + std::to_string(values.size()) + ": " + error;
      values.push_back(value);
    }
    *out = std::move(values);
    return "";
  }
  static std::string Write(const std::vector<T>& v) {
    std::string s = "[";
    for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + TomlCodec<T>::Write(v[i]);
    return s + "]";
  }
};

// An enum named in configs by text: `Parse` is its FromString, ToString found by lookup.
template <typename E, StatusOr<E> (*Parse)(const std::string&)>
struct EnumCodec {
  static std::string Read(const toml::node& node, E* out) {
    const auto* s = node.as_string();
    if (!s) return "expected a string";
    StatusOr<E> value = Parse(s->get());
    if (!value.ok()) return value.status().message();
    *out = *value;
    return "";
  }
  static std::string Write(E v) { return TomlQuoted(ToString(v)); }
};

// The line of a node as "source:line" ("source:?" without a node).
inline std::string TomlWhere(const std::string& source, const toml::node* node) {
  return source + ":" + (node ? std::to_string(node->source().begin.line) : std::string("?"));
}

// Edit distance, for "did you mean" suggestions.
inline size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1] ? 1 : 0)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// " (did you mean 'x'?)" for the closest known name within a third of its length, else "".
inline std::string DidYouMean(const std::string& name, const std::set<std::string>& known) {
  std::string best;
  size_t best_distance = std::numeric_limits<size_t>::max();
  for (const std::string& k : known) {
    const size_t d = EditDistance(name, k);
    if (d < best_distance) {
      best_distance = d;
      best = k;
    }
  }
  if (best.empty() || best_distance > std::max<size_t>(1, best.size() / 3)) return "";
  return " (did you mean '" + best + "'?)";
}

// Reads declared fields from one TOML table. `where` names the table in messages ("[camera]",
// "the manifest"); `key_prefix` goes before a key in an error ("camera." gives
// "file:3: camera.shift_px: must be ..."). The first error wins; later calls do nothing.
class TableBinder {
 public:
  TableBinder(const toml::table& table, std::string where, std::string key_prefix,
              std::string source)
      : table_(table),
        where_(std::move(where)),
        key_prefix_(std::move(key_prefix)),
        source_(std::move(source)) {}

  template <typename T>
  void operator()(const char* key, T& field, const char* /*doc*/, const Rule& rule) {
    const toml::node* node = Take(key);
    if (!node || !status_.ok()) return;
    T value = field;
    std::string error = TomlCodec<T>::Read(*node, &value);
    if (error.empty()) error = Violation(value, rule);
    if (!error.empty()) return Fail(node, key, error);
    field = std::move(value);
  }

  // The node under `key` (nullptr when absent), marked as known; for fields read by hand.
  const toml::node* Take(const std::string& key) {
    known_.insert(key);
    return table_.get(key);
  }
  // The sub-table `key`, or nullptr (an error when it is there but not a table).
  const toml::table* Table(const std::string& key) {
    const toml::node* node = Take(key);
    if (!node) return nullptr;
    const auto* t = node->as_table();
    if (!t) Fail(node, key, "expected a table");
    return t;
  }
  // The array of tables `key` ([[key]]); empty when absent.
  std::vector<const toml::table*> Tables(const std::string& key) {
    std::vector<const toml::table*> out;
    const toml::node* node = Take(key);
    if (!node) return out;
    const auto* a = node->as_array();
    if (!a) {
      Fail(node, key, "expected [[" + key + "]] tables");
      return out;
    }
    for (const auto& element : *a) {
      if (const auto* t = element.as_table()) {
        out.push_back(t);
      } else {
        Fail(&element, key, "expected [[" + key + "]] tables");
      }
    }
    return out;
  }

  void Fail(const toml::node* node, const std::string& key, const std::string& message) {
    if (!status_.ok()) return;
    status_ = Status::Error(TomlWhere(source_, node) + ": " + key_prefix_ + key + ": " + message);
  }
  // An error at `node` in this table's words, for checks between fields.
  void FailAt(const toml::node* node, const std::string& message) {
    if (status_.ok()) status_ = Status::Error(TomlWhere(source_, node) + ": " + message);
  }

  // The first error, else an error for the first key that no field asked for.
  Status Finish() {
    if (!status_.ok()) return status_;
    for (const auto& [key, node] : table_) {
      const std::string name(key.str());
      if (known_.count(name)) continue;
      return Status::Error(TomlWhere(source_, &node) + ": unknown key '" + name + "' in " + where_ +
                           DidYouMean(name, known_));
    }
    return Status::Ok();
  }
  const Status& status() const { return status_; }
  const std::set<std::string>& known() const { return known_; }

 private:
  const toml::table& table_;
  std::string where_;
  std::string key_prefix_;
  std::string source_;
  std::set<std::string> known_;
  Status status_;
};

// Writes declared fields as "key = value" lines; with `comments`, each after its documentation
// line ("# doc (unit; range)").
class TablePrinter {
 public:
  TablePrinter(std::ostringstream& out, bool comments) : out_(out), comments_(comments) {}
  template <typename T>
  void operator()(const char* key, const T& field, const char* doc, const Rule& rule) {
    if (comments_ && doc && *doc) {
      const std::string described = DescribeRule(rule);
      out_ << "# " << doc << (described.empty() ? "" : " " + described) << "\n";
    }
    out_ << key << " = " << TomlCodec<T>::Write(field) << "\n";
  }

 private:
  std::ostringstream& out_;
  bool comments_;
};

// Parses TOML text, turning a syntax error into "source:line: reason".
inline StatusOr<toml::table> ParseToml(const std::string& text, const std::string& source) {
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    return Status::Error(source + ":" + std::to_string(e.source().begin.line) + ": " +
                         std::string(e.description()));
  }
}

}  // namespace ratslam::schema

#endif  // RATSLAM_COMMON_TOML_BINDER_H_
