// Status and StatusOr: error reporting without exceptions on the hot path.
//
// Usage:
//   Status s = solve(...);
//   if (!s.ok()) return s.with_context("transient at t=1.2e-6 s");
//   StatusOr<Circuit> c = build(...);
//   if (!c) return c.status();
//   use(*c);
// A message is one human-readable line (or a formatted diagnostic block); each caller that adds
// context prepends it, so the final message reads outermost-first.
#pragma once

#include <optional>
#include <string>
#include <utility>

namespace isolink {

class [[nodiscard]] Status {
 public:
  Status() = default;
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(std::move(message)); }

  bool ok() const { return !message_.has_value(); }
  explicit operator bool() const { return ok(); }
  const std::string& message() const;
  // Prefixes "context: " to the message of a failed status; no-op when ok.
  Status with_context(const std::string& context) const;

 private:
  explicit Status(std::string message) : message_(std::move(message)) {}
  std::optional<std::string> message_;
};

template <class T>
class [[nodiscard]] StatusOr {
 public:
  StatusOr(T value) : value_(std::move(value)) {}          // NOLINT: implicit by design
  StatusOr(Status status) : status_(std::move(status)) {}  // NOLINT: must be an error
  bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }
  const Status& status() const { return status_; }
  T& operator*() { return *value_; }
  const T& operator*() const { return *value_; }
  T* operator->() { return &*value_; }
  const T* operator->() const { return &*value_; }

 private:
  std::optional<T> value_;
  Status status_;
};

}  // namespace isolink
