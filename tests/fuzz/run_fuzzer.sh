#!/usr/bin/env bash
# Runs one libFuzzer target for a bounded time: first every saved regression input, then
# the seed corpus (copied to a scratch directory) for SECONDS. Prints the executions;
# exits non-zero on a crash, leak, timeout or broken invariant.
# usage: run_fuzzer.sh FUZZER SEED_DIR WORK_DIR SECONDS [REGRESSION_DIR]
set -uo pipefail
fuzzer=$1 seeds=$2 work=$3 seconds=$4 regressions=${5:-}
name=$(basename "$fuzzer")
rm -rf "$work/corpus" && mkdir -p "$work/corpus" "$work/artifacts"
[ -d "$seeds" ] && cp "$seeds"/* "$work/corpus/" 2>/dev/null
if [ -n "$regressions" ] && [ -d "$regressions" ] && [ -n "$(ls -A "$regressions" 2>/dev/null)" ]; then
  # Regressions are known bugs until fixed: report them, but only fail the run on them
  # when HEDGE_FUZZ_STRICT=1 (the fuzzing below still fails on any new finding).
  if ! "$fuzzer" -runs=0 "$regressions"/* >"$work/regressions.log" 2>&1; then
    echo "$name: a saved regression input still fails (see $work/regressions.log)"
    [ "${HEDGE_FUZZ_STRICT:-0}" = 1 ] && exit 1
  fi
fi
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
# A fixed seed (HEDGE_FUZZ_SEED, default 1) makes a run's inputs the same on every machine,
# so what CI finds can be found again here by running as long; 0 draws a fresh seed.
"$fuzzer" -seed="${HEDGE_FUZZ_SEED:-1}" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -max_len=4096 -print_final_stats=1 \
  -artifact_prefix="$work/artifacts/" "$work/corpus" >"$work/fuzz.log" 2>&1
rc=$?
execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$work/fuzz.log" | grep -o '[0-9]*$' | tail -1)
cov=$(grep -o 'cov: [0-9]*' "$work/fuzz.log" | tail -1)
echo "$name: ${execs:-?} executions in ${seconds}s, ${cov:-cov: ?}, corpus $(ls "$work/corpus" | wc -l) inputs, exit $rc"
if [ $rc -ne 0 ]; then
  grep -m1 -E 'ERROR: |FUZZ INVARIANT|runtime error|Test unit written' "$work/fuzz.log"
  tail -n 40 "$work/fuzz.log"
  ls "$work/artifacts"
fi
exit $rc
