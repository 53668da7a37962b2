#!/usr/bin/env bash
# Frame pacing of `nelf play` (DESIGN.md §10, issue #5): 24, 30 and 60 fps sources (1920x1080
# half side-by-side H.264 with AAC audio) played to hdmi-fp-720p60 with profile hmz-t1 in a private
# Xvfb, sound on SDL's dummy driver (it consumes samples in real time, so the audio clock is master
# as with a real device). Reports the exit line (shown / repeated / dropped) and, from
# --log-frames, where the time of each new frame goes: upload of the two views, compositing both
# eyes, present() (blit to the window and swap). Not run by ctest; results go to docs/PERFORMANCE.md.
#
# usage: tests/bench/play_pacing.sh [NELF] [SECONDS] [FSAA] [PROFILE]
#   NELF     the nelf binary (default build/nelf)
#   SECONDS  clip length (default 10)
#   FSAA     --fsaa for play (default 1)
#   PROFILE  the device profile (default hmz-t1)
# With PACING_LOGS=DIR the frame logs are kept there as log24.csv, log30.csv, log60.csv.
# PACING_ARGS adds options to each play (e.g. "--depth estimate"); PACING_RATES picks the source
# rates (default "24 30 60").
# PACING_SCREEN=WxH sets the Xvfb screen (default 1920x1600, where the 1280x1470 window fits 1:1;
# 1920x1080 gives a window scaled to fit, as on a 1080p desktop).
set -euo pipefail
nelf=$(realpath "${1:-build/nelf}")
seconds=${2:-10}
fsaa=${3:-1}
profile=${4:-hmz-t1}
export LP_NUM_THREADS=${LP_NUM_THREADS:-$(nproc)}
export SDL_AUDIODRIVER=${SDL_AUDIODRIVER:-dummy}

work=$(mktemp -d)
xvfb_pid=
cleanup() {
  [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
export MESA_SHADER_CACHE_DIR=$work/shader-cache
export NELF_CACHE_DIR=$work/nelf-cache  # composite tables: recorded on the first frame, as on a first play

# A private X server on a free display number (Xvfb writes it to the fd we give it).
exec {displayfd}<> <(:)
Xvfb -displayfd "$displayfd" -screen 0 "${PACING_SCREEN:-1920x1600}x24" -nolisten tcp -noreset >/dev/null 2>&1 &
xvfb_pid=$!
read -r -t 10 display_number <&"$displayfd"
export DISPLAY=:$display_number

echo "screen: ${PACING_SCREEN:-1920x1600}"
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg), LP_NUM_THREADS=$LP_NUM_THREADS"
echo "command: nelf play CLIP --profile $profile --signal hdmi-fp-720p60 --fsaa $fsaa ${PACING_ARGS:+$PACING_ARGS }--log-frames LOG (DISPLAY=$DISPLAY, SDL_AUDIODRIVER=$SDL_AUDIODRIVER)"
printf '| source | frames | shown | repeated | dropped | upload ms | composite ms | present ms | late >1 frame |\n'
printf '|---|---|---|---|---|---|---|---|---|\n'
for fps in ${PACING_RATES:-24 30 60}; do
  clip=$work/clip$fps.mp4
  # Half side-by-side: each 960x1080 half is a squeezed 1920x1080 view (moving test pattern).
  ffmpeg -nostdin -hide_banner -loglevel error -y \
    -f lavfi -i "testsrc2=s=960x1080:r=$fps:d=$seconds" \
    -f lavfi -i "testsrc2=s=960x1080:r=$fps:d=$seconds,hue=h=180" \
    -f lavfi -i "sine=frequency=440:sample_rate=48000:duration=$seconds" \
    -filter_complex "[0][1]hstack[v]" -map "[v]" -map 2:a \
    -c:v libx264 -preset veryfast -crf 20 -pix_fmt yuv420p -c:a aac -shortest "$clip"
  log=$work/log$fps.csv
  # shellcheck disable=SC2086  # PACING_ARGS is a list of options
  summary=$("$nelf" play "$clip" --layout sbs-half --profile "$profile" --signal hdmi-fp-720p60 --fsaa "$fsaa" \
    ${PACING_ARGS:-} --log-frames "$log" --quiet 2>&1 | tail -1)
  read -r shown repeated dropped < <(echo "$summary" | sed -E 's/.* ([0-9]+) frames shown, ([0-9]+) repeated, ([0-9]+) dropped.*/\1 \2 \3/')
  # Medians over the new frames (the first one compiles shaders and is left out).
  stats=$(awk -F, -v fps="$fps" 'NR > 2 && $2 == "shown" {
      n++; up[n] = $9; co[n] = $10; pr[n] = $11; d = $4 - $3; if (d < 0) d = -d; if (d > 1 / fps) late++ }
    function median(a, n,   i, j, t) {
      for (i = 2; i <= n; i++) { t = a[i]; for (j = i - 1; j >= 1 && a[j] > t; j--) a[j + 1] = a[j]; a[j + 1] = t }
      return n ? a[int((n + 1) / 2)] : 0 }
    END { printf "%.1f %.1f %.1f %d", median(up, n), median(co, n), median(pr, n), late }' "$log")
  read -r up co pr late <<<"$stats"
  if [ -n "${PACING_LOGS:-}" ]; then mkdir -p "$PACING_LOGS" && cp "$log" "$PACING_LOGS/"; fi
  printf '| %d fps, %d s | %d | %s | %s | %s | %s | %s | %s | %s |\n' "$fps" "$seconds" $((fps * seconds)) \
    "$shown" "$repeated" "$dropped" "$up" "$co" "$pr" "$late"
done
