// Errors are returned and carried, never thrown across the API.
#pragma once

#include <string>
#include <utility>

namespace dcm {

/// The outcome of an operation: OK, an error with a message that names the
/// file, channel or field at fault, or "pending" — a provider that cannot
/// evaluate the requested samples now (the file-based round trip: the samples
/// are rendered by another process and come back in the next round), or
/// "over budget" — an evaluation refused because it would pass the exact-pixel
/// budget of a quality search, or a budget too small for that search's
/// validation or coarsest run (an error to everyone who does not ask).
class [[nodiscard]] Status {
 public:
  enum class Code { kOk, kError, kPending, kOverBudget };

  Status() = default;
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(Code::kError, std::move(message)); }
  static Status Pending(std::string message) { return Status(Code::kPending, std::move(message)); }
  static Status OverBudget(std::string message) { return Status(Code::kOverBudget, std::move(message)); }

  bool ok() const { return code_ == Code::kOk; }
  bool pending() const { return code_ == Code::kPending; }
  bool overBudget() const { return code_ == Code::kOverBudget; }
  Code code() const { return code_; }
  const std::string& message() const { return message_; }

 private:
  Status(Code c, std::string m) : code_(c), message_(std::move(m)) {}
  Code code_ = Code::kOk;
  std::string message_;
};

/// Returns from the enclosing function when `expr` is not OK.
#define DCM_RETURN_IF_ERROR(expr)            \
  do {                                       \
    ::dcm::Status _dcm_status = (expr);      \
    if (!_dcm_status.ok()) return _dcm_status; \
  } while (0)

}  // namespace dcm
