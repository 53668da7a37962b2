#pragma once
// What `nelf play` plays one after the other: the inputs of its command line, where a directory
// stands for the media files in it and an `.m3u` playlist for the entries it lists.
#include <functional>
#include <string>
#include <vector>

namespace nelf {

// Whether a file name is one nelf plays by its extension: a still (inputs/still_source.hpp) or a
// common video container. A directory lists only these.
bool is_media_file_name(const std::string& name);

// Natural order ("photo2" before "photo10"): runs of digits compare as numbers, the rest byte by
// byte.
bool natural_less(const std::string& a, const std::string& b);

// The entries `inputs` stand for, in order. A directory: its media files (not its subdirectories),
// in natural order. An `.m3u`/`.m3u8` file: its lines that are not empty or `#` comments, relative
// to the playlist's folder unless absolute or a URL; an entry that is not there is left out with a
// warning (one line, passed to `warn`); an HLS playlist (`#EXT-X-` tags) stays one input, the
// stream FFmpeg reads. Anything else stays as it is (a file, `synthetic:`, a URL).
// Throws UserError (status 2) for a directory without media files, a playlist that cannot be read
// or has no entry left.
std::vector<std::string> expand_playlist(const std::vector<std::string>& inputs,
                                         const std::function<void(const std::string&)>& warn);

}  // namespace nelf
