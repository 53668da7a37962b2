#!/usr/bin/env bash
# A long fuzzing campaign (docs/fuzzing.md): all targets at once, each at the lowest priority, for
# SECONDS each. A target that stops on a finding (crash, leak, timeout, out-of-memory; the input is
# saved) is started again, with the corpus grown so far, for the time left, so every target fuzzes
# for the whole time.
#   tests/fuzz/campaign.sh BUILD_DIR OUT_DIR SECONDS [TARGET...]
# Returns at once; the targets run in the background. OUT_DIR/T.log is libFuzzer's log (one
# "campaign: run N ..." line after each run), OUT_DIR/T.time the wall and CPU time of all runs
# (/usr/bin/time -v), OUT_DIR/corpus/T the grown corpus, OUT_DIR/artifacts/T the findings.
# The binaries and the image-library module are copied to OUT_DIR/bin and OUT_DIR/lib first, so
# that rebuilding BUILD_DIR meanwhile changes nothing.
set -euo pipefail

build=${1:?usage: campaign.sh BUILD_DIR OUT_DIR SECONDS [TARGET...]}
out=${2:?usage: campaign.sh BUILD_DIR OUT_DIR SECONDS [TARGET...]}
seconds=${3:?usage: campaign.sh BUILD_DIR OUT_DIR SECONDS [TARGET...]}
shift 3
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(profile stereo_layout stereo_metadata still video)
here=$(cd "$(dirname "$0")" && pwd)
out=$(mkdir -p "$out" && cd "$out" && pwd)

mkdir -p "$out/bin" "$out/lib/nelf" "$out/seeds"
# The module is found beside the executable (bin/../lib/nelf), as in an installed nelf.
cp "$build/lib/nelf/nelf-oiio.so" "$out/lib/nelf/"

# Runs one target until SECONDS have passed since it started (arguments: target, seconds, out, dict).
# shellcheck disable=SC2016
loop='t=$1 seconds=$2 out=$3; shift 3
start=$(date +%s) run=0
while left=$((seconds - ($(date +%s) - start))); [ "$left" -gt 0 ]; do
  run=$((run + 1))
  "$out/bin/fuzz_$t" -max_total_time="$left" -timeout=30 -print_final_stats=1 \
    -artifact_prefix="$out/artifacts/$t/" "$@" "$out/corpus/$t" "$out/seeds/$t"
  status=$?
  echo "campaign: run $run of fuzz_$t ended with status $status after $(($(date +%s) - start)) s"
  [ "$status" -eq 0 ] && break
done'

for t in "${targets[@]}"; do
  cp "$build/tests/fuzz/fuzz_$t" "$out/bin/"
  rm -rf "$out/seeds/$t" && cp -r "$build/corpus/seeds/$t" "$out/seeds/$t"
  mkdir -p "$out/corpus/$t" "$out/artifacts/$t"
  dict=()
  [ -f "$here/$t.dict" ] && dict=(-dict="$here/$t.dict")
  LSAN_OPTIONS=suppressions=$here/lsan.supp ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    nohup nice -n 19 /usr/bin/time -v -o "$out/$t.time" bash -c "$loop" campaign "$t" "$seconds" "$out" \
    "${dict[@]}" >"$out/$t.log" 2>&1 </dev/null &
  echo "fuzz_$t: pid $!, log $out/$t.log"
done
