#!/usr/bin/env bash
# Runs the libFuzzer targets built by the `fuzz` preset: first every checked-in
# seed and regression input once (a crash found earlier must stay fixed), then
# fuzzing for SECONDS each. New corpus entries and crash inputs go under the build
# directory, never into the repository. One line per target; exit 1 on a crash.
#
#   tests/fuzz/run.sh BUILD_DIR SECONDS
set -uo pipefail

build=${1:?usage: run.sh BUILD_DIR SECONDS}
seconds=${2:?usage: run.sh BUILD_DIR SECONDS}
here=$(cd "$(dirname "$0")" && pwd)
status=0

for target in spec npy npz csv; do
  bin=$build/tests/fuzz/fuzz_$target
  work=$build/fuzz-work/$target
  mkdir -p "$work/corpus" "$work/crashes"
  log=$work/last.log
  dict=()
  [ -f "$here/$target.dict" ] && dict=(-dict="$here/$target.dict")
  # -timeout: one input taking seconds is a hang (every seed runs in milliseconds);
  # -rss_limit_mb: far above what inputs of -max_len bytes need, far below the machine.
  opts=(-timeout=10 -rss_limit_mb=2048 -max_len=65536 -artifact_prefix="$work/crashes/")

  mapfile -t inputs < <(find "$here/corpus/$target" "$here/regressions/$target" -type f ! -name '.*' | sort)
  if ! "$bin" "${opts[@]}" "${inputs[@]}" >"$log" 2>&1; then
    echo "fuzz $target: FAILED on a checked-in input (see $log):"
    grep -m1 -E 'Running: |ERROR|==ERROR' "$log" | sed 's/^/  /'
    status=1
    continue
  fi

  if ! "$bin" "${opts[@]}" "${dict[@]}" -max_total_time="$seconds" -print_final_stats=1 \
       "$work/corpus" "$here/corpus/$target" >"$log" 2>&1; then
    crash=$(ls -t "$work/crashes" 2>/dev/null | head -1)
    echo "fuzz $target: CRASH after fuzzing (see $log); input $work/crashes/$crash —" \
         "keep it in tests/fuzz/regressions/$target/ and fix the bug"
    status=1
    continue
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  echo "fuzz $target: ok — ${#inputs[@]} checked-in inputs replayed, ${runs:-?} executions in ${seconds} s," \
       "$(find "$work/corpus" -type f | wc -l) corpus entries in $work/corpus, no crash"
done
exit $status
