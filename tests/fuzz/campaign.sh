#!/usr/bin/env bash
# A long fuzzing campaign (docs/fuzzing.md): all targets at once, each at the lowest priority,
# each until it has used CPU_SECONDS of CPU (user + system). CPU time, not wall time, because the
# targets share the machine with each other and with whatever else runs: an hour of wall time at
# nice 19 on a busy machine is minutes of fuzzing. A target that stops on a finding (crash, leak,
# timeout, out-of-memory; the input is saved) is started again, with the corpus grown so far, for
# the CPU time left.
#   tests/fuzz/campaign.sh BUILD_DIR OUT_DIR CPU_SECONDS [TARGET...]
# Returns at once; the targets run in the background. OUT_DIR/T.log is libFuzzer's log (one
# "campaign: run N ..." line after each run), OUT_DIR/T.cpu the CPU seconds used so far,
# OUT_DIR/corpus/T the grown corpus, OUT_DIR/artifacts/T the findings. Run it again with the same
# OUT_DIR to go on where a stopped campaign left off (the CPU used so far counts).
# The binaries and the image-library module are copied to OUT_DIR/bin and OUT_DIR/lib first, so
# that rebuilding BUILD_DIR meanwhile changes nothing.
set -euo pipefail

build=${1:?usage: campaign.sh BUILD_DIR OUT_DIR CPU_SECONDS [TARGET...]}
out=${2:?usage: campaign.sh BUILD_DIR OUT_DIR CPU_SECONDS [TARGET...]}
budget=${3:?usage: campaign.sh BUILD_DIR OUT_DIR CPU_SECONDS [TARGET...]}
shift 3
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(profile defect_map stereo_layout stereo_metadata still video)
here=$(cd "$(dirname "$0")" && pwd)
out=$(mkdir -p "$out" && cd "$out" && pwd)

mkdir -p "$out/bin" "$out/lib/nelf" "$out/seeds"
# The module is found beside the executable (bin/../lib/nelf), as in an installed nelf. Copied as a
# new file, never over the old one: targets of a campaign already running have that one mapped, and
# rewriting it in place ends them with SIGBUS (it did, once).
cp --remove-destination "$build/lib/nelf/nelf-oiio.so" "$out/lib/nelf/"

# Runs one target until it has used BUDGET CPU seconds over all its runs (arguments: target,
# budget, out, libFuzzer options). The CPU time of a running fuzzer is read from /proc (all its
# threads); once the budget is spent it gets SIGINT, on which libFuzzer prints its final stats.
# shellcheck disable=SC2016
loop='t=$1 budget=$2 out=$3; shift 3
tick=$(getconf CLK_TCK)
used=$(cat "$out/$t.cpu" 2>/dev/null || echo 0)
run=$(grep -c "^campaign: run" "$out/$t.log.all" 2>/dev/null || true)
cpu_of() { awk -v tick="$tick" "{ sub(/^.*\\) /, \"\"); print int((\$12 + \$13) / tick) }" "/proc/$1/stat" 2>/dev/null || echo 0; }
while [ "$used" -lt "$budget" ]; do
  run=$((run + 1))
  "$out/bin/fuzz_$t" -timeout=60 -print_final_stats=1 -artifact_prefix="$out/artifacts/$t/" \
    "$@" "$out/corpus/$t" "$out/seeds/$t" &
  pid=$! this=0
  while kill -0 "$pid" 2>/dev/null; do
    sleep 5
    now=$(cpu_of "$pid")
    [ "$now" -gt "$this" ] && this=$now
    if [ $((used + this)) -ge "$budget" ]; then kill -INT "$pid" 2>/dev/null || true; fi
  done
  status=0
  wait "$pid" || status=$?
  used=$((used + this))
  echo "$used" >"$out/$t.cpu"
  echo "campaign: run $run of fuzz_$t ended with status $status; CPU used $used of $budget s"
done'

for t in "${targets[@]}"; do
  cp --remove-destination "$build/tests/fuzz/fuzz_$t" "$out/bin/"
  rm -rf "$out/seeds/$t" && cp -r "$build/corpus/seeds/$t" "$out/seeds/$t"
  mkdir -p "$out/corpus/$t" "$out/artifacts/$t"
  dict=()
  [ -f "$here/$t.dict" ] && dict=(-dict="$here/$t.dict")
  # A resumed campaign keeps the earlier logs: T.log.all gathers them all.
  [ -f "$out/$t.log" ] && cat "$out/$t.log" >>"$out/$t.log.all"
  LSAN_OPTIONS=suppressions=$here/lsan.supp ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    nohup nice -n 19 bash -c "$loop" campaign "$t" "$budget" "$out" "${dict[@]}" \
    >"$out/$t.log" 2>&1 </dev/null &
  echo "fuzz_$t: pid $!, log $out/$t.log"
done
