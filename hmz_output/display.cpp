#include "hmz_output/display.hpp"

#include <stdexcept>

namespace nelf {

OutputKind parse_output_kind(const std::string& name) {
  if (name == "window") return OutputKind::window;
  if (name == "fullscreen") return OutputKind::fullscreen;
  if (name == "kms") return OutputKind::kms;
  if (name == "quad-buffer") return OutputKind::quad_buffer;
  throw std::invalid_argument("unknown output '" + name + "' (expected window, fullscreen, kms or quad-buffer)");
}

std::string output_kind_name(OutputKind kind) {
  switch (kind) {
    case OutputKind::window:
      return "window";
    case OutputKind::fullscreen:
      return "fullscreen";
    case OutputKind::kms:
      return "kms";
    case OutputKind::quad_buffer:
      return "quad-buffer";
  }
  return "window";
}

}  // namespace nelf
