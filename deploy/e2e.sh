#!/usr/bin/env bash
# Browser tests (tests/e2e/): real shore_server and boat_node processes on private DDS domains
# (150-199) and free loopback ports, Debian's chromium driven headless by playwright-core.
# Installs what they need first: chromium (deploy/packages-browser.txt, only when missing) and
# the npm packages of web/ (only when stale). Fails, never skips, when any of that is missing.
#   deploy/e2e.sh [--bin-dir DIR] [TEST_FILE...]      (default: every tests/e2e/*.test.mjs)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=${TELLTALE_BIN_DIR:-$root/build/bin}
files=()
while [ $# -gt 0 ]; do
  case "$1" in
    --bin-dir) bin=$2; shift 2 ;;
    *) files+=("$1"); shift ;;
  esac
done
[ ${#files[@]} -gt 0 ] || files=("$root"/tests/e2e/*.test.mjs)

chromium=${TELLTALE_CHROMIUM:-/usr/bin/chromium}
# Idempotent and quick when everything is there; a failure shows in the check below.
"$root/deploy/bootstrap.sh" --browser || echo "e2e: could not install the browser packages" >&2
[ -x "$chromium" ] || { echo "e2e: FAILED: $chromium is missing and could not be installed" >&2; exit 1; }
command -v node >/dev/null || { echo "e2e: FAILED: node not found (Node.js >= 20 needed)" >&2; exit 1; }
major=$(node -p 'process.versions.node.split(".")[0]')
[ "$major" -ge 20 ] || { echo "e2e: FAILED: Node.js $major found, >= 20 needed" >&2; exit 1; }
"$root/deploy/web_deps.sh"
for b in shore_server boat_node wearable_node; do
  [ -x "$bin/$b" ] || { echo "e2e: FAILED: $bin/$b not built" >&2; exit 1; }
done
mkdir -p "$root/tests/artifacts"
export TELLTALE_BIN_DIR=$bin
export TELLTALE_E2E_DOMAIN_BASE=${TELLTALE_E2E_DOMAIN_BASE:-$((RANDOM % 50))}
cd "$root"
exec timeout --signal=INT --kill-after=10 300 node --test --test-concurrency=1 --test-reporter=spec "${files[@]}"
