#pragma once
// Error handling, in three tiers (see docs/STYLE): programming errors are debug asserts; bad input or bad
// geometry is a returned Status / Result<T>; exceptions and exit codes only at the edges (file I/O, CLI).
#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace seam {

enum class ErrorCode {
  kOk = 0,
  kInvalidInput,  ///< malformed data: sizes, NaN/Inf, knots, weights, unknown names
  kDegenerate,    ///< geometrically degenerate input (zero-length edge, vanishing normal, ...)
  kNotFound,      ///< a named object or a requested feature does not exist
  kUnsupported,   ///< valid input that this version cannot handle
  kNoSolution,    ///< a constraint system has no solution
  kIoError,       ///< a file could not be read or written
};

/// Outcome of an operation that returns nothing: ok, or an error code with a human-readable message.
class Status {
 public:
  Status() = default;
  Status(ErrorCode code, std::string message) : code_(code), message_(std::move(message)) {}
  static Status ok() { return {}; }
  [[nodiscard]] bool isOk() const { return code_ == ErrorCode::kOk; }
  explicit operator bool() const { return isOk(); }
  [[nodiscard]] ErrorCode code() const { return code_; }
  [[nodiscard]] const std::string& message() const { return message_; }
  /// Returns a copy whose message is "prefix: message" (to add the file or object name on the way up).
  [[nodiscard]] Status withContext(const std::string& prefix) const {
    return isOk() ? *this : Status(code_, prefix + ": " + message_);
  }

 private:
  ErrorCode code_ = ErrorCode::kOk;
  std::string message_;
};

inline Status invalidInput(std::string message) { return {ErrorCode::kInvalidInput, std::move(message)}; }

/// A value or the Status that explains why there is none.
template <class T>
class Result {
 public:
  Result(T value) : data_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
  Result(Status status) : data_(std::move(status)) {  // NOLINT(google-explicit-constructor)
    assert(!std::get<Status>(data_).isOk() && "a Result built from a Status must carry an error");
  }
  [[nodiscard]] bool isOk() const { return std::holds_alternative<T>(data_); }
  explicit operator bool() const { return isOk(); }
  [[nodiscard]] const T& value() const& {
    assert(isOk());
    return std::get<T>(data_);
  }
  [[nodiscard]] T& value() & {
    assert(isOk());
    return std::get<T>(data_);
  }
  [[nodiscard]] T&& value() && {
    assert(isOk());
    return std::get<T>(std::move(data_));
  }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }
  /// The error; Status::ok() when a value is held.
  [[nodiscard]] Status status() const { return isOk() ? Status::ok() : std::get<Status>(data_); }

 private:
  std::variant<T, Status> data_;
};

}  // namespace seam
