#!/usr/bin/env bash
# Builds everything and runs every test (unit, integration over real DDS and HTTP).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/deploy/build.sh"
cd "$root/build"
ctest --output-on-failure -j"$(nproc)" --timeout 600
# Then every parser fuzzed for a bounded time, and the whole suite again under ASan + UBSan.
"$root/deploy/fuzz.sh" "${TELLTALE_FUZZ_SECONDS:-45}"
"$root/deploy/test_sanitized.sh"
