#pragma once
// What a setup() returns: success, or why not. A failed setup leaves its object unsized, so
// the result must be checked ([[nodiscard]]); the reason is for the user ("the OCP is invalid:
// ...").
#include <string>
#include <utility>

namespace mixpilot {

class [[nodiscard]] SetupResult {
 public:
  SetupResult() = default;  // success
  static SetupResult failure(std::string reason) {
    SetupResult r;
    r.ok_ = false;
    r.reason_ = std::move(reason);
    return r;
  }
  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const std::string& reason() const { return reason_; }  // empty on success

 private:
  bool ok_ = true;
  std::string reason_;
};

}  // namespace mixpilot
