#!/usr/bin/env bash
# Builds everything and runs every test: the README's test command, and CI's (.ci/run).
#  1. The plain build (warnings are errors; benchmarks and tools compiled too) and its unit tests:
#     every test that is not a whole-process one (labels integration and e2e).
#  2. Every parser fuzzed for a bounded time (clang, ASan + UBSan), targets side by side.
#  3. The whole suite, unit, integration over real DDS/HTTP/SQLite, network-namespace faults,
#     crash cycles and the browser, on the ASan + UBSan build: the product's code with every
#     memory and undefined-behaviour check on. The process-level tests run once, there; the plain
#     build's copy of them would check the same code again without the sanitizers (run it with
#     `ctest --test-dir build -L 'integration|e2e'`).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
t0=$(date +%s)
"$root/deploy/build.sh"
t1=$(date +%s)
ctest --test-dir "$root/build" --output-on-failure -j"$(nproc)" --timeout 600 -LE 'integration|e2e'
t2=$(date +%s)
"$root/deploy/fuzz.sh" "${TELLTALE_FUZZ_SECONDS:-45}"
t3=$(date +%s)
"$root/deploy/test_sanitized.sh"
t4=$(date +%s)
echo "test: build $((t1 - t0)) s, unit tests $((t2 - t1)) s, fuzzing $((t3 - t2)) s," \
  "sanitized build and suite $((t4 - t3)) s; total $((t4 - t0)) s"
