#pragma once
// Reading a PipeWire video node as it produces frames, for the `pipewire:` source: a compositor's
// or a game's screen-cast stream (gamescope, a Wayland compositor's ScreenCast node, anything
// `pw-cli ls Node` lists as Video/Source). nelf links its own input stream to the node, so no
// session manager is needed and none links nelf to anything else; frames come in shared memory
// (MemFd or MemPtr buffers) in any 8-bit RGB order and are read as RGBA.
#include <atomic>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "inputs/live_capture.hpp"

namespace nelf {

// What `pipewire:node=ID|NAME[,fps=N][,wait=S]` names.
struct PipeWireCaptureSpec {
  std::optional<unsigned> node_id;  // the node's id (pw-cli ls Node)
  std::string node_name;            // or its node.name / node.description
  double fps = 60.0;                // the most frames a second that are read
  double wait_s = 0.0;              // how long to wait for the node to appear
};

bool is_pipewire_capture_spec(std::string_view input);
// Throws UserError (status 2) for unknown keys, bad values and a spec without node= (the desktop's
// ScreenCast portal is not read yet).
PipeWireCaptureSpec parse_pipewire_capture_spec(const std::string& input);

class PipeWireCapture final : public LiveCapture {
 public:
  // Connects to the PipeWire daemon ($PIPEWIRE_REMOTE, $PIPEWIRE_RUNTIME_DIR or $XDG_RUNTIME_DIR, as
  // every PipeWire client does), finds the node (waiting up to spec.wait_s for it), links a stream to
  // it and waits for its first frame. Throws UserError: status 1 when there is no daemon, no such
  // node, the node offers no format nelf reads or sends no frame; status 2 when a name matches several
  // nodes (they are listed, to choose one by id). `stop` (may be null) ends a wait with status 130.
  PipeWireCapture(const PipeWireCaptureSpec& spec, std::string input, const std::atomic<bool>* stop = nullptr);
  ~PipeWireCapture() override;
  PipeWireCapture(const PipeWireCapture&) = delete;
  PipeWireCapture& operator=(const PipeWireCapture&) = delete;

  CapturedImage read() override;
  std::optional<CapturedImage> read_when_changed(std::chrono::milliseconds wait) override;
  bool closed() const override;
  const std::string& description() const override;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace nelf
