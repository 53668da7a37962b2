#!/usr/bin/env bash
# Runs each fuzz target for a given time (docs/fuzzing.md): `make fuzz` and `make test` call it.
#   tests/fuzz/run_fuzzers.sh BUILD_DIR SECONDS_PER_TARGET [TARGET...]
# Each target starts from its seeds (BUILD_DIR/corpus/seeds/T, written at build time) and the corpus
# it grew in earlier runs (BUILD_DIR/corpus/T); a crash, leak, timeout or out-of-memory input is
# written to BUILD_DIR/fuzz-artifacts/T/ and makes this script fail. Prints, per target, the
# executions, exec/s, coverage (cov = edges, ft = features) and corpus size libFuzzer reports.
set -uo pipefail

build=${1:?usage: run_fuzzers.sh BUILD_DIR SECONDS [TARGET...]}
seconds=${2:?usage: run_fuzzers.sh BUILD_DIR SECONDS [TARGET...]}
shift 2
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(profile defect_map stereo_layout stereo_metadata still video)
here=$(cd "$(dirname "$0")" && pwd)
# A single input must finish in this many seconds; the machine may be busy, so it is generous.
timeout_s=${FUZZ_INPUT_TIMEOUT:-30}

# Targets run side by side, FUZZ_JOBS at a time (default: one per core): each libFuzzer process
# uses one core, and CI's bounded run would otherwise leave all but one idle.
jobs=${FUZZ_JOBS:-$(nproc)}

run_target() {
  local t=$1 binary="$build/tests/fuzz/fuzz_$1"
  local corpus="$build/corpus/$t" artifacts="$build/fuzz-artifacts/$t" log="$build/fuzz-logs/$t.log"
  mkdir -p "$corpus" "$artifacts" "$(dirname "$log")"
  local dict=()
  [ -f "$here/$t.dict" ] && dict=(-dict="$here/$t.dict")
  # lsan.supp: leaks inside third-party libraries that nelf cannot avoid (documented there).
  LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$here/lsan.supp} \
    ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1} \
    "$binary" -max_total_time="$seconds" -timeout="$timeout_s" -print_final_stats=1 \
    -artifact_prefix="$artifacts/" "${dict[@]}" "$corpus" "$build/corpus/seeds/$t" >"$log" 2>&1
  echo $? >"$log.status"
}

for t in "${targets[@]}"; do
  [ -x "$build/tests/fuzz/fuzz_$t" ] || { echo "run_fuzzers: $build/tests/fuzz/fuzz_$t is not built" >&2; exit 2; }
done
running=0
for t in "${targets[@]}"; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n
    running=$((running - 1))
  fi
  run_target "$t" &
  running=$((running + 1))
done
wait

failed=()
printf '%-16s %10s %8s %7s %7s %7s  %s\n' target execs exec/s cov ft corpus result
for t in "${targets[@]}"; do
  log="$build/fuzz-logs/$t.log"
  status=$(cat "$log.status" 2>/dev/null || echo 125)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
  corp=$(sed -n 's/.* corp: \([0-9]*\).*/\1/p' <<<"$last")
  result=ok
  if [ "$status" -ne 0 ]; then
    result="FINDING (exit $status), log $log"
    failed+=("$t")
  fi
  printf '%-16s %10s %8s %7s %7s %7s  %s\n' "$t" "${execs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}" "$result"
done

if [ ${#failed[@]} -ne 0 ]; then
  for t in "${failed[@]}"; do
    echo "--- fuzz_$t: $build/fuzz-logs/$t.log (end) ---" >&2
    grep -E 'ERROR|SUMMARY|==[0-9]+==|runtime error|broken invariant|Test unit written' "$build/fuzz-logs/$t.log" | tail -15 >&2
    echo "reproduce: $build/tests/fuzz/fuzz_$t $build/fuzz-artifacts/$t/<file>" >&2
  done
  exit 1
fi
