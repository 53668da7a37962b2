// What the glx-stereo: source accepts of a game's hello (inputs/glx_stereo_driver.cpp). The frame
// memory comes from a process nelf did not write (the game, with nelf's interposer inside it), and
// nelf reads it for as long as the game runs: memory smaller than the frames it announces, or memory
// the game could shrink later, would make a read fault (SIGBUS) and kill nelf, so such a hello is
// refused with one line. A fake interposer speaks the protocol here, no X server needed; the real one
// is tested against the test game in window/test_glx_stereo_source.cpp.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <optional>
#include <string>
#include <thread>

#include "core/unix_socket.hpp"
#include "core/user_error.hpp"
#include "inputs/glx_stereo_protocol.hpp"
#include "inputs/source_drivers.hpp"
#include "support/source_requests.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace test_glx_stereo_driver {

namespace protocol = glx_stereo;

constexpr std::uint32_t kWidth = 64, kHeight = 32;

// A memfd of `bytes`, sealed against shrinking (and growing) when `sealed`, as the interposer makes it.
UniqueFd frame_memory(std::size_t bytes, bool sealed) {
  UniqueFd fd(memfd_create("test-frames", MFD_CLOEXEC | MFD_ALLOW_SEALING));
  EXPECT_GE(fd.get(), 0);
  EXPECT_EQ(ftruncate(fd.get(), static_cast<off_t>(bytes)), 0);
  if (sealed) {
    EXPECT_EQ(fcntl(fd.get(), F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL), 0);
  }
  return fd;
}

// Slot 0 of `memory` written as the interposer writes a frame: both kWidth × kHeight eyes, the left
// red and the right blue, frame 0.
void write_red_and_blue_frame(int memory) {
  const std::size_t bytes = protocol::shared_bytes(kWidth, kHeight);
  void* mapped = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, memory, 0);
  ASSERT_NE(mapped, MAP_FAILED);
  auto* slot = static_cast<unsigned char*>(mapped);
  auto* head = reinterpret_cast<protocol::SlotHeader*>(slot);
  head->sequence = 2;
  head->frame = 0;
  const std::size_t eye = protocol::eye_bytes(kWidth, kHeight);
  for (std::size_t i = 0; i < eye; i += 4) {
    unsigned char* left = slot + protocol::kSlotHeader + i;
    unsigned char* right = left + eye;
    left[0] = 255, left[1] = 0, left[2] = 0, left[3] = 255;
    right[0] = 0, right[1] = 0, right[2] = 255, right[3] = 255;
  }
  munmap(mapped, bytes);
}

// The game's end of the link: connects to `socket` once nelf listens, says `hello` with `memory`
// attached (none when < 0), announces frame 0 in slot 0, and keeps the link open until destroyed.
class FakeInterposer {
 public:
  FakeInterposer(std::string socket, protocol::Message hello, UniqueFd memory)
      : thread_([socket = std::move(socket), hello, memory = std::move(memory)](std::stop_token stop) {
          UniqueFd link;
          const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
          while (!stop.stop_requested() && std::chrono::steady_clock::now() < until) {
            link = test::connect_unix_socket(socket);
            if (link.get() >= 0) break;
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
          }
          if (link.get() < 0) return;
          protocol::send_message(link.get(), hello, memory.get(), MSG_NOSIGNAL);
          protocol::Message frame;
          frame.type = protocol::MessageType::frame;
          frame.slot = 0;
          frame.frame = 0;
          protocol::send_message(link.get(), frame, -1, MSG_NOSIGNAL);
          while (!stop.stop_requested()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }) {}

 private:
  std::jthread thread_;
};

protocol::Message stereo_hello(std::uint32_t width = kWidth, std::uint32_t height = kHeight) {
  protocol::Message hello;
  hello.type = protocol::MessageType::hello;
  hello.stereo = 1;
  hello.width = width;
  hello.height = height;
  hello.slot = 4242;  // the game's process id
  return hello;
}

class GlxStereoHello : public ::testing::Test {
 protected:
  std::string socket() const { return (dir_.path() / "game.sock").string(); }
  std::string input() const { return "glx-stereo:wait=10,socket=" + socket(); }

  // The one line the source is refused with (its exit status 1), after the fake game said `hello`.
  std::string refusal(const protocol::Message& hello, UniqueFd memory) {
    FakeInterposer game(socket(), hello, std::move(memory));
    try {
      open_source(test::quiet_request(input()));
    } catch (const UserError& e) {
      EXPECT_EQ(e.status(), 1);
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_EQ(what.rfind(input() + ": ", 0), 0u) << what;
      return what;
    }
    ADD_FAILURE() << "the hello was accepted";
    return {};
  }

  test::TempDir dir_;
};

TEST_F(GlxStereoHello, TheInterposersSealedFrameMemoryIsRead) {
  // The control: memory as the interposer makes it gives the game's two eyes.
  UniqueFd memory = frame_memory(protocol::shared_bytes(kWidth, kHeight), true);
  write_red_and_blue_frame(memory.get());
  FakeInterposer game(socket(), stereo_hello(), std::move(memory));
  auto source = open_source(test::quiet_request(input()));
  const std::optional<StereoVideoFrame> frame = source->next();
  ASSERT_TRUE(frame);
  ASSERT_EQ(frame->width, static_cast<int>(kWidth));
  ASSERT_EQ(frame->height, static_cast<int>(kHeight));
  EXPECT_EQ(frame->left[0], 255);
  EXPECT_EQ(frame->left[2], 0);
  EXPECT_EQ(frame->right[0], 0);
  EXPECT_EQ(frame->right[2], 255);
}

TEST_F(GlxStereoHello, FrameMemorySmallerThanTheFramesItAnnouncesIsRefused) {
  const std::string why = refusal(stereo_hello(), frame_memory(4096, true));
  EXPECT_NE(why.find("the game's frame memory holds 4096 bytes where its 64x32 frames need"), std::string::npos) << why;
}

TEST_F(GlxStereoHello, FrameMemoryTheGameCouldShrinkIsRefused) {
  const std::string why = refusal(stereo_hello(), frame_memory(protocol::shared_bytes(kWidth, kHeight), false));
  EXPECT_NE(why.find("not sealed against shrinking"), std::string::npos) << why;
}

TEST_F(GlxStereoHello, FramesOfNoSizeOrOfAnImpossibleSizeAreRefused) {
  for (const auto& [width, height] :
       {std::pair<std::uint32_t, std::uint32_t>{0, 32}, {64, 0}, {100000, 32}, {64, 0xffffffffu}}) {
    SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height));
    const std::string why = refusal(stereo_hello(width, height), frame_memory(4096, true));
    EXPECT_NE(why.find("the game's interposer announces " + std::to_string(width) + "x" + std::to_string(height) +
                       " frames (each side 1 to 16384)"),
              std::string::npos)
        << why;
  }
}

TEST_F(GlxStereoHello, AHelloWithoutFrameMemoryIsRefused) {
  const std::string why = refusal(stereo_hello(), UniqueFd());
  EXPECT_NE(why.find("attached no frame memory"), std::string::npos) << why;
}

}  // namespace test_glx_stereo_driver
}  // namespace nelf
