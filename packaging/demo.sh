#!/usr/bin/env bash
# `make demo`: the main job on built-in input. Renders nelf's own stereo clip (spheres in front of,
# on and behind the screen plane, with a tone), converts it for the hmz-t1 light field display into an
# HDMI 1.4a frame-packed video, and shows what an eye would see. Also prints the display's design.
set -euo pipefail
nelf=${1:-build/nelf}
mkdir -p demo
"$nelf" design --profile hmz-t1 --plot demo/design-hmz-t1.png
"$nelf" convert synthetic:duration=3 demo/hmz-t1.mkv --profile hmz-t1 -y
"$nelf" convert synthetic:duration=3 'demo/.preview_%03d.png' --profile hmz-t1 --frames 1 --quiet -y
mv -f demo/.preview_001.png demo/preview.png
"$nelf" simulate synthetic: --profile hmz-t1 --eye left --output demo/retina.png --ideal demo/ideal.png
cat <<MSG

demo: wrote
  demo/hmz-t1.mkv          3 s of 1280x1470 HDMI 1.4a frame-packed video with sound, for the HMZ-T1 + lens array
  demo/preview.png         its first frame: the elemental images of both eyes (left on top)
  demo/retina.png          what the left eye sees through the lens array (demo/ideal.png: a real screen)
  demo/design-hmz-t1.png   the display's design space (resolution over lens focal length and pitch)
MSG
