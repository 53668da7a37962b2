#!/usr/bin/env bash
# Installs the Debian 12 packages nelf needs to build, test and run.
# Idempotent and quiet: only missing packages are installed; nothing is printed when all are present.
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake pkg-config git clang-format file dpkg-dev
  # clang and its libFuzzer + sanitizer runtimes (a Recommends, so named) for the fuzz targets (make fuzz)
  clang libclang-rt-14-dev
  # graphics: EGL/OpenGL through epoxy, Mesa's llvmpipe for GPU-less tests, GLFW windows, KMS/GBM
  libepoxy-dev libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri libgbm-dev libdrm-dev libglfw3-dev libxrandr-dev libx11-dev
  glslang-tools xvfb xauth
  # live capture (x11: windows through Composite, Damage and MIT-SHM)
  libxcomposite-dev libxdamage-dev libxext-dev
  # live capture (pipewire: a PipeWire video node); the daemon, its tools and GStreamer's
  # videotestsrc into pipewiresink are what the tests start as a node to read
  libpipewire-0.3-dev pipewire-bin gstreamer1.0-tools gstreamer1.0-plugins-base gstreamer1.0-pipewire
  # live capture (pipewire: alone: the desktop's ScreenCast portal over D-Bus through sd-bus); the
  # tests run the real xdg-desktop-portal on a private session bus, a test backend of their own
  # answering the user's dialog (tests/desktop/), and WirePlumber to link the portal's stream
  libsystemd-dev xdg-desktop-portal wireplumber dbus-daemon
  # synthetic key presses for the window tests of `nelf calibrate`
  xdotool
  # media: FFmpeg libraries, the ffmpeg CLI for test media and benchmarks, OpenImageIO
  libavformat-dev libavcodec-dev libavutil-dev libswscale-dev libswresample-dev libavfilter-dev libavdevice-dev
  ffmpeg libopenimageio-dev libpng-dev
  # stereo matching for the estimated depth (inputs/stereo_matcher): OpenCV's block matcher, its
  # three modules alone (libopencv-dev would add every other module, 42 packages, 315 MB)
  libopencv-core-dev libopencv-imgproc-dev libopencv-calib3d-dev
  # maths, configuration, CLI, formatting, JSON, audio, subtitles (libass)
  libglm-dev libtomlplusplus-dev libcli11-dev libfmt-dev libspdlog-dev nlohmann-json3-dev libsdl2-dev libass-dev
  # tests (zsh and fish: the completion checks run them)
  libgtest-dev libgmock-dev zsh fish
  # a real client of the JSON IPC socket (--input-ipc-server) for its tests, as mpv's scripts use
  socat
  # mpv, a real player, reading what convert writes (which tracks it selects on its own)
  mpv
  # the package checks (tests/package): the man page rendered as lintian does, lintian itself,
  # AppStream validation and the MIME database
  man-db lintian appstream shared-mime-info
  # fonts for the text of `nelf design --plot` (OpenImageIO render_text)
  fonts-dejavu-core
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO=sudo; else
    echo "install-deps: missing packages (${missing[*]}); run this script as root" >&2
    exit 1
  fi
else
  SUDO=
fi

echo "install-deps: installing ${#missing[@]} package(s): ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
