#!/usr/bin/env bash
# Configures and builds into build/ (binaries in build/bin): everything, or only the CMake targets
# named as arguments (the demo builds just the three programs it runs).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/deploy/bootstrap.sh"
# Line tables only (-g1): stack traces, perf and gdb backtraces keep file:line; full debug info
# cost 30-50 % more compile time per file for locals nobody reads in an optimised build.
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build "$root/build" -j"$(nproc)" "${targets[@]}"
# The dashboard's charts library (npm, vendored into web/vendor/); without npm the fleet view
# still works and the chart views say what is missing.
"$root/deploy/web_deps.sh" || echo "build: web/ npm packages not installed (need Node.js and npm)" >&2
