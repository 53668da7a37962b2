#pragma once
// A media file's audio and subtitle streams for stream copy (core/carried_streams.hpp): a second
// demuxer on the file, read in step with the video so that the muxer's interleaving buffer stays
// small.
#include <memory>
#include <string>

#include "core/carried_streams.hpp"

namespace nelf {

// The carried streams of `path`, with container time `origin_s` (the video's first frame) as output
// time 0. Throws UserError (status 1) when the file cannot be opened again.
std::unique_ptr<CarriedStreams> open_file_carried_streams(const std::string& path, double origin_s, bool allow_network);

}  // namespace nelf
