#include "player/depth_input.hpp"

#include <utility>

#include "inputs/estimated_depth_source.hpp"
#include "inputs/source_drivers.hpp"

namespace nelf {

std::unique_ptr<Source> open_source_for_depth(SourceRequest request, DepthMode mode, const Profile& display) {
  if (mode == DepthMode::off || !display.lens_array) return open_source(request);
  request.display = std::make_shared<const Profile>(display);
  request.known_depth = mode == DepthMode::automatic;
  return with_estimated_depth(open_source(request), /*keep_known=*/mode == DepthMode::automatic);
}

}  // namespace nelf
