// The declarative part of every configured struct: each field is listed once, as
//   v(key, member, doc, Unit("m").Positive())
// in the struct's `VisitFields`, and that list drives reading (common/toml_binder.h), printing,
// the fingerprint, the documentation check and the range checks below. A struct's `IsValid`
// calls `CheckFields` and adds only the relations between fields that a rule cannot say.
#ifndef RATSLAM_COMMON_SCHEMA_H_
#define RATSLAM_COMMON_SCHEMA_H_

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

namespace ratslam::schema {

// What a field's values may be. Numbers (and each number of a list) must be finite and within
// [lo, hi] (each end open or closed); the flags add what a range cannot say.
struct Rule {
  const char* unit = "";  // for the documentation: "m", "s", "dBm", "cells", ...
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;
  bool odd = false;            // integers
  bool not_empty = false;      // strings and lists
  bool increasing = false;     // lists of numbers: each at least the one before
  bool relative_path = false;  // strings: a relative path that cannot leave its folder

  constexpr Rule AtLeast(double v) const { return Lower(v, false); }
  constexpr Rule Above(double v) const { return Lower(v, true); }
  constexpr Rule AtMost(double v) const { return Upper(v, false); }
  constexpr Rule Below(double v) const { return Upper(v, true); }
  constexpr Rule Positive() const { return Above(0.0); }
  constexpr Rule NonNegative() const { return AtLeast(0.0); }
  constexpr Rule Within(double a, double b) const { return AtLeast(a).AtMost(b); }
  constexpr Rule Odd() const { return With(&Rule::odd); }
  constexpr Rule NotEmpty() const { return With(&Rule::not_empty); }
  constexpr Rule Increasing() const { return With(&Rule::increasing); }
  constexpr Rule RelativePath() const { return With(&Rule::relative_path).NotEmpty(); }

 private:
  constexpr Rule Lower(double v, bool open) const {
    Rule r = *this;
    r.lo = v;
    r.lo_open = open;
    return r;
  }
  constexpr Rule Upper(double v, bool open) const {
    Rule r = *this;
    r.hi = v;
    r.hi_open = open;
    return r;
  }
  constexpr Rule With(bool Rule::*flag) const {
    Rule r = *this;
    r.*flag = true;
    return r;
  }
};

// A rule with a unit and no constraint yet; "" for dimensionless values.
constexpr Rule Unit(const char* unit) {
  Rule r;
  r.unit = unit;
  return r;
}
// Any value of the field's type (booleans, enums, free text).
constexpr Rule Any() { return Rule(); }

namespace internal {

inline std::string Number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", v);
  return buffer;
}

inline bool HasLower(const Rule& r) { return r.lo != -std::numeric_limits<double>::infinity(); }
inline bool HasUpper(const Rule& r) { return r.hi != std::numeric_limits<double>::infinity(); }

inline bool InRange(double v, const Rule& r) {
  if (!std::isfinite(v)) return false;
  if (r.lo_open ? !(v > r.lo) : !(v >= r.lo)) return false;
  if (r.hi_open ? !(v < r.hi) : !(v <= r.hi)) return false;
  return true;
}

// The range in words, for error messages: "odd and at least 1", "in (0, 1]", "positive".
inline std::string InWords(const Rule& r) {
  std::string range;
  if (HasLower(r) && HasUpper(r)) {
    range = std::string("in ") + (r.lo_open ? "(" : "[") + Number(r.lo) + ", " + Number(r.hi) +
            (r.hi_open ? ")" : "]");
  } else if (HasLower(r)) {
    if (r.lo == 0.0) {
      range = r.lo_open ? "positive" : "zero or more";
    } else {
      range = (r.lo_open ? "greater than " : "at least ") + Number(r.lo);
    }
  } else if (HasUpper(r)) {
    range = (r.hi_open ? "less than " : "at most ") + Number(r.hi);
  } else {
    range = "a finite number";
  }
  return r.odd ? "odd and " + range : range;
}

}  // namespace internal

// The range as people write it: "> 0", "in [0, 1)", "odd, >= 1"; empty when there is none.
inline std::string DescribeRange(const Rule& r) {
  using internal::Number;
  std::string out = r.odd ? "odd" : "";
  auto add = [&out](const std::string& s) { out += (out.empty() ? "" : ", ") + s; };
  if (internal::HasLower(r) && internal::HasUpper(r)) {
    add(std::string("in ") + (r.lo_open ? "(" : "[") + Number(r.lo) + ", " + Number(r.hi) +
        (r.hi_open ? ")" : "]"));
  } else if (internal::HasLower(r)) {
    add((r.lo_open ? "> " : ">= ") + Number(r.lo));
  } else if (internal::HasUpper(r)) {
    add((r.hi_open ? "< " : "<= ") + Number(r.hi));
  }
  if (r.not_empty && !r.relative_path) add("not empty");
  if (r.increasing) add("increasing");
  if (r.relative_path) add("a relative path inside the folder");
  return out;
}

// "(m; > 0)": unit and range for a documentation line; empty when the rule says nothing.
inline std::string DescribeRule(const Rule& r) {
  const std::string range = DescribeRange(r);
  std::string unit = r.unit;
  if (unit.empty() && range.empty()) return "";
  if (unit.empty()) return "(" + range + ")";
  if (range.empty()) return "(" + unit + ")";
  return "(" + unit + "; " + range + ")";
}

// Why `value` breaks `rule`, or "" when it does not.
template <typename T>
std::string Violation(const T& value, const Rule& rule) {
  if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
    const double v = static_cast<double>(value);
    bool ok = internal::InRange(v, rule);
    if constexpr (std::is_integral_v<T>) {
      if (rule.odd && value % 2 == 0) ok = false;
    }
    if (!ok && !std::isfinite(v)) return "must be a finite number";
    if (!ok) return "must be " + internal::InWords(rule);
    if constexpr (std::is_floating_point_v<T>) {
      // 1e-320 is "positive", but no setting means it: a cell that small made NaN poses.
      if (std::fpclassify(value) == FP_SUBNORMAL) {
        return "must be zero or a normal number (" + internal::Number(v) +
               " is below the smallest normal double)";
      }
    }
    return "";
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (rule.not_empty && value.empty()) return "must not be empty";
    if (rule.relative_path) {
      const std::filesystem::path path(value);
      if (path.is_absolute()) return "must be a relative path inside the folder";
      for (const auto& part : path) {
        if (part == "..") return "must be a relative path inside the folder";
      }
    }
    return "";
  } else if constexpr (std::is_same_v<T, std::vector<double>> ||
                       std::is_same_v<T, std::vector<int>>) {
    if (rule.not_empty && value.empty()) return "must not be empty";
    for (size_t i = 0; i < value.size(); ++i) {
      const std::string element = Violation(value[i], rule);
      if (!element.empty()) return "element " + std::to_string(i) + ": " + element;
      if (rule.increasing && i > 0 && value[i] < value[i - 1]) return "must be increasing";
    }
    return "";
  } else {
    return "";  // booleans, enums and composite values: the type is the constraint
  }
}

namespace internal {
class Checker {
 public:
  explicit Checker(std::string* error) : error_(error) {}
  template <typename T>
  void operator()(const char* key, const T& field, const char* /*doc*/, const Rule& rule) {
    if (!ok_) return;
    const std::string why = Violation(field, rule);
    if (why.empty()) return;
    ok_ = false;
    if (error_) *error_ = std::string(key) + ": " + why;
  }
  bool ok() const { return ok_; }

 private:
  std::string* error_;
  bool ok_ = true;
};
}  // namespace internal

// Checks every field of `options` against its rule; on the first violation sets `*error` (if not
// null) to "key: must be ..." and returns false. `S` has `template <class V> VisitFields(V&&)`.
template <typename S>
bool CheckFields(const S& options, std::string* error) {
  internal::Checker checker(error);
  // VisitFields hands out mutable references for the reader; the checker only reads.
  const_cast<S&>(options).VisitFields(checker);
  return checker.ok();
}

}  // namespace ratslam::schema

#endif  // RATSLAM_COMMON_SCHEMA_H_
