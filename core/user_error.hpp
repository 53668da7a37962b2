#pragma once
// A problem with how nelf was invoked or with its input, raised anywhere (inputs, outputs, the
// player) and reported by main() as one line with exit status `status` (2 for bad arguments or
// profiles, 1 for failed jobs, 130 when interrupted). Lives in the library so that the pieces the
// commands share (stereo frame sources, the player) can say the same thing convert says.
#include <stdexcept>
#include <string>

namespace nelf {

class UserError : public std::runtime_error {
 public:
  explicit UserError(const std::string& message, int status = 1) : std::runtime_error(message), status_(status) {}
  int status() const { return status_; }

 private:
  int status_;
};

}  // namespace nelf
