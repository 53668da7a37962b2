#include "hmz_output/audio_output.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace nelf {

namespace {

using Steady = std::chrono::steady_clock;
double seconds_between(Steady::time_point a, Steady::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// ALSA's library prints several lines to stderr when there is no sound card; the player reports
// that case itself in one line. Silences fd 2 for the scope (called before any thread starts).
class QuietStderr {
 public:
  QuietStderr() {
    std::fflush(stderr);
    saved_ = dup(2);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) dup2(null, 2);
    if (null >= 0) close(null);
  }
  ~QuietStderr() {
    if (saved_ < 0) return;
    dup2(saved_, 2);
    close(saved_);
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  int saved_ = -1;
};

}  // namespace

// --- SystemClock ------------------------------------------------------------------------------

SystemClock::SystemClock() : origin_(Clock::now()) {}

double SystemClock::now_locked() const {
  if (paused_) return base_;
  return base_ + seconds_between(origin_, Clock::now());
}
double SystemClock::now() const {
  std::lock_guard lock(mutex_);
  return now_locked();
}
void SystemClock::set_paused(bool paused) {
  std::lock_guard lock(mutex_);
  if (paused == paused_) return;
  base_ = now_locked();
  origin_ = Clock::now();
  paused_ = paused;
}
bool SystemClock::paused() const {
  std::lock_guard lock(mutex_);
  return paused_;
}
void SystemClock::restart_at(double seconds) {
  std::lock_guard lock(mutex_);
  base_ = seconds;
  origin_ = Clock::now();
}

// --- AudioOutput ------------------------------------------------------------------------------

void apply_volume(std::span<float> samples, double volume, bool muted) {
  const double v = std::clamp(volume, 0.0, 130.0) / 100.0;
  const auto gain = static_cast<float>(muted ? 0.0 : v * v * v);
  if (gain == 1.f) return;
  for (float& sample : samples) sample *= gain;
}

std::unique_ptr<AudioOutput> AudioOutput::open(int sample_rate, int channels, std::string& why_not) {
  SDL_AudioSpec want{};
  want.freq = sample_rate;
  want.format = AUDIO_F32SYS;
  want.channels = static_cast<Uint8>(std::clamp(channels, 1, 8));
  want.samples = 512;  // ~10 ms at 48 kHz: the granularity of the audio clock
  SDL_AudioSpec have{};
  SDL_AudioDeviceID device = 0;
  {
    QuietStderr quiet;
    if (SDL_InitSubSystem(SDL_INIT_AUDIO) != 0) {
      why_not = SDL_GetError();
      return nullptr;
    }
    // Allowing a change of the channel count makes SDL say what the device really takes instead of
    // mixing down itself; anything but what was asked for then gets stereo, which SDL converts to
    // whatever the device has.
    device = SDL_OpenAudioDevice(nullptr, 0, &want, &have, want.channels > 2 ? SDL_AUDIO_ALLOW_CHANNELS_CHANGE : 0);
    if (device != 0 && have.channels != want.channels) {
      SDL_CloseAudioDevice(device);
      want.channels = 2;
      device = SDL_OpenAudioDevice(nullptr, 0, &want, &have, 0);
    }
  }
  if (device == 0) {
    why_not = SDL_GetError();
    SDL_QuitSubSystem(SDL_INIT_AUDIO);
    return nullptr;
  }
  return std::unique_ptr<AudioOutput>(new AudioOutput(device, have));
}

AudioOutput::AudioOutput(SDL_AudioDeviceID device, const SDL_AudioSpec& spec) : device_(device), spec_(spec) {}

AudioOutput::~AudioOutput() {
  SDL_CloseAudioDevice(device_);
  SDL_QuitSubSystem(SDL_INIT_AUDIO);
}

std::string AudioOutput::description() const {
  const char* driver = SDL_GetCurrentAudioDriver();
  return fmt::format("{}, {} Hz, {} channels, {}-sample buffer", driver ? driver : "?", spec_.freq, spec_.channels,
                     spec_.samples);
}

void AudioOutput::queue(const AudioChunk& chunk) {
  const int channels = spec_.channels;
  if (chunk.channels != channels)
    throw std::logic_error(
        fmt::format("AudioOutput::queue: a {}-channel chunk for a {}-channel device", chunk.channels, channels));
  if (chunk.samples.empty()) return;
  std::lock_guard lock(mutex_);
  if (queued_end_pts_) {
    const double gap = chunk.pts_s - *queued_end_pts_;
    if (gap > 1.0 / spec_.freq && gap < 10.0) {
      const std::vector<float> silence(static_cast<std::size_t>(std::lround(gap * spec_.freq)) * channels, 0.f);
      SDL_QueueAudio(device_, silence.data(), static_cast<Uint32>(silence.size() * sizeof(float)));
      *queued_end_pts_ += static_cast<double>(silence.size() / channels) / spec_.freq;
    }
  } else {
    queued_end_pts_ = chunk.pts_s;
  }
  std::vector<float> scaled = chunk.samples;
  apply_volume(scaled, volume_, muted_);
  SDL_QueueAudio(device_, scaled.data(), static_cast<Uint32>(scaled.size() * sizeof(float)));
  *queued_end_pts_ += static_cast<double>(chunk.frames()) / spec_.freq;
  end_of_stream_ = false;
  drained_at_.reset();
}

void AudioOutput::set_volume(double volume, bool muted) {
  std::lock_guard lock(mutex_);
  volume_ = volume;
  muted_ = muted;
}

double AudioOutput::buffered_s() const {
  return static_cast<double>(SDL_GetQueuedAudioSize(device_)) / (spec_.freq * spec_.channels * sizeof(float));
}

void AudioOutput::end_of_stream() {
  std::lock_guard lock(mutex_);
  end_of_stream_ = true;
}

double AudioOutput::now_locked() const {
  const auto t = Steady::now();
  if (!queued_end_pts_) return hold_pts_;
  const Uint32 queued = SDL_GetQueuedAudioSize(device_);
  const double bytes_per_s = spec_.freq * static_cast<double>(spec_.channels) * sizeof(float);
  const double buffer_s = static_cast<double>(spec_.samples) / spec_.freq;
  if (queued == 0 && end_of_stream_) {
    // Audio is over; video may go on: continue from where the sound ended.
    if (!drained_at_) {
      drained_at_ = t;
      drained_base_ = *queued_end_pts_;
    }
    return paused_ ? drained_base_ : drained_base_ + seconds_between(*drained_at_, t);
  }
  const double raw = *queued_end_pts_ - queued / bytes_per_s - buffer_s;
  if (queued != last_queued_bytes_ || std::abs(raw - last_clock_) > buffer_s * 2) {
    last_queued_bytes_ = queued;
    last_clock_ = raw;
    last_change_ = t;
  }
  if (paused_ || queued == 0) return last_clock_;  // starved or paused: nothing is being heard
  // SDL took a buffer at last_change_ and plays it out over one buffer period.
  return last_clock_ + std::min(seconds_between(last_change_, t), buffer_s);
}

double AudioOutput::now() const {
  std::lock_guard lock(mutex_);
  return now_locked();
}

void AudioOutput::set_paused(bool paused) {
  std::lock_guard lock(mutex_);
  if (paused == paused_) return;
  if (drained_at_) {  // the extrapolation after the sound ended pauses too
    drained_base_ = now_locked();
    drained_at_ = Steady::now();
  }
  paused_ = paused;
  SDL_PauseAudioDevice(device_, paused ? 1 : 0);
  last_change_ = Steady::now();
}

bool AudioOutput::paused() const {
  std::lock_guard lock(mutex_);
  return paused_;
}

void AudioOutput::restart_at(double seconds) {
  std::lock_guard lock(mutex_);
  SDL_ClearQueuedAudio(device_);
  queued_end_pts_.reset();
  hold_pts_ = seconds;
  end_of_stream_ = false;
  drained_at_.reset();
  last_queued_bytes_ = 0;
  last_clock_ = seconds;
  last_change_ = Steady::now();
}

}  // namespace nelf
