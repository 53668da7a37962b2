#pragma once
// A SourceRequest as the inputs' tests open one: the input, a layout or none (detect), and nothing
// printed (the description and warnings the tests read from info() and errors instead).
#include <optional>
#include <string>

#include "inputs/source.hpp"

namespace nelf::test {

inline SourceRequest quiet_request(const std::string& input, std::optional<StereoLayout> layout = std::nullopt) {
  SourceRequest request;
  request.input = input;
  request.layout = layout;
  request.quiet = true;
  return request;
}

}  // namespace nelf::test
