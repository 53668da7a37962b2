#pragma once
// Reading a PipeWire video node as it produces frames, for the `pipewire:` source: the screen or
// window the user chooses in the desktop's ScreenCast portal (inputs/screencast_portal), or a node
// named directly (gamescope's, anything `pw-cli ls Node` lists as Video/Source). A named node is
// linked by nelf itself, so no session manager is needed and none links nelf to anything else; the
// portal's stream is linked by the desktop's session manager, as the portal's connection sees only
// that node. Frames come in shared memory (MemFd or MemPtr buffers) in any 8-bit RGB order or in
// 8-bit YUV and are read as RGBA (inputs/pipewire_frame).
#include <atomic>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "inputs/live_capture.hpp"

namespace nelf {

// What `pipewire:[node=ID|NAME][,fps=N][,wait=S][,restore=no]` names; without a node, the
// ScreenCast portal's choice.
struct PipeWireCaptureSpec {
  std::optional<unsigned> node_id;  // the node's id (pw-cli ls Node)
  std::string node_name;            // or its node.name / node.description
  std::optional<bool> restore;      // portal: take back the choice kept from the last run (unset: yes)
  double fps = 60.0;                // the most frames a second that are read
  double wait_s = 0.0;              // how long to wait for the node to appear
};

bool is_pipewire_capture_spec(std::string_view input);
// Throws UserError (status 2) for unknown keys and bad values.
PipeWireCaptureSpec parse_pipewire_capture_spec(const std::string& input);

class PipeWireCapture final : public LiveCapture {
 public:
  // For a named node: connects to the PipeWire daemon ($PIPEWIRE_REMOTE, $PIPEWIRE_RUNTIME_DIR or
  // $XDG_RUNTIME_DIR, as every PipeWire client does), finds the node (waiting up to spec.wait_s for
  // it) and links a stream to it. Without one: asks the ScreenCast portal and connects through the
  // connection it opens. Throws UserError: status 1 when there is no daemon, no such node, the node
  // offers no format nelf reads or sends no frame, the portal is missing or the cast refused; status 2
  // when a name matches several nodes (they are listed, to choose one by id). `stop` (may be null)
  // ends a wait with status 130.
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
