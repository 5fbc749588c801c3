#!/usr/bin/env bash
# Runs the libFuzzer targets built by the `fuzz` preset: first every checked-in
# seed and regression input once (a crash found earlier must stay fixed), then
# fuzzing for SECONDS each. New corpus entries and crash inputs go under the build
# directory, never into the repository. One line per target; exit 1 on a crash.
# The targets run side by side, as many at once as there are cores (FUZZ_JOBS).
#
#   tests/fuzz/run.sh BUILD_DIR SECONDS
set -uo pipefail

build=${1:?usage: run.sh BUILD_DIR SECONDS}
seconds=${2:?usage: run.sh BUILD_DIR SECONDS}
here=$(cd "$(dirname "$0")" && pwd)
jobs=${FUZZ_JOBS:-$(nproc)}
targets=(spec npy npz csv)

# One target: its line into $work/result, its status as the function's.
fuzz_one() {
  local target=$1
  local bin=$build/tests/fuzz/fuzz_$target
  local work=$build/fuzz-work/$target
  mkdir -p "$work/corpus" "$work/crashes"
  local log=$work/last.log
  local dict=()
  [ -f "$here/$target.dict" ] && dict=(-dict="$here/$target.dict")
  # -timeout: one input taking seconds is a hang (every seed runs in milliseconds);
  # -rss_limit_mb: far above what inputs of -max_len bytes need, far below the machine.
  local opts=(-timeout=10 -rss_limit_mb=2048 -max_len=65536 -artifact_prefix="$work/crashes/")

  local inputs runs crash
  mapfile -t inputs < <(find "$here/corpus/$target" "$here/regressions/$target" -type f ! -name '.*' | sort)
  exec >"$work/result"
  if ! "$bin" "${opts[@]}" "${inputs[@]}" >"$log" 2>&1; then
    echo "fuzz $target: FAILED on a checked-in input (see $log):"
    grep -m1 -E 'Running: |ERROR|==ERROR' "$log" | sed 's/^/  /'
    return 1
  fi

  if ! "$bin" "${opts[@]}" "${dict[@]}" -max_total_time="$seconds" -print_final_stats=1 \
       "$work/corpus" "$here/corpus/$target" >"$log" 2>&1; then
    crash=$(ls -t "$work/crashes" 2>/dev/null | head -1)
    echo "fuzz $target: CRASH after fuzzing (see $log); input $work/crashes/$crash —" \
         "keep it in tests/fuzz/regressions/$target/ and fix the bug"
    return 1
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  echo "fuzz $target: ok — ${#inputs[@]} checked-in inputs replayed, ${runs:-?} executions in ${seconds} s," \
       "$(find "$work/corpus" -type f | wc -l) corpus entries in $work/corpus, no crash"
}

for target in "${targets[@]}"; do
  mkdir -p "$build/fuzz-work/$target"
  rm -f "$build/fuzz-work/$target/result"
  ( fuzz_one "$target" ) &
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n; done
done
wait
status=0
for target in "${targets[@]}"; do
  result=$build/fuzz-work/$target/result
  if [ -s "$result" ]; then cat "$result"; else echo "fuzz $target: no result (see $build/fuzz-work/$target/last.log)"; fi
  grep -q "^fuzz $target: ok" "$result" 2>/dev/null || status=1
done
exit $status
