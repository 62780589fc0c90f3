#include "base/status.h"

namespace isolink {

const std::string& Status::message() const {
  static const std::string kEmpty;
  return message_ ? *message_ : kEmpty;
}

Status Status::with_context(const std::string& context) const {
  if (ok()) return *this;
  return Status(context + ": " + *message_);
}

}  // namespace isolink
