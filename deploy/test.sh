#!/usr/bin/env bash
# Builds everything and runs every test: the README's test command, and CI's (.ci/run).
#  1. The plain build of every program (warnings are errors): the nodes, the shore, the importer,
#     the CLI and the benchmarks (CMake target `programs`), as users and the demo run them.
#  2. Every parser fuzzed for a bounded time (clang, ASan + UBSan, 30 s each), side by side.
#  3. The whole suite, unit, integration over real DDS/HTTP/SQLite, network-namespace faults,
#     crash cycles and the browser, on the ASan + UBSan build (warnings are errors there too): the
#     product's code with every memory and undefined-behaviour check on. The tests are compiled
#     once, there; a plain build of them checks the same code again without the sanitizers (run
#     it with `deploy/build.sh && ctest --test-dir build`).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
t0=$(date +%s)
# The build's packages first (build.sh, fuzz.sh and test_sanitized.sh then find them all), so
# that the browser's apt-get below runs alone: two at once would fight over dpkg's lock.
"$root/deploy/bootstrap.sh"
# The browser's packages (Chromium, ~30 s to install on a new machine) come in while the compiler
# runs, not in the browser test's own time at the end, where it runs alone.
mkdir -p "$root/build"
"$root/deploy/bootstrap.sh" --browser >"$root/build/browser-packages.log" 2>&1 &
browser_packages=$!
"$root/deploy/build.sh" programs
t1=$(date +%s)
# 30 s per target: on a machine that fuzzed before, each run starts from the corpus the earlier
# runs grew (build-fuzz/corpus/), so coverage accumulates across runs.
"$root/deploy/fuzz.sh" "${TELLTALE_FUZZ_SECONDS:-30}"
t2=$(date +%s)
wait "$browser_packages" || cat "$root/build/browser-packages.log" >&2  # the browser test says it fails
"$root/deploy/test_sanitized.sh"
t3=$(date +%s)
echo "test: programs build $((t1 - t0)) s, fuzzing $((t2 - t1)) s," \
  "sanitized build and suite $((t3 - t2)) s; total $((t3 - t0)) s"
