#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz, clang, ASan + UBSan) into build-fuzz/ and runs each for
# a bounded time: deploy/fuzz.sh [SECONDS_PER_TARGET (default 45)] [TARGET...]
# Prints per target the seconds run, executions, exec/s, coverage (libFuzzer's cov: edges) and
# crashes; fails if any target crashed. Crash inputs are kept in build-fuzz/crashes/<target>/
# (replay one: build-fuzz/bin/<target> FILE). Inputs that found new coverage accumulate in
# build-fuzz/corpus/<target>/ across runs; the seeds stay in tests/fuzz/corpus/<target>/.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="$root/build-fuzz"
seconds=${1:-45}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_csv fuzz_nmea fuzz_witmotion fuzz_session_log fuzz_rest fuzz_ingest
  fuzz_import_vakaros_csv fuzz_import_vkx fuzz_import_vtk fuzz_import_nmea_log fuzz_import_gpx)
"$root/deploy/bootstrap.sh"

start=$(date +%s)
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DTELLTALE_FUZZ=ON -DBUILD_TESTING=OFF -DTELLTALE_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j"$(nproc)" --target "${targets[@]}"
echo "fuzz: build $(($(date +%s) - start)) s"

# Leaks are findings too; UBSan stops at the first report like ASan does.
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
# Targets run side by side, one per core: each is a single process on one input at a time.
run_target() {
  local t=$1 corpus="$build/corpus/$1" crashes="$build/crashes/$1" log="$build/logs/$1.log"
  mkdir -p "$corpus" "$crashes" "$(dirname "$log")"
  rm -f "$build/logs/$t.summary"
  local dict=()
  [ -f "$root/tests/fuzz/dict/$t.dict" ] && dict=(-dict="$root/tests/fuzz/dict/$t.dict")
  local before t0 status=0
  before=$(find "$crashes" -type f | wc -l)
  t0=$(date +%s)
  # -timeout: one input taking over 10 s is a hang, reported like a crash.
  "$build/bin/$t" -max_total_time="$seconds" -timeout=10 -print_final_stats=1 \
    -artifact_prefix="$crashes/" "${dict[@]}" "$corpus" "$root/tests/fuzz/corpus/$t" \
    >"$log" 2>&1 || status=$?
  local ran execs rate cov found
  ran=$(($(date +%s) - t0))
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  cov=$({ grep -o 'cov: [0-9]*' "$log" || true; } | tail -1 | cut -d' ' -f2)
  found=$(($(find "$crashes" -type f | wc -l) - before))
  if [ "$status" -ne 0 ] && [ "$found" -eq 0 ]; then found=1; fi  # died without an artifact
  printf '%-18s %8s %12s %10s %8s %8s\n' "$t" "$ran" "${execs:-?}" "${rate:-?}" "${cov:-?}" \
    "$found" >"$build/logs/$t.summary"
  if [ "$found" -ne 0 ]; then
    echo "fuzz: $t crashed (status $status); log $log; inputs in $crashes/:" >&2
    grep -E 'ERROR|INVARIANT|SUMMARY|Test unit written' "$log" | head -20 >&2 || true
    return 1
  fi
}
jobs_max=$(nproc)
failed=0
running=0
for t in "${targets[@]}"; do
  if [ "$running" -ge "$jobs_max" ]; then
    wait -n || failed=1
    running=$((running - 1))
  fi
  run_target "$t" &
  running=$((running + 1))
done
while [ "$running" -gt 0 ]; do
  wait -n || failed=1
  running=$((running - 1))
done
summary=$(printf '%-18s %8s %12s %10s %8s %8s' target seconds executions exec/s cov crashes)
for t in "${targets[@]}"; do
  summary+=$'\n'$(cat "$build/logs/$t.summary" 2>/dev/null || echo "$t: did not run")
done
echo "$summary"
[ "$failed" -eq 0 ] || { echo "fuzz: FAILED (crash inputs kept under $build/crashes)" >&2; exit 1; }
echo "fuzz: all targets ran without a crash"
