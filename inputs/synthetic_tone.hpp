#pragma once
// The sound of the `synthetic:` clip (SyntheticClip::audio) as an AudioStream, so that play and
// convert take it as they take a file's audio.
#include <memory>

#include "core/audio_stream.hpp"
#include "inputs/synthetic_source.hpp"

namespace nelf {

// The tone of the clip `settings` describes, from frame `first_frame` (pts 0) to the clip's end, as
// `format` asks (0: the clip's own rate, mono: what `nelf convert` encodes). Stereo carries the
// same samples in both channels.
std::unique_ptr<AudioStream> open_synthetic_tone(const SyntheticClipSettings& settings, int first_frame,
                                                 AudioFormat format);

}  // namespace nelf
