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
# The dashboard's charts library (npm, vendored into web/vendor/) is fetched while the compiler
# runs: it waits on the network, the compiler on the CPU. Without npm the fleet view still works
# and the chart views say what is missing.
mkdir -p "$root/build"
"$root/deploy/web_deps.sh" >"$root/build/web_deps.log" 2>&1 &
web=$!
trap 'kill "$web" 2>/dev/null || true' EXIT
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build "$root/build" -j"$(nproc)" "${targets[@]}"
if ! wait "$web"; then
  cat "$root/build/web_deps.log" >&2
  echo "build: web/ npm packages not installed (need Node.js and npm)" >&2
fi
trap - EXIT
