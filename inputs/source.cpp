#include "inputs/source.hpp"

#include <fmt/format.h>

#include "core/user_error.hpp"

namespace nelf {

void Source::seek(double /*seconds*/) {
  throw UserError(fmt::format("{}: this input cannot seek", info().description), 1);
}

}  // namespace nelf
