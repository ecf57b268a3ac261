// Error reporting for expected failures (bad input, bad configuration, inconsistent ids).
// Library code returns a Status instead of throwing across module boundaries or exiting.
#ifndef RATSLAM_COMMON_STATUS_H_
#define RATSLAM_COMMON_STATUS_H_

#include <optional>
#include <stdexcept>
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
  StatusOr(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design.
  // From an error. An OK status holds no value, so it cannot stand for one: a StatusOr made
  // from one is an error that says so (a bug in the caller), never "ok without a value".
  StatusOr(Status status)  // NOLINT: implicit by design.
      : status_(status.ok() ? Status::Error(kOkWithoutValue) : std::move(status)) {}
  static constexpr const char* kOkWithoutValue =
      "internal error: a StatusOr was made from an OK status, without a value";

  bool ok() const { return status_.ok(); }
  const Status& status() const { return status_; }
  // The value; on an error, a programming mistake, throws std::logic_error with the error's
  // message (defined behaviour, caught at the top of the program), never reads garbage.
  const T& value() const& { return Checked(); }
  T& value() & { return Checked(); }
  T&& value() && { return std::move(Checked()); }
  const T* operator->() const { return &Checked(); }
  T* operator->() { return &Checked(); }
  const T& operator*() const& { return Checked(); }
  T& operator*() & { return Checked(); }
  T&& operator*() && { return std::move(Checked()); }

 private:
  T& Checked() {
    if (!value_) throw std::logic_error("StatusOr: value of an error: " + status_.message());
    return *value_;
  }
  const T& Checked() const {
    if (!value_) throw std::logic_error("StatusOr: value of an error: " + status_.message());
    return *value_;
  }

  Status status_;
  std::optional<T> value_;
};

}  // namespace ratslam

#define RATSLAM_RETURN_IF_ERROR(expr)                  \
  do {                                                 \
    ::ratslam::Status ratslam_status_ = (expr);        \
    if (!ratslam_status_.ok()) return ratslam_status_; \
  } while (false)

#endif  // RATSLAM_COMMON_STATUS_H_
