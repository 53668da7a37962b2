#!/usr/bin/env bash
# Latency and pacing of live games (issue #13): the test game (tests/game/) drawing two 1280x720
# eyes side by side at 30 and 60 fps in a private Xvfb, played by `nelf run --output offscreen`
# (the real player loop, paced at 60 Hz, profile hmz-t1). Each game frame carries its counter and
# CLOCK_MONOTONIC present time in its pixels; --log-frames gives, for every frame nelf presented,
# when it was read and when nelf presented it. Reports the added latency from the game's present
# to nelf's (median, 99th percentile, ms) and the share of the game's frames nelf showed. Not run by
# ctest; results go to docs/PERFORMANCE.md.
#
# usage: tests/bench/live_latency.sh [BUILD] [SECONDS] [OUTPUT]
#   BUILD    the build tree (default build): BUILD/nelf and BUILD/tests/nelf-test-game
#   SECONDS  how long each game runs (default 10)
#   OUTPUT   nelf's --output (default offscreen; window shows it in an Xvfb window)
# With LATENCY_ARGS="…" more options go to nelf run (e.g. "--fsaa 0", "--profile lvt-prototype").
# LATENCY_MODE=quad-buffer runs the game in quad-buffer stereo (its eyes through nelf's interposer)
# instead of side by side in its window (sbs, the default; any mode of the test game).
# LATENCY_VSYNC=1 has the game ask for vsync (--swap-interval 60/fps) instead of sleeping to its
# rate: a quad-buffer game's swaps then return at nelf's refreshes, as on a monitor.
set -euo pipefail
build=$(realpath "${1:-build}")
seconds=${2:-10}
output=${3:-offscreen}
export LP_NUM_THREADS=${LP_NUM_THREADS:-$(nproc)}

work=$(mktemp -d)
xvfb_pid=
cleanup() {
  [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
exec {fd}<> <(:)
Xvfb -displayfd "$fd" -screen 0 2600x1600x24 -nolisten tcp -noreset >/dev/null 2>&1 &
xvfb_pid=$!
read -r -t 10 display <&"$fd"
export DISPLAY=":$display"

echo "game fps | nelf shown | latency median ms | latency p99 ms | game frames shown"
for fps in 30 60; do
  pacing=()
  [ -n "${LATENCY_VSYNC:-}" ] && pacing=(--swap-interval $((60 / fps)))
  # shellcheck disable=SC2086
  "$build/nelf" run --output "$output" --quiet --log-frames "$work/nelf$fps.csv" ${LATENCY_ARGS:-} -- \
    "$build/tests/nelf-test-game" --mode "${LATENCY_MODE:-sbs}" --size 1280x720 --fps "$fps" --duration "$seconds" \
    "${pacing[@]}" --log "$work/game$fps.csv" 2>"$work/err$fps.txt" || { cat "$work/err$fps.txt" >&2; exit 1; }
  summary=$(tail -1 "$work/err$fps.txt")
  # Latency: nelf's present minus the game's, for each game frame when nelf first showed it. Share:
  # the distinct game frames shown among those the game presented from the first shown to the last.
  awk -F, 'NR > 1 && $16 != "" && !seen[$16]++ { printf "%.3f\n", ($14 - $17) / 1e6 }' "$work/nelf$fps.csv" |
    sort -n >"$work/lat$fps.txt"
  n=$(wc -l <"$work/lat$fps.txt")
  median=$(awk -v n="$n" 'NR == int((n + 1) / 2) { print; exit }' "$work/lat$fps.txt")
  p99=$(awk -v n="$n" 'NR == int(n * 0.99 + 0.999) { print; exit }' "$work/lat$fps.txt")
  range=$(awk -F, 'NR > 1 && $16 != "" { if (first == "") first = $16; last = $16 } END { print first, last }' \
    "$work/nelf$fps.csv")
  read -r first last <<<"$range"
  share=$(awk -v n="$n" -v f="$first" -v l="$last" 'BEGIN { printf "%d of %d (%.1f %%)", n, l - f + 1, 100 * n / (l - f + 1) }')
  echo "$fps | ${summary#nelf: } | $median | $p99 | $share"
done
