// Error reporting for expected failures (bad input, bad configuration, inconsistent ids).
// Library code returns a Status instead of throwing across module boundaries or exiting.
#ifndef RATSLAM_STATUS_H_
#define RATSLAM_STATUS_H_

#include <optional>
#include <string>
#include <utility>

namespace ratslam {

class [[nodiscard]] Status {
 public:
  Status() = default;  // OK.
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(std::move(message)); }

  bool ok() const { return !message_.has_value(); }
  // The error message; empty for an OK status.
  const std::string& message() const {
    static const std::string kEmpty;
    return message_ ? *message_ : kEmpty;
  }
  // Returns this error with `context` prepended ("context: message"); OK stays OK.
  Status WithContext(const std::string& context) const {
    return ok() ? *this : Status(context + ": " + *message_);
  }

 private:
  explicit Status(std::string message) : message_(std::move(message)) {}
  std::optional<std::string> message_;
};

// A value or the error that prevented computing it.
template <typename T>
class [[nodiscard]] StatusOr {
 public:
  StatusOr(T value) : value_(std::move(value)) {}          // NOLINT: implicit by design.
  StatusOr(Status status) : status_(std::move(status)) {}  // NOLINT: implicit by design.

  bool ok() const { return status_.ok(); }
  const Status& status() const { return status_; }
  const T& value() const& { return *value_; }
  T& value() & { return *value_; }
  T&& value() && { return std::move(*value_); }
  const T* operator->() const { return &*value_; }
  T* operator->() { return &*value_; }
  const T& operator*() const& { return *value_; }
  T& operator*() & { return *value_; }

 private:
  Status status_;
  std::optional<T> value_;
};

}  // namespace ratslam

#define RATSLAM_RETURN_IF_ERROR(expr)                  \
  do {                                                 \
    ::ratslam::Status ratslam_status_ = (expr);        \
    if (!ratslam_status_.ok()) return ratslam_status_; \
  } while (false)

#endif  // RATSLAM_STATUS_H_
